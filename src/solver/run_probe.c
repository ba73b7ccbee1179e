/* Rank 0's probes over MPI ranks (run_impl.h, sph_probe_view): the
 * probes' particles found once over the ranks, their fields gathered from
 * their owners at every frame, so that no rank holds the whole run. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "solver/run_impl.h"

static int cmp_id(const void *pa, const void *pb) {
  int64_t a = *(const int64_t *)pa, b = *(const int64_t *)pb;
  return (a > b) - (a < b);
}

/* the rows of the probes' particles this rank owns: fields (the position
 * only with X) or the reference positions, to rank 0's set (collective) */
sph_status sph_probe_view_fill(sph_probe_view *pv, sph_sim *sim, int X,
                               sph_error *err) {
  const sph_particles *ps = sim->ps;
  sph_particles *v = pv->ps;
  size_t m = v->n, w = (size_t)pv->w;
  memset(pv->rows, 0, m * w * sizeof *pv->rows);
  for (size_t a = 0; a < ps->n; ++a) {
    const int64_t *k = bsearch(&ps->id[a], v->id, m, sizeof *v->id, cmp_id);
    if (!k)
      continue;
    double *r = pv->rows + w * (size_t)(k - v->id);
    r[0] = 1.0;
    size_t c = 1;
    for (int f = 0; f < SPH_FIELD_COUNT; ++f) {
      if (X ? f != SPH_FIELD_POSITION0 : !(pv->fields & 1ul << f))
        continue;
      size_t nc = (size_t)sph_field_components((sph_field)f);
      memcpy(r + c, ps->field[f] + nc * a, nc * sizeof *r);
      c += nc;
    }
  }
  SPH_TRY(sph_domain_pick(sim->domain, pv->rows, m, pv->w, pv->got, err));
  for (size_t k = 0; k < m && sph_domain_rank(sim->domain) == 0; ++k) {
    size_t c = 1;
    for (int f = 0; f < SPH_FIELD_COUNT; ++f) {
      if (X ? f != SPH_FIELD_POSITION0 : !(pv->fields & 1ul << f))
        continue;
      size_t nc = (size_t)sph_field_components((sph_field)f);
      memcpy(v->field[f] + nc * k, pv->got + w * k + c, nc * sizeof *pv->got);
      c += nc;
    }
  }
  return SPH_OK;
}

void sph_probe_view_destroy(sph_probe_view *pv) {
  sph_particles_destroy(pv->ps);
  free(pv->rows);
  free(pv->got);
}

/* the probes' particles: the nearest owned one of each rank, then the
 * nearest of those, ties to the smallest id (collective) */
sph_status sph_probe_view_create(sph_probe_view *pv, sph_sim *sim,
                                 sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_particles *ps = sim->ps;
  size_t np = s->output.nprobes, m = 0;
  int64_t *ids = malloc((np + 1) * sizeof *ids);
  sph_status st = ids ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "probes");
  SPH_TRY(sph_domain_agree(sim->domain, st, err));
  for (size_t k = 0; k < np; ++k) {
    double best = INFINITY, id = INFINITY;
    for (size_t a = 0; a < ps->n; ++a) {
      const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * a;
      double d = 0.0;
      for (int c = 0; c < 3; ++c)
        d += pow(X[c] - s->output.probes[k].at[c], 2);
      if (d < best || (d == best && (double)ps->id[a] < id)) {
        best = d;
        id = (double)ps->id[a];
      }
    }
    double dmin = sph_domain_min(sim->domain, best);
    ids[k] = (int64_t)sph_domain_min(sim->domain, best == dmin ? id : INFINITY);
  }
  qsort(ids, np, sizeof *ids, cmp_id);
  for (size_t k = 0; k < np; ++k)
    if (m == 0 || ids[k] != ids[m - 1])
      ids[m++] = ids[k];
  st = sph_particles_create(&pv->ps, m ? m : 1, ps->dim, err);
  int w = 4; /* the flag, then the reference position or the fields */
  for (size_t k = 0; st == SPH_OK && k < np; ++k)
    for (int i = 0; st == SPH_OK && i < s->output.probes[k].nfields; ++i) {
      int f = s->output.probes[k].fields[i];
      if (ps->field[f] && f != SPH_FIELD_POSITION0 &&
          !(pv->fields & 1ul << f)) {
        st = sph_particles_require(pv->ps, (sph_field)f, err);
        pv->fields |= 1ul << f;
        w += sph_field_components((sph_field)f);
      }
    }
  if (st == SPH_OK) {
    pv->w = w;
    pv->ps->n = m;
    memcpy(pv->ps->id, ids, m * sizeof *ids);
    pv->rows = malloc((m * (size_t)w + 1) * sizeof *pv->rows);
    pv->got = calloc(m * (size_t)w + 1, sizeof *pv->got);
    if (!pv->rows || !pv->got)
      st = sph_error_set(err, SPH_ERR_NOMEM, "probes");
  }
  free(ids);
  SPH_TRY(sph_domain_agree(sim->domain, st, err));
  return sph_probe_view_fill(pv, sim, 1, err);
}
