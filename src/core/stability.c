/* Stability indicators and the verdict of a run (see stability.h). */
#include "sph/stability.h"

#include "sph/geometry.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * a;
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

sph_status sph_verdict_create(sph_verdict **out, const sph_sim *sim,
                              sph_error *err) {
  sph_verdict *v = calloc(1, sizeof *v);
  if (!v)
    return sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  v->stable = 1;
  v->J_min = INFINITY;
  v->J_max = -INFINITY;
  const sph_scene *s = sim->scene;
  v->energy_tracked = !s->has_body_force;
  for (size_t k = 0; k < s->nboundaries; ++k)
    if (s->boundaries[k].kind == SPH_BC_VELOCITY)
      v->energy_tracked = 0;
  const sph_particles *ps = sim->ps;
  v->parity = malloc(ps->n ? ps->n : 1);
  if (!v->parity) {
    sph_verdict_destroy(v);
    return sph_error_set(err, SPH_ERR_NOMEM, "verdict");
  }
  sph_lattice_parity(s, ps, v->parity);
  for (size_t a = 0; a < ps->n; ++a)
    v->has_parity |= v->parity[a] != 0;
  *out = v;
  return SPH_OK;
}

void sph_verdict_destroy(sph_verdict *v) {
  if (!v)
    return;
  free(v->parity);
  free(v);
}

void sph_verdict_fail(sph_verdict *v, double t, const char *reason) {
  if (!v->stable)
    return;
  v->stable = 0;
  v->t_tripped = t;
  snprintf(v->reason, sizeof v->reason, "%s", reason);
}

static int all_finite(const double *f, size_t count) {
  if (!f)
    return 1;
  for (size_t i = 0; i < count; ++i)
    if (!isfinite(f[i]))
      return 0;
  return 1;
}

void sph_verdict_observe(sph_verdict *v, const sph_frame *fr) {
  const sph_particles *ps = fr->ps;
  size_t n = ps->n;
  char msg[256];
  /* non-finite state */
  if (!all_finite(ps->field[SPH_FIELD_POSITION], 3 * n) ||
      !all_finite(ps->field[SPH_FIELD_VELOCITY], 3 * n) ||
      !all_finite(ps->field[SPH_FIELD_STRESS], 9 * n) ||
      !isfinite(fr->kinetic + fr->strain)) {
    v->nan = 1;
    sph_verdict_fail(v, fr->time, "nan: non-finite state");
    return;
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
    sph_verdict_fail(v, fr->time, msg);
  }
  /* energy */
  double E = fr->kinetic + fr->strain;
  if (v->frames == 0) {
    v->energy0 = v->energy_max = E;
  }
  v->energy_max = E > v->energy_max ? E : v->energy_max;
  v->energy_final = E;
  if (v->energy_tracked && v->energy0 > 0.0 &&
      E > (1.0 + SPH_ENERGY_GROWTH_MAX) * v->energy0) {
    snprintf(msg, sizeof msg,
             "energy growth: total energy %.4g exceeds the initial %.4g by "
             "more than %.0f %%",
             E, v->energy0, 100 * SPH_ENERGY_GROWTH_MAX);
    sph_verdict_fail(v, fr->time, msg);
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
      sph_verdict_fail(v, fr->time, msg);
    }
  }
  v->frames++;
}
