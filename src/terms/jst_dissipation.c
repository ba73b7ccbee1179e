/* Jameson-Schmidt-Turkel dissipation, seed 000 eq. 35-38 (seed 003
 * eq. 13-15): D(u) = eps2 c_p h L[u] - eps4 c_p h^3 L[L[u]] with the
 * corrected particle Laplacian L[u]_a = sum_b V_b (u_b - u_a) Lap W~_b(X_a),
 * or in the symmetrised form of seed 004 eq. 28 (outer sums over the pair
 * mean of Lap W~, the inner L[u] as eq. 27),
 * for u = p (into dp) or u = J (into dJ), never F or H (involutions). The
 * conservative projections of eq. 49 (p: zero sum and moment per body) and
 * eq. 51 (J: zero volume-weighted sum per body) are applied when asked.
 * Over MPI ranks (sim->domain) the ghosts' u (when the method's sweep has
 * not set it) and L[u] are exchanged before the sweeps that read them, and
 * the projections' sums are global. */
#include <stdlib.h>
#include <string.h>

#include "terms/terms_impl.h"

typedef struct jst {
  jst_params p;
  double *lu; /* L[u] (p.lu when the method sums it) */
  double *d;  /* D(u) */
} jst;

/* out_a = cs self_a + cl L[u]_a with L[u]_a = sum_b (V_b Lap W~_b(X_a))
 * (u_b - u_a) (self may be NULL when cs = 0), one loop per component
 * count so that the compiler sees it */
static void laplacian3(const jst *j, const double *wl, const double *u,
                       const double *self, double cs, double cl, double *out,
                       long n) {
  const sph_neighbors *nl = j->p.nl;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double s[3] = {0.0, 0.0, 0.0};
    const double *ua = u + 3 * a;
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      const double *ub = u + 3 * (size_t)nl->index[k];
      s[0] += wl[k] * (ub[0] - ua[0]);
      s[1] += wl[k] * (ub[1] - ua[1]);
      s[2] += wl[k] * (ub[2] - ua[2]);
    }
    for (int c = 0; c < 3; ++c)
      out[3 * a + c] = self ? cs * self[3 * a + c] + cl * s[c] : cl * s[c];
  }
}

static void laplacian1(const jst *j, const double *wl, const double *u,
                       const double *self, double cs, double cl, double *out,
                       long n) {
  const sph_neighbors *nl = j->p.nl;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double s = 0.0;
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k)
      s += wl[k] * (u[nl->index[k]] - u[a]);
    out[a] = self ? cs * self[a] + cl * s : cl * s;
  }
}

static void laplacian(const jst *j, const double *wl, const double *u,
                      const double *self, double cs, double cl, double *out,
                      long n) {
  if (j->p.ncomp == 3)
    laplacian3(j, wl, u, self, cs, cl, out, n);
  else
    laplacian1(j, wl, u, self, cs, cl, out, n);
}

/* out_a += cl (sum_b adj_ab (w_b - w_a) + diag_a w_a): the adjoint outer
 * sweep (jst_params.lap_adj) */
static void laplacian_adj3(const jst *j, const double *w, double cl,
                           double *out, long n) {
  const sph_neighbors *nl = j->p.nl;
  const double *adj = j->p.lap_adj, *diag = j->p.lap_diag;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double s[3] = {0.0, 0.0, 0.0};
    const double *wa = w + 3 * a;
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      const double *wb = w + 3 * (size_t)nl->index[k];
      s[0] += adj[k] * (wb[0] - wa[0]);
      s[1] += adj[k] * (wb[1] - wa[1]);
      s[2] += adj[k] * (wb[2] - wa[2]);
    }
    for (int c = 0; c < 3; ++c)
      out[3 * a + c] += cl * (s[c] + diag[a] * wa[c]);
  }
}

static sph_status jst_rates(sph_term *term, sph_sim *sim, sph_stage *stage,
                            sph_error *err) {
  jst *j = term->data;
  const sph_particles *ps = sim->ps;
  const double *V = j->p.V;
  long n = (long)ps->n;
  int nc = j->p.ncomp;
  const double *u = nc == 3 ? stage->p : stage->J;
  double *rate = nc == 3 ? stage->dp : stage->dJ;
  double cp = j->p.cp_now ? *j->p.cp_now : j->p.cp;
  double c2 = j->p.eps2 * cp * j->p.h;
  double c4 = j->p.eps4 * cp * j->p.h * j->p.h * j->p.h;
  if (j->p.exchange_u)
    SPH_TRY(sph_domain_exchange(sim->domain, (double *)u, nc, err));
  if (!j->p.lu)
    laplacian(j, j->p.lap, u, NULL, 0.0, 1.0, j->lu, n);
  /* the second sweep reads the ghosts' L[u] */
  if (j->p.lap_sym || c4 != 0.0)
    SPH_TRY(sph_domain_exchange(sim->domain, j->lu, nc, err));
  if (sim->mirror) { /* the images' Laplacians mirror their sources' */
    if (nc == 3)
      sph_mirror_vector(sim->mirror, j->lu);
    else
      sph_mirror_scalar(sim->mirror, j->lu, 0.0);
  }
  long len = nc * n;
  if (j->p.lap_sym && j->p.lap_adj) { /* D = c2 S[u] - c4 L*[L[u]] */
    if (c2 != 0.0)
      laplacian(j, j->p.lap_sym, u, NULL, 0.0, c2, j->d, n);
    else
      memset(j->d, 0, (size_t)len * sizeof *j->d);
    laplacian_adj3(j, j->lu, -c4, j->d, n);
  } else if (j->p.lap_sym) { /* eq. 28: D = c2 S[u] - c4 S[L[u]] */
    if (c2 != 0.0)
      laplacian(j, j->p.lap_sym, u, NULL, 0.0, c2, j->d, n);
    laplacian(j, j->p.lap_sym, j->lu, c2 != 0.0 ? j->d : NULL, 1.0, -c4, j->d,
              n);
  } else if (c4 != 0.0) { /* D = c2 L[u] - c4 L[L[u]] */
    laplacian(j, j->p.lap, j->lu, j->lu, c2, -c4, j->d, n);
  } else {
#pragma omp parallel for schedule(static)
    for (long i = 0; i < len; ++i)
      j->d[i] = c2 * j->lu[i];
  }
  if (j->p.project) {
    if (nc == 3) {
      sph_momentum_projection(sim->domain, ps->n, ps->field[SPH_FIELD_VOLUME0],
                              stage->x_moment, ps->body,
                              (int)sim->scene->nbodies, j->d);
    } else {
      for (size_t b = 0; b < sim->scene->nbodies; ++b) {
        double s[2] = {0.0, 0.0}; /* sum V, sum V D */
        for (long a = 0; a < n; ++a)
          if (ps->body[a] == (int32_t)b) {
            s[0] += V[a];
            s[1] += V[a] * j->d[a];
          }
        sph_domain_sum(sim->domain, s, 2);
        double mu = s[0] > 0.0 ? -s[1] / s[0] : 0.0;
        for (long a = 0; a < n; ++a)
          if (ps->body[a] == (int32_t)b)
            j->d[a] += mu;
      }
    }
  }
#pragma omp parallel for schedule(static)
  for (long i = 0; i < len; ++i)
    rate[i] += j->d[i];
  return SPH_OK;
}

static void jst_destroy(sph_term *term) {
  jst *j = term->data;
  if (!j)
    return;
  if (!j->p.lu)
    free(j->lu);
  free(j->d);
  free(j);
}

const sph_term_ops jst_p_term_ops = {
    .name = "jst_dissipation_p",
    .reference = "seed 000 eq. 35-38, projection eq. 49",
    .gpu = 1,
    .distributed = 1,
    .rates = jst_rates,
    .destroy = jst_destroy,
};

const sph_term_ops jst_p_sym_term_ops = {
    .name = "jst_dissipation_p",
    .reference = "seed 004 eq. 27-28 (symmetrised)",
    .distributed = 1,
    .rates = jst_rates,
    .destroy = jst_destroy,
};

const sph_term_ops jst_j_term_ops = {
    .name = "jst_dissipation_J",
    .reference = "seed 000 eq. 35-38, projection eq. 51",
    .distributed = 1,
    .rates = jst_rates,
    .destroy = jst_destroy,
};

sph_status jst_dissipation_create(sph_sim *sim, const jst_params *p,
                                  sph_error *err) {
  jst *j = calloc(1, sizeof *j);
  size_t len = (size_t)p->ncomp * (p->nl->n ? p->nl->n : 1);
  if (!j || !(j->lu = p->lu ? p->lu : calloc(len, sizeof(double))) ||
      !(j->d = calloc(len, sizeof(double)))) {
    if (j) {
      if (!p->lu)
        free(j->lu);
      free(j);
    }
    return sph_error_set(err, SPH_ERR_NOMEM, "JST work arrays");
  }
  j->p = *p;
  sph_status st = sph_sim_add_term(sim,
                                   p->ncomp == 1 ? &jst_j_term_ops
                                   : p->lap_sym  ? &jst_p_sym_term_ops
                                                 : &jst_p_term_ops,
                                   j, err);
  if (st != SPH_OK) {
    sph_term t = {.data = j};
    jst_destroy(&t);
  }
  return st;
}
