/* Stability indicators and the verdict of a run (see stability.h); over
 * MPI ranks each rank judges its owned particles and the indicators are
 * reduced over the ranks (sph_domain_*). */
#include "solver/stability.h"

#include "core/neighbors.h"
#include "core/tensor.h"
#include "materials/material.h"
#include "parallel/domain.h"
#include "scene/geometry.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *sph_indicator_key(sph_indicator i) {
  static const char *const keys[] = {
#define SPH_INDICATOR_KEY(id, key) key,
      SPH_INDICATOR_LIST(SPH_INDICATOR_KEY)
#undef SPH_INDICATOR_KEY
  };
  return i >= 0 && i < SPH_INDICATOR_COUNT ? keys[i] : "none";
}

static double pair_distance(const double *x, size_t a, size_t b, int dim) {
  double d2 = 0.0;
  for (int c = 0; c < dim; ++c) {
    double d = x[3 * a + c] - x[3 * b + c];
    d2 += d * d;
  }
  return sqrt(d2);
}

/* Particles a support of body b holds on a full lattice: the support's
 * volume in units of dp^dim */
static double support_count(const sph_verdict *v, int32_t b, int dim) {
  double r = v->body_kernel[b].support / v->body_dp[b];
  return dim == 3   ? 4.0 / 3.0 * M_PI * r * r * r
         : dim == 2 ? M_PI * r * r
                    : 2.0 * r;
}

/* *p holds at least need items of `size` bytes (kept); 0 when short */
static int grow(void **p, size_t *cap, size_t need, size_t size) {
  if (need <= *cap)
    return 1;
  size_t c = need + need / 4 + 16;
  void *q = realloc(*p, c * size);
  if (!q)
    return 0;
  *p = q;
  *cap = c;
  return 1;
}

/* sums of n values over the ranks (rank order), 16 at a time */
static void sum_over(sph_domain *d, double *v, size_t n) {
  for (size_t k = 0; k < n; k += 16)
    sph_domain_sum(d, v + k, (int)(n - k < 16 ? n - k : 16));
}

/* The points the lists are built over: serially the particles (*np = n,
 * the arrays NULL: positions x, ps's bodies, storage index = index); over
 * MPI ranks the owned particles, then the other ranks' within `radius` of
 * this rank's box, in v->lx, ls (von Mises s, or 0), lbody and lkey
 * (collective). */
static sph_status local_points(sph_verdict *v, const sph_particles *ps,
                               const double *x, const double *s, double radius,
                               size_t *np, sph_error *err) {
  size_t n = ps->n;
  *np = n;
  if (!v->dom)
    return SPH_OK;
  const int64_t *key = sph_domain_storage_index(v->dom);
  sph_status st = SPH_OK;
  if (!grow((void **)&v->pts, &v->pts_cap, 6 * n + 1, sizeof(double)))
    st = sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  for (size_t a = 0; st == SPH_OK && a < n; ++a) {
    double *p = v->pts + 6 * a;
    memcpy(p, x + 3 * a, 3 * sizeof *p);
    p[3] = s ? s[a] : 0.0;
    p[4] = (double)ps->body[a];
    p[5] = (double)key[a];
  }
  SPH_TRY(sph_domain_agree(v->dom, st, err));
  SPH_TRY(sph_domain_box_points(v->dom, v->pts, n, 6, radius, &v->near,
                                &v->near_cap, &v->nnear, err));
  size_t tot = n + v->nnear;
  /* four arrays of one capacity: each grows alike from it */
  size_t c[4] = {v->local_cap, v->local_cap, v->local_cap, v->local_cap};
  if (!grow((void **)&v->lx, &c[0], tot, 3 * sizeof *v->lx) ||
      !grow((void **)&v->ls, &c[1], tot, sizeof *v->ls) ||
      !grow((void **)&v->lbody, &c[2], tot, sizeof *v->lbody) ||
      !grow((void **)&v->lkey, &c[3], tot, sizeof *v->lkey))
    st = sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  else
    v->local_cap = c[0];
  for (size_t a = 0; st == SPH_OK && a < tot; ++a) {
    const double *p = a < n ? v->pts + 6 * a : v->near + 6 * (a - n);
    memcpy(v->lx + 3 * a, p, 3 * sizeof *v->lx);
    v->ls[a] = p[3];
    v->lbody[a] = (int32_t)p[4];
    v->lkey[a] = (int64_t)p[5];
  }
  *np = tot;
  return sph_domain_agree(v->dom, st, err);
}

/* The particles the zig-zag roughness is judged on, from the reference
 * lists in v->nl over the np points X of bodies `body`, the first n of
 * them this rank's (serially all): those of bodies with an interior at
 * least one support across. A particle whose support holds fewer than
 * SPH_ZIGZAG_SURFACE of a full support's particles is at a surface; an
 * interior particle has no surface particle in its support, so the fit
 * around it interpolates a field resolved on every side. A body with fewer
 * interior particles than one support holds is too coarse to judge: no
 * interior at 5 or 6 particles across, 8 at 8 across (a 3D support
 * reaches 2.6 dp). Over MPI ranks the points reach two supports beyond the
 * owned ones, so the surface flags within one support are exact. */
static sph_status zigzag_interior(sph_verdict *v, const sph_scene *s,
                                  const double *X, const int32_t *body,
                                  size_t n, size_t np, sph_error *err) {
  size_t nb = s->nbodies ? s->nbodies : 1;
  const sph_neighbors *nl = v->nl;
  int dim = s->dimension;
  char *flag = calloc(np ? np : 1, 1);
  double *count = calloc(nb, sizeof *count);
  v->body_judged = calloc(nb, 1);
  if (!flag || !count || !v->body_judged) {
    free(flag);
    free(count);
    return sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  }
  /* surface particles (1) */
  for (size_t a = 0; a < np; ++a) {
    double r = v->body_kernel[body[a]].support;
    size_t k = 0;
    for (size_t j = nl->offset[a]; j < nl->offset[a + 1]; ++j)
      k += pair_distance(X, a, (size_t)nl->index[j], dim) < r;
    flag[a] = (double)k < SPH_ZIGZAG_SURFACE * support_count(v, body[a], dim);
  }
  /* interior: no surface particle within the support */
  for (size_t a = 0; a < n; ++a) {
    if (flag[a] == 1)
      continue;
    double r = v->body_kernel[body[a]].support;
    int inside = 1;
    for (size_t j = nl->offset[a]; inside && j < nl->offset[a + 1]; ++j) {
      size_t b = (size_t)nl->index[j];
      inside = !(flag[b] == 1 && pair_distance(X, a, b, dim) < r);
    }
    flag[a] = inside ? 2 : 3; /* 3: near a surface */
  }
  for (size_t a = 0; a < n; ++a)
    count[body[a]] += flag[a] == 2;
  sum_over(v->dom, count, nb);
  double judged = 0.0;
  for (size_t b = 0; b < nb; ++b)
    v->body_judged[b] = count[b] >= support_count(v, (int32_t)b, dim);
  for (size_t a = 0; a < n; ++a)
    judged += v->body_judged[body[a]];
  sum_over(v->dom, &judged, 1);
  v->zigzag_count = (size_t)judged;
  free(flag);
  free(count);
  return SPH_OK;
}

/* Per-body spacings and kernels, the current-configuration neighbour lists
 * (sized by a build in the reference configuration) and the initially
 * adjacent pairs, taken from that same build (over MPI ranks: the pairs
 * whose first particle, by storage index, this rank owns). */
static sph_status lists_create(sph_verdict *v, const sph_scene *s,
                               const sph_particles *ps, sph_error *err) {
  v->fracture_dp = s->stability.fracture_dp;
  v->zigzag_threshold = s->stability.zigzag_max;
  v->zigzag = v->zigzag_max = NAN;
  for (size_t m = 0; m < s->nmaterials; ++m)
    v->stress_floor = fmax(v->stress_floor, s->materials[m].mu);
  v->stress_floor *= SPH_ZIGZAG_FLOOR;
  v->nbodies = s->nbodies;
  v->n = ps->n;
  size_t nb = s->nbodies ? s->nbodies : 1, n = ps->n;
  v->body_dp = calloc(nb, sizeof *v->body_dp);
  v->body_kernel = calloc(nb, sizeof *v->body_kernel);
  if (!v->body_dp || !v->body_kernel ||
      !grow((void **)&v->work, &v->work_cap, n ? n : 1, sizeof *v->work))
    return sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  int dim = s->dimension;
  for (size_t b = 0; b < s->nbodies; ++b) {
    v->body_dp[b] = s->bodies[b].spacing;
    SPH_TRY(sph_kernel_create(&v->body_kernel[b], SPH_KERNEL_WENDLAND_C2, dim,
                              SPH_ZIGZAG_H_OVER_DP * v->body_dp[b], err));
    v->zigzag_radius = fmax(v->zigzag_radius, v->body_kernel[b].support);
  }
  SPH_TRY(sph_neighbors_create(&v->nl, err));
  const double *X = ps->field[SPH_FIELD_POSITION0];
  if (!(v->zigzag_radius > 0.0) || (!v->dom && (!n || !X)))
    return SPH_OK;
  /* over ranks the surface flags need the points within two supports */
  size_t np;
  SPH_TRY(local_points(v, ps, X, NULL, 2.0 * v->zigzag_radius, &np, err));
  const double *lX = v->dom ? v->lx : X;
  const int32_t *body = v->dom ? v->lbody : ps->body;
  const int64_t *key = v->dom ? v->lkey : NULL;
  /* the kernel support (2.6 dp) covers 1.5 dp: one build serves both */
  sph_status st = sph_neighbors_build(v->nl, lX, np, dim, v->zigzag_radius,
                                      body, SPH_PAIRS_SAME_BODY, err);
  SPH_TRY(sph_domain_agree(v->dom, st, err));
  const sph_neighbors *nl = v->nl;
  SPH_TRY(zigzag_interior(v, s, lX, body, n, np, err));
  for (int pass = 0; pass < 2; ++pass) {
    size_t k = 0;
    for (size_t a = 0; a < n; ++a) {
      double lim = SPH_FRACTURE_ADJACENT * v->body_dp[body[a]] *
                   (1.0 + 1e-9); /* round-off of lattice distances */
      int64_t ka = key ? key[a] : (int64_t)a;
      for (size_t j = nl->offset[a]; j < nl->offset[a + 1]; ++j) {
        size_t b = (size_t)nl->index[j];
        int64_t kb = key ? key[b] : (int64_t)b;
        if (kb <= ka || pair_distance(lX, a, b, dim) > lim)
          continue;
        if (pass == 1) {
          v->pairs[2 * k] = ka;
          v->pairs[2 * k + 1] = kb;
        }
        ++k;
      }
    }
    if (pass == 0) {
      v->npairs_local = k;
      v->pairs = malloc((k ? 2 * k : 1) * sizeof *v->pairs);
      st = v->pairs
               ? SPH_OK
               : sph_error_set(err, SPH_ERR_NOMEM, "verdict: %zu pairs", k);
      SPH_TRY(sph_domain_agree(v->dom, st, err));
    }
  }
  double total = (double)v->npairs_local;
  sum_over(v->dom, &total, 1);
  v->npairs = (size_t)total;
  return SPH_OK;
}

sph_status sph_verdict_create(sph_verdict **out, const sph_sim *sim,
                              sph_error *err) {
  sph_verdict *v = calloc(1, sizeof *v);
  if (!v)
    return sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  v->stable = 1;
  v->first = SPH_INDICATOR_NONE;
  for (int i = 0; i < SPH_INDICATOR_COUNT; ++i)
    v->tripped_at[i] = NAN;
  v->J_min = INFINITY;
  v->J_max = -INFINITY;
  v->dom = sim->domain;
  const sph_scene *s = sim->scene;
  v->energy_tracked = !s->has_body_force;
  for (size_t k = 0; k < s->nboundaries; ++k)
    if (s->boundaries[k].kind == SPH_BC_VELOCITY)
      v->energy_tracked = 0;
  const sph_particles *ps = sim->ps;
  const double *m = ps->field[SPH_FIELD_MASS];
  for (size_t a = 0; m && a < ps->n; ++a) {
    double c =
        sph_material_wave_speed(&s->materials[s->bodies[ps->body[a]].material]);
    v->energy_floor += m[a] * c * c;
  }
  sum_over(v->dom, &v->energy_floor, 1);
  v->energy_floor *= SPH_ENERGY_FLOOR;
  sph_status st = SPH_OK;
  if (!grow((void **)&v->parity, &v->parity_cap, ps->n ? ps->n : 1, 1))
    st = sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  st = sph_domain_agree(v->dom, st, err);
  if (st != SPH_OK) {
    sph_verdict_destroy(v);
    return st;
  }
  sph_lattice_parity(s, ps, v->parity);
  for (size_t a = 0; a < ps->n; ++a)
    v->has_parity |= v->parity[a] != 0;
  v->has_parity = (int)sph_domain_max(v->dom, v->has_parity);
  st = lists_create(v, s, ps, err);
  if (st != SPH_OK) {
    sph_verdict_destroy(v);
    return st;
  }
  *out = v;
  return SPH_OK;
}

void sph_verdict_destroy(sph_verdict *v) {
  if (!v)
    return;
  free(v->parity);
  free(v->pairs);
  free(v->body_dp);
  free(v->body_kernel);
  free(v->work);
  free(v->body_judged);
  free(v->pts);
  free(v->near);
  free(v->lx);
  free(v->ls);
  free(v->lbody);
  free(v->lkey);
  free(v->order);
  sph_neighbors_destroy(v->nl);
  free(v);
}

void sph_verdict_fail(sph_verdict *v, sph_indicator i, double t,
                      const char *reason) {
  if (i >= 0 && i < SPH_INDICATOR_COUNT && isnan(v->tripped_at[i]))
    v->tripped_at[i] = t;
  v->nan |= i == SPH_INDICATOR_NAN;
  if (!v->stable)
    return;
  v->stable = 0;
  v->first = i;
  v->t_tripped = t;
  snprintf(v->reason, sizeof v->reason, "%s", reason);
}

void sph_verdict_fail_step(sph_verdict *v, double t, const sph_error *err) {
  char msg[sizeof v->reason];
  sph_error_format(err, msg, sizeof msg);
  sph_verdict_fail(
      v, err->code == SPH_ERR_NUMERIC ? SPH_INDICATOR_NAN : SPH_INDICATOR_STEP,
      t, msg);
}

static int all_finite(const double *f, size_t count) {
  if (!f)
    return 1;
  for (size_t i = 0; i < count; ++i)
    if (!isfinite(f[i]))
      return 0;
  return 1;
}

static int cmp_key(const void *pa, const void *pb) {
  int64_t a = *(const int64_t *)pa, b = *(const int64_t *)pb;
  return (a > b) - (a < b);
}

/* the point holding storage index k in v->order (np rows), or -1 */
static long point_of(const sph_verdict *v, size_t np, int64_t k) {
  const int64_t *r =
      np ? bsearch(&k, v->order, np, 2 * sizeof *v->order, cmp_key) : NULL;
  return r ? (long)r[1] : -1;
}

/* Over MPI ranks: the positions and bodies of the pairs' particles that
 * are not among this rank's np points (a pair stretched beyond the zig-zag
 * radius), from their owners: *extra rows (storage index, np + i) after
 * v->order's np, ascending, their values (x, y, z, body) in v->work. */
static sph_status fetch_partners(sph_verdict *v, size_t n, size_t np,
                                 size_t *extra, sph_error *err) {
  *extra = 0;
  double missing = 0.0;
  for (size_t k = 0; k < 2 * v->npairs_local; ++k)
    missing += point_of(v, np, v->pairs[k]) < 0;
  double any = missing;
  sum_over(v->dom, &any, 1);
  if (any == 0.0)
    return SPH_OK;
  size_t nm = (size_t)missing;
  int64_t *want = malloc((nm + 1) * sizeof *want);
  int64_t *okey = malloc((n + 1) * sizeof *okey);
  double *oval = malloc(4 * (n + 1) * sizeof *oval);
  sph_status st = SPH_OK;
  if (!want || !okey || !oval ||
      !grow((void **)&v->order, &v->order_cap, 2 * (np + nm),
            sizeof *v->order) ||
      !grow((void **)&v->work, &v->work_cap, 4 * nm + 1, sizeof *v->work))
    st = sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  st = sph_domain_agree(v->dom, st, err);
  if (st == SPH_OK) {
    size_t w = 0, o = 0;
    for (size_t k = 0; k < 2 * v->npairs_local; ++k)
      if (point_of(v, np, v->pairs[k]) < 0)
        want[w++] = v->pairs[k];
    for (size_t r = 0; r < np; ++r) { /* owned, by storage index */
      size_t a = (size_t)v->order[2 * r + 1];
      if (a >= n)
        continue;
      okey[o] = v->order[2 * r];
      memcpy(oval + 4 * o, v->lx + 3 * a, 3 * sizeof *oval);
      oval[4 * o++ + 3] = (double)v->lbody[a];
    }
    st = sph_domain_fetch(v->dom, want, nm, okey, oval, o, 4, v->work, err);
  }
  if (st == SPH_OK) {
    for (size_t i = 0; i < nm; ++i) {
      v->order[2 * (np + i)] = want[i];
      v->order[2 * (np + i) + 1] = (int64_t)(np + i);
    }
    qsort(v->order + 2 * np, nm, 2 * sizeof *v->order, cmp_key);
    *extra = nm;
  }
  free(want);
  free(okey);
  free(oval);
  return st;
}

/* the position and body of storage index k among the np points and the
 * extra fetched rows; NULL when neither holds it */
static const double *position_of(const sph_verdict *v, size_t np, size_t extra,
                                 int64_t k, int32_t *body) {
  long p = point_of(v, np, k);
  if (p >= 0) {
    *body = v->lbody[p];
    return v->lx + 3 * p;
  }
  const int64_t *r = extra ? bsearch(&k, v->order + 2 * np, extra,
                                     2 * sizeof *v->order, cmp_key)
                           : NULL;
  if (!r)
    return NULL;
  const double *row = v->work + 4 * ((size_t)r[1] - np);
  *body = (int32_t)row[3];
  return row;
}

/* Largest stretch of the initially adjacent pairs and the count beyond
 * the threshold (over MPI ranks: reduced; the np points of local_points). */
static sph_status fracture_update(sph_verdict *v, const sph_particles *ps,
                                  size_t np, sph_error *err) {
  const double *x = ps->field[SPH_FIELD_POSITION];
  if (!x || !v->npairs || (!v->dom && ps->n != v->n))
    return SPH_OK; /* serially: lists of other particles */
  double worst = 0.0, over = 0.0;
  if (!v->dom) {
    for (size_t k = 0; k < v->npairs; ++k) {
      size_t a = (size_t)v->pairs[2 * k], b = (size_t)v->pairs[2 * k + 1];
      double r = pair_distance(x, a, b, ps->dim) / v->body_dp[ps->body[a]];
      worst = r > worst ? r : worst;
      over += v->fracture_dp > 0.0 && r > v->fracture_dp;
    }
  } else {
    /* each point by storage index; partners beyond the points fetched */
    sph_status st = SPH_OK;
    if (!grow((void **)&v->order, &v->order_cap, 2 * np + 2, sizeof *v->order))
      st = sph_error_set(err, SPH_ERR_NOMEM, "verdict");
    SPH_TRY(sph_domain_agree(v->dom, st, err));
    for (size_t a = 0; a < np; ++a) {
      v->order[2 * a] = v->lkey[a];
      v->order[2 * a + 1] = (int64_t)a;
    }
    qsort(v->order, np, 2 * sizeof *v->order, cmp_key);
    size_t extra;
    SPH_TRY(fetch_partners(v, ps->n, np, &extra, err));
    for (size_t k = 0; k < v->npairs_local; ++k) {
      int32_t body = 0, bb = 0;
      const double *xa = position_of(v, np, extra, v->pairs[2 * k], &body);
      const double *xb = position_of(v, np, extra, v->pairs[2 * k + 1], &bb);
      if (!xa || !xb)
        continue; /* owned by no rank: cannot happen */
      double d2 = 0.0;
      for (int c = 0; c < ps->dim; ++c)
        d2 += (xa[c] - xb[c]) * (xa[c] - xb[c]);
      double r = sqrt(d2) / v->body_dp[body];
      worst = r > worst ? r : worst;
      over += v->fracture_dp > 0.0 && r > v->fracture_dp;
    }
    worst = sph_domain_max(v->dom, worst);
    sum_over(v->dom, &over, 1);
  }
  v->fracture_max_stretch = worst;
  v->fracture_pairs_over = (long)over;
  v->fracture_peak_stretch = fmax(v->fracture_peak_stretch, worst);
  v->fracture_peak_over = v->fracture_pairs_over > v->fracture_peak_over
                              ? v->fracture_pairs_over
                              : v->fracture_peak_over;
  return SPH_OK;
}

/* Roughness R of the von Mises field (stability.h) from the np points of
 * local_points; NaN without the field or for a uniform one. */
static sph_status zigzag_update(sph_verdict *v, const sph_particles *ps,
                                size_t np, sph_error *err) {
  const double *V = ps->field[SPH_FIELD_VOLUME0];
  const double *s = ps->field[SPH_FIELD_VON_MISES];
  v->zigzag = NAN;
  if (!ps->field[SPH_FIELD_POSITION] || !s || !(v->zigzag_radius > 0.0) ||
      !v->zigzag_count || (!v->dom && (!ps->n || ps->n != v->n)))
    return SPH_OK;
  const double *x = v->dom ? v->lx : ps->field[SPH_FIELD_POSITION];
  const double *sl = v->dom ? v->ls : s;
  const int32_t *body = v->dom ? v->lbody : ps->body;
  sph_status st = sph_neighbors_build(v->nl, x, np, ps->dim, v->zigzag_radius,
                                      body, SPH_PAIRS_SAME_BODY, err);
  if (st == SPH_OK &&
      !grow((void **)&v->work, &v->work_cap, ps->n + 1, sizeof *v->work))
    st = sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  SPH_TRY(sph_domain_agree(v->dom, st, err));
  const sph_neighbors *nl = v->nl;
  if (v->dom) /* the serial lists' order: ascending storage index */
    sph_domain_sort_lists_by(v->nl, ps->n, v->lkey);
  double *smooth = v->work;
  long n = (long)ps->n;
  int dim = ps->dim;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    if (!v->body_judged[body[a]]) { /* a body too coarse to judge */
      smooth[a] = NAN;
      continue;
    }
    const sph_kernel *k = &v->body_kernel[body[a]];
    const double *xa = x + 3 * a;
    /* kernel-weighted moments of the offsets d and of s, in one pass */
    double sw = 0.0, sws = 0.0, dm[3] = {0.0, 0.0, 0.0};
    double C[9] = {0}, r[3] = {0.0, 0.0, 0.0};
    for (size_t j = nl->offset[a]; j < nl->offset[a + 1]; ++j) {
      size_t b = (size_t)nl->index[j];
      double w = sph_kernel_eval(k, pair_distance(x, (size_t)a, b, dim));
      double d[3] = {0.0, 0.0, 0.0}, wd[3] = {0.0, 0.0, 0.0};
      for (int c = 0; c < dim; ++c) {
        d[c] = x[3 * b + c] - xa[c];
        wd[c] = w * d[c];
        dm[c] += wd[c];
        r[c] += wd[c] * sl[b];
      }
      sw += w;
      sws += w * sl[b];
      sph_mat3_add_outer(C, wd, d);
    }
    /* isolated particles (no neighbour within the support) are left out */
    if (!(sw > 0.0)) {
      smooth[a] = NAN;
      continue;
    }
    double sm = sws / sw;
    for (int c = 0; c < dim; ++c)
      dm[c] /= sw;
    /* weighted linear fit about the means, evaluated at x_a: covariances
     * sum w (d - dm)(d - dm)^T and sum w (d - dm)(s - sm) */
    for (int r0 = 0; r0 < dim; ++r0) {
      r[r0] -= sw * dm[r0] * sm;
      for (int c = 0; c < dim; ++c)
        C[3 * r0 + c] -= sw * dm[r0] * dm[c];
    }
    double scale = 0.0;
    for (int c = 0; c < dim; ++c)
      scale += C[4 * c] / dim;
    for (int c = dim; c < 3; ++c)
      C[4 * c] = scale;
    double Ci[9] = {0}, g[3];
    double det = sph_mat3_inverse(C, Ci);
    /* neighbours on a line or a plane: no gradient, the plain average */
    if (!(scale > 0.0) ||
        !(det > SPH_ZIGZAG_CONDITION * scale * scale * scale)) {
      smooth[a] = sm;
      continue;
    }
    sph_mat3_vec(Ci, r, g);
    smooth[a] = sm - (g[0] * dm[0] + g[1] * dm[1] + g[2] * dm[2]);
  }
  double sm[2] = {0.0, 0.0}; /* sum V, sum V s */
  for (long a = 0; a < n; ++a)
    if (!isnan(smooth[a])) {
      double Va = V ? V[a] : 1.0;
      sm[0] += Va;
      sm[1] += Va * s[a];
    }
  sph_domain_sum(v->dom, sm, 2);
  double sv = sm[0], mean = sm[1];
  if (!(sv > 0.0))
    return SPH_OK;
  mean /= sv;
  double rs[2] = {0.0, 0.0}; /* rough, spread */
  for (long a = 0; a < n; ++a)
    if (!isnan(smooth[a])) {
      double Va = V ? V[a] : 1.0;
      rs[0] += Va * (s[a] - smooth[a]) * (s[a] - smooth[a]);
      rs[1] += Va * (s[a] - mean) * (s[a] - mean);
    }
  sph_domain_sum(v->dom, rs, 2);
  double rough = rs[0], spread = rs[1];
  /* a uniform field (to round-off of the stress scale) has no pattern */
  if (!(spread > 0.0) || sqrt(spread / sv) <= v->stress_floor)
    return SPH_OK;
  v->zigzag = sqrt(rough / spread);
  v->zigzag_max = fmax(v->zigzag_max, v->zigzag);
  return SPH_OK;
}

/* The frame's momenta (summed over the ranks when it has none) and, at
 * the first frame, their scales sum m |v| and sum m |v| |x|. */
static void momentum_update(sph_verdict *v, const sph_frame *fr, double lin[3],
                            double ang[3]) {
  const sph_particles *ps = fr->ps;
  double mo[6];
  if (fr->momentum) {
    memcpy(mo, fr->momentum, sizeof mo);
  } else {
    sph_momentum(ps, mo, mo + 3);
    sph_domain_sum(v->dom, mo, 6);
  }
  memcpy(lin, mo, 3 * sizeof *lin);
  memcpy(ang, mo + 3, 3 * sizeof *ang);
  if (v->frames != 0)
    return;
  memcpy(v->lin0, lin, 3 * sizeof *lin);
  memcpy(v->ang0, ang, 3 * sizeof *ang);
  const double *m = ps->field[SPH_FIELD_MASS];
  const double *vel = ps->field[SPH_FIELD_VELOCITY];
  const double *x = ps->field[SPH_FIELD_POSITION];
  double sc[2] = {0.0, 0.0};
  for (size_t a = 0; m && vel && x && a < ps->n; ++a) {
    double sp = sqrt(vel[3 * a] * vel[3 * a] + vel[3 * a + 1] * vel[3 * a + 1] +
                     vel[3 * a + 2] * vel[3 * a + 2]);
    double r = sqrt(x[3 * a] * x[3 * a] + x[3 * a + 1] * x[3 * a + 1] +
                    x[3 * a + 2] * x[3 * a + 2]);
    sc[0] += m[a] * sp;
    sc[1] += m[a] * sp * r;
  }
  sph_domain_sum(v->dom, sc, 2);
  v->lin_scale = sc[0];
  v->ang_scale = sc[1];
}

sph_status sph_verdict_observe(sph_verdict *v, const sph_frame *fr,
                               sph_error *err) {
  const sph_particles *ps = fr->ps;
  size_t n = ps->n;
  char msg[256];
  /* non-finite state */
  int bad = !all_finite(ps->field[SPH_FIELD_POSITION], 3 * n) ||
            !all_finite(ps->field[SPH_FIELD_VELOCITY], 3 * n) ||
            !all_finite(ps->field[SPH_FIELD_STRESS], 9 * n);
  bad = (int)sph_domain_max(v->dom, bad);
  if (bad || !isfinite(fr->kinetic + fr->strain)) {
    sph_verdict_fail(v, SPH_INDICATOR_NAN, fr->time, "nan: non-finite state");
    return SPH_OK;
  }
  /* Jacobian */
  const double *J = ps->field[SPH_FIELD_JACOBIAN];
  for (size_t a = 0; J && a < n; ++a) {
    v->J_min = J[a] < v->J_min ? J[a] : v->J_min;
    v->J_max = J[a] > v->J_max ? J[a] : v->J_max;
  }
  if (v->dom && J) {
    v->J_min = sph_domain_min(v->dom, v->J_min);
    v->J_max = sph_domain_max(v->dom, v->J_max);
  }
  if (J && v->J_min <= 0.0) {
    snprintf(msg, sizeof msg, "J <= 0: inverted material (J min %.3g)",
             v->J_min);
    sph_verdict_fail(v, SPH_INDICATOR_JACOBIAN, fr->time, msg);
  }
  /* energy */
  double E = fr->kinetic + fr->strain;
  if (v->frames == 0) {
    v->energy0 = v->energy_max = E;
  }
  v->energy_max = E > v->energy_max ? E : v->energy_max;
  v->energy_final = E;
  double bound = fmax(SPH_ENERGY_GROWTH_MAX * v->energy0, v->energy_floor);
  if (v->energy_tracked && v->energy0 > 0.0 && E > v->energy0 + bound) {
    snprintf(msg, sizeof msg,
             "energy growth: total energy %.4g exceeds the initial %.4g by "
             "more than %.0f %%",
             E, v->energy0, 100 * SPH_ENERGY_GROWTH_MAX);
    sph_verdict_fail(v, SPH_INDICATOR_ENERGY_GROWTH, fr->time, msg);
  }
  /* without external work the kinetic energy is bounded by the initial
   * total, whatever a method books as stored energy (ul-sph books the work
   * of its shear force, which a non-conservative force can drive negative) */
  if (v->energy_tracked && v->energy0 > 0.0 &&
      fr->kinetic > v->energy0 + bound) {
    snprintf(msg, sizeof msg,
             "energy growth: kinetic energy %.4g exceeds the initial total "
             "%.4g by more than %.0f %%",
             fr->kinetic, v->energy0, 100 * SPH_ENERGY_GROWTH_MAX);
    sph_verdict_fail(v, SPH_INDICATOR_ENERGY_GROWTH, fr->time, msg);
  }
  /* momentum drift */
  double lin[3], ang[3];
  momentum_update(v, fr, lin, ang);
  double dl = 0.0, da = 0.0;
  for (int c = 0; c < 3; ++c) {
    dl += pow(lin[c] - v->lin0[c], 2);
    da += pow(ang[c] - v->ang0[c], 2);
  }
  if (v->lin_scale > 0.0)
    v->lin_drift = fmax(v->lin_drift, sqrt(dl) / v->lin_scale);
  if (v->ang_scale > 0.0)
    v->ang_drift = fmax(v->ang_drift, sqrt(da) / v->ang_scale);
  sph_verdict_energy_from_rest(v, fr, E, lin);
  /* pressure checkerboard (over MPI ranks the owned particles change with
   * migration: their parities are taken again) */
  const double *p = ps->field[SPH_FIELD_PRESSURE];
  if (p && v->has_parity) {
    if (v->dom) {
      sph_status st = SPH_OK;
      if (!grow((void **)&v->parity, &v->parity_cap, n + 1, 1))
        st = sph_error_set(err, SPH_ERR_NOMEM, "verdict");
      SPH_TRY(sph_domain_agree(v->dom, st, err));
      sph_lattice_parity(fr->sim->scene, ps, v->parity);
    }
    v->checkerboard = sph_checkerboard_indicator_over(
        v->dom, v->parity, ps->field[SPH_FIELD_VOLUME0], p, n);
    v->checkerboard_max = fmax(v->checkerboard_max, v->checkerboard);
    if (v->checkerboard > SPH_CHECKERBOARD_MAX) {
      snprintf(msg, sizeof msg,
               "pressure checkerboard: indicator %.3g above %.2g",
               v->checkerboard, SPH_CHECKERBOARD_MAX);
      sph_verdict_fail(v, SPH_INDICATOR_CHECKERBOARD, fr->time, msg);
    }
  }
  /* over MPI ranks both lists below see the other ranks' particles near
   * this rank's */
  size_t np = n;
  if (v->dom && ps->field[SPH_FIELD_POSITION] && v->zigzag_radius > 0.0 &&
      (v->npairs || v->zigzag_count))
    SPH_TRY(local_points(v, ps, ps->field[SPH_FIELD_POSITION],
                         ps->field[SPH_FIELD_VON_MISES], v->zigzag_radius, &np,
                         err));
  /* numerical fracture */
  SPH_TRY(fracture_update(v, ps, np, err));
  if (v->fracture_pairs_over > 0) {
    snprintf(msg, sizeof msg,
             "numerical fracture: %ld initially adjacent pair%s more than %g "
             "dp apart (largest %.3g dp)",
             v->fracture_pairs_over, v->fracture_pairs_over == 1 ? "" : "s",
             v->fracture_dp, v->fracture_max_stretch);
    sph_verdict_fail(v, SPH_INDICATOR_FRACTURE, fr->time, msg);
  }
  /* zig-zag pattern of the von Mises stress */
  SPH_TRY(zigzag_update(v, ps, np, err));
  if (v->zigzag_threshold > 0.0 &&
      isgreater(v->zigzag, v->zigzag_threshold)) { /* quiet for NaN */
    snprintf(msg, sizeof msg,
             "zig-zag pattern: von Mises roughness %.3g above %.3g", v->zigzag,
             v->zigzag_threshold);
    sph_verdict_fail(v, SPH_INDICATOR_ZIGZAG, fr->time, msg);
  }
  v->frames++;
  return SPH_OK;
}
