/* Stability indicators and the verdict of a run (see stability.h). */
#include "sph/stability.h"

#include "sph/geometry.h"
#include "sph/material.h"
#include "sph/neighbors.h"
#include "sph/tensor.h"

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

double sph_checkerboard_indicator(const signed char *parity,
                                  const double *volume, const double *f,
                                  size_t n) {
  double sv = 0.0, mean = 0.0;
  for (size_t a = 0; a < n; ++a)
    if (parity[a]) {
      sv += volume[a];
      mean += volume[a] * f[a];
    }
  if (!(sv > 0.0))
    return NAN;
  mean /= sv;
  double proj = 0.0, var = 0.0;
  for (size_t a = 0; a < n; ++a)
    if (parity[a]) {
      double d = f[a] - mean;
      proj += volume[a] * parity[a] * d;
      var += volume[a] * d * d;
    }
  return var > 0.0 ? fabs(proj) / sqrt(sv * var) : 0.0;
}

void sph_lattice_parity(const sph_scene *s, const sph_particles *ps,
                        signed char *parity) {
  for (size_t a = 0; a < ps->n; ++a) {
    const sph_body *b = &s->bodies[ps->body[a]];
    double X[3];
    sph_body_local(b, ps->field[SPH_FIELD_POSITION0] + 3 * a, X);
    parity[a] = 0;
    if (b->distribution == SPH_DIST_RELAX)
      continue;
    double lo[3], hi[3];
    sph_shape_bounds(&b->shape, s->dimension, lo, hi);
    long sum = 0;
    for (int c = 0; c < s->dimension; ++c) {
      double h = b->lattice == SPH_LATTICE_FACES
                     ? (hi[c] - lo[c]) / (b->count[c] - 1)
                     : b->spacing;
      double off = b->lattice == SPH_LATTICE_FACES ? 0.0 : 0.5;
      sum += lround((X[c] - lo[c]) / h - off);
    }
    parity[a] = (sum % 2) ? -1 : 1;
  }
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

/* The particles the zig-zag roughness is judged on (1), from the reference
 * lists in v->nl: those of bodies with an interior at least one support
 * across. A particle whose support holds fewer than SPH_ZIGZAG_SURFACE of
 * a full support's particles is at a surface; an interior particle has no
 * surface particle in its support, so the fit around it interpolates a
 * field resolved on every side. A body with fewer interior particles than
 * one support holds is too coarse to judge (0): no interior at 5 or 6
 * particles across, 8 at 8 across (a 3D support reaches 2.6 dp). */
static sph_status zigzag_interior(sph_verdict *v, const sph_scene *s,
                                  const sph_particles *ps, sph_error *err) {
  size_t n = ps->n, nb = s->nbodies ? s->nbodies : 1;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  const sph_neighbors *nl = v->nl;
  int dim = s->dimension;
  char *flag = v->zigzag_judged = calloc(n ? n : 1, 1);
  size_t *count = calloc(nb, sizeof *count);
  if (!flag || !count) {
    free(count);
    return sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  }
  /* surface particles (1) */
  for (size_t a = 0; a < n; ++a) {
    double r = v->body_kernel[ps->body[a]].support;
    size_t k = 0;
    for (size_t j = nl->offset[a]; j < nl->offset[a + 1]; ++j)
      k += pair_distance(X, a, (size_t)nl->index[j], dim) < r;
    flag[a] =
        (double)k < SPH_ZIGZAG_SURFACE * support_count(v, ps->body[a], dim);
  }
  /* interior: no surface particle within the support */
  for (size_t a = 0; a < n; ++a) {
    if (flag[a] == 1)
      continue;
    double r = v->body_kernel[ps->body[a]].support;
    int inside = 1;
    for (size_t j = nl->offset[a]; inside && j < nl->offset[a + 1]; ++j) {
      size_t b = (size_t)nl->index[j];
      inside = !(flag[b] == 1 && pair_distance(X, a, b, dim) < r);
    }
    flag[a] = inside ? 2 : 3; /* 3: near a surface */
  }
  for (size_t a = 0; a < n; ++a)
    count[ps->body[a]] += flag[a] == 2;
  for (size_t a = 0; a < n; ++a) {
    flag[a] = (double)count[ps->body[a]] >= support_count(v, ps->body[a], dim);
    v->zigzag_count += (size_t)flag[a];
  }
  free(count);
  return SPH_OK;
}

/* Per-body spacings and kernels, the current-configuration neighbour lists
 * (sized by a build in the reference configuration) and the initially
 * adjacent pairs, taken from that same build. */
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
  v->work = malloc((n ? n : 1) * sizeof *v->work);
  if (!v->body_dp || !v->body_kernel || !v->work)
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
  if (!n || !X || !(v->zigzag_radius > 0.0))
    return SPH_OK;
  /* the kernel support (2.6 dp) covers 1.5 dp: one build serves both */
  SPH_TRY(sph_neighbors_build(v->nl, X, n, dim, v->zigzag_radius, ps->body,
                              SPH_PAIRS_SAME_BODY, err));
  const sph_neighbors *nl = v->nl;
  SPH_TRY(zigzag_interior(v, s, ps, err));
  for (int pass = 0; pass < 2; ++pass) {
    size_t k = 0;
    for (size_t a = 0; a < n; ++a) {
      double lim = SPH_FRACTURE_ADJACENT * v->body_dp[ps->body[a]] *
                   (1.0 + 1e-9); /* round-off of lattice distances */
      for (size_t j = nl->offset[a]; j < nl->offset[a + 1]; ++j) {
        size_t b = (size_t)nl->index[j];
        if (b <= a || pair_distance(X, a, b, dim) > lim)
          continue;
        if (pass == 1) {
          v->pairs[2 * k] = (int32_t)a;
          v->pairs[2 * k + 1] = (int32_t)b;
        }
        ++k;
      }
    }
    if (pass == 0) {
      v->npairs = k;
      v->pairs = malloc((k ? 2 * k : 1) * sizeof *v->pairs);
      if (!v->pairs)
        return sph_error_set(err, SPH_ERR_NOMEM, "verdict: %zu pairs", k);
    }
  }
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
  v->energy_floor *= SPH_ENERGY_FLOOR;
  v->parity = malloc(ps->n ? ps->n : 1);
  if (!v->parity) {
    sph_verdict_destroy(v);
    return sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  }
  sph_lattice_parity(s, ps, v->parity);
  for (size_t a = 0; a < ps->n; ++a)
    v->has_parity |= v->parity[a] != 0;
  sph_status st = lists_create(v, s, ps, err);
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
  free(v->zigzag_judged);
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

/* Largest stretch of the initially adjacent pairs and the count beyond
 * the threshold. */
static void fracture_update(sph_verdict *v, const sph_particles *ps) {
  const double *x = ps->field[SPH_FIELD_POSITION];
  if (!x || !v->npairs || ps->n != v->n) /* lists of other particles */
    return;
  double worst = 0.0;
  long over = 0;
  for (size_t k = 0; k < v->npairs; ++k) {
    size_t a = (size_t)v->pairs[2 * k], b = (size_t)v->pairs[2 * k + 1];
    double r = pair_distance(x, a, b, ps->dim) / v->body_dp[ps->body[a]];
    worst = r > worst ? r : worst;
    over += v->fracture_dp > 0.0 && r > v->fracture_dp;
  }
  v->fracture_max_stretch = worst;
  v->fracture_pairs_over = over;
  v->fracture_peak_stretch = fmax(v->fracture_peak_stretch, worst);
  v->fracture_peak_over =
      over > v->fracture_peak_over ? over : v->fracture_peak_over;
}

/* Roughness R of the von Mises field (stability.h); NaN without the field
 * or for a uniform one. */
static sph_status zigzag_update(sph_verdict *v, const sph_particles *ps,
                                sph_error *err) {
  const double *x = ps->field[SPH_FIELD_POSITION];
  const double *s = ps->field[SPH_FIELD_VON_MISES];
  const double *V = ps->field[SPH_FIELD_VOLUME0];
  v->zigzag = NAN;
  if (!x || !s || !ps->n || ps->n != v->n || !(v->zigzag_radius > 0.0) ||
      !v->zigzag_count)
    return SPH_OK;
  SPH_TRY(sph_neighbors_build(v->nl, x, ps->n, ps->dim, v->zigzag_radius,
                              ps->body, SPH_PAIRS_SAME_BODY, err));
  const sph_neighbors *nl = v->nl;
  double *smooth = v->work;
  long n = (long)ps->n;
  int dim = ps->dim;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    if (!v->zigzag_judged[a]) { /* a body too coarse to judge */
      smooth[a] = NAN;
      continue;
    }
    const sph_kernel *k = &v->body_kernel[ps->body[a]];
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
        r[c] += wd[c] * s[b];
      }
      sw += w;
      sws += w * s[b];
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
  double sv = 0.0, mean = 0.0;
  for (long a = 0; a < n; ++a)
    if (!isnan(smooth[a])) {
      double Va = V ? V[a] : 1.0;
      sv += Va;
      mean += Va * s[a];
    }
  if (!(sv > 0.0))
    return SPH_OK;
  mean /= sv;
  double rough = 0.0, spread = 0.0;
  for (long a = 0; a < n; ++a)
    if (!isnan(smooth[a])) {
      double Va = V ? V[a] : 1.0;
      rough += Va * (s[a] - smooth[a]) * (s[a] - smooth[a]);
      spread += Va * (s[a] - mean) * (s[a] - mean);
    }
  /* a uniform field (to round-off of the stress scale) has no pattern */
  if (!(spread > 0.0) || sqrt(spread / sv) <= v->stress_floor)
    return SPH_OK;
  v->zigzag = sqrt(rough / spread);
  v->zigzag_max = fmax(v->zigzag_max, v->zigzag);
  return SPH_OK;
}

sph_status sph_verdict_observe(sph_verdict *v, const sph_frame *fr,
                               sph_error *err) {
  const sph_particles *ps = fr->ps;
  size_t n = ps->n;
  char msg[256];
  /* non-finite state */
  if (!all_finite(ps->field[SPH_FIELD_POSITION], 3 * n) ||
      !all_finite(ps->field[SPH_FIELD_VELOCITY], 3 * n) ||
      !all_finite(ps->field[SPH_FIELD_STRESS], 9 * n) ||
      !isfinite(fr->kinetic + fr->strain)) {
    sph_verdict_fail(v, SPH_INDICATOR_NAN, fr->time, "nan: non-finite state");
    return SPH_OK;
  }
  /* Jacobian */
  const double *J = ps->field[SPH_FIELD_JACOBIAN];
  for (size_t a = 0; J && a < n; ++a) {
    v->J_min = J[a] < v->J_min ? J[a] : v->J_min;
    v->J_max = J[a] > v->J_max ? J[a] : v->J_max;
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
  sph_momentum(ps, lin, ang);
  if (v->frames == 0) {
    memcpy(v->lin0, lin, sizeof lin);
    memcpy(v->ang0, ang, sizeof ang);
    const double *m = ps->field[SPH_FIELD_MASS];
    const double *vel = ps->field[SPH_FIELD_VELOCITY];
    const double *x = ps->field[SPH_FIELD_POSITION];
    for (size_t a = 0; m && vel && x && a < n; ++a) {
      double sp =
          sqrt(vel[3 * a] * vel[3 * a] + vel[3 * a + 1] * vel[3 * a + 1] +
               vel[3 * a + 2] * vel[3 * a + 2]);
      double r = sqrt(x[3 * a] * x[3 * a] + x[3 * a + 1] * x[3 * a + 1] +
                      x[3 * a + 2] * x[3 * a + 2]);
      v->lin_scale += m[a] * sp;
      v->ang_scale += m[a] * sp * r;
    }
  }
  double dl = 0.0, da = 0.0;
  for (int c = 0; c < 3; ++c) {
    dl += pow(lin[c] - v->lin0[c], 2);
    da += pow(ang[c] - v->ang0[c], 2);
  }
  if (v->lin_scale > 0.0)
    v->lin_drift = fmax(v->lin_drift, sqrt(dl) / v->lin_scale);
  if (v->ang_scale > 0.0)
    v->ang_drift = fmax(v->ang_drift, sqrt(da) / v->ang_scale);
  /* pressure checkerboard */
  const double *p = ps->field[SPH_FIELD_PRESSURE];
  if (p && v->has_parity) {
    v->checkerboard = sph_checkerboard_indicator(
        v->parity, ps->field[SPH_FIELD_VOLUME0], p, n);
    v->checkerboard_max = fmax(v->checkerboard_max, v->checkerboard);
    if (v->checkerboard > SPH_CHECKERBOARD_MAX) {
      snprintf(msg, sizeof msg,
               "pressure checkerboard: indicator %.3g above %.2g",
               v->checkerboard, SPH_CHECKERBOARD_MAX);
      sph_verdict_fail(v, SPH_INDICATOR_CHECKERBOARD, fr->time, msg);
    }
  }
  /* numerical fracture */
  fracture_update(v, ps);
  if (v->fracture_pairs_over > 0) {
    snprintf(msg, sizeof msg,
             "numerical fracture: %ld initially adjacent pair%s more than %g "
             "dp apart (largest %.3g dp)",
             v->fracture_pairs_over, v->fracture_pairs_over == 1 ? "" : "s",
             v->fracture_dp, v->fracture_max_stretch);
    sph_verdict_fail(v, SPH_INDICATOR_FRACTURE, fr->time, msg);
  }
  /* zig-zag pattern of the von Mises stress */
  sph_status st = zigzag_update(v, ps, err);
  if (st != SPH_OK)
    return st;
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
