/* Strong-stability-preserving Runge-Kutta integrators, monolithic over every
 * state array of the method: the two-stage TVD-RK2 of seed 000 eq. 43 and
 * the three-stage SSP-RK3 of seed 004 eq. 30. Each stage is a convex
 * combination y = a y^n + b (y + dt f(y)) of forward-Euler steps. */
#include <omp.h>
#include <stdlib.h>

#include "integrators/integrator_impl.h"

/* y0 = y, every state array in one parallel region */
static void save(sph_ode *ode) {
  double t0 = omp_get_wtime();
#pragma omp parallel
  for (int v = 0; v < ode->nvec; ++v) {
    double *y0 = ode->y0[v];
    const double *y = ode->y[v];
    long n = (long)ode->len[v];
#pragma omp for schedule(static) nowait
    for (long i = 0; i < n; ++i)
      y0[i] = y[i];
  }
  ode->seconds += omp_get_wtime() - t0;
}

/* y = a y0 + b (y + dt rate) */
static void combine(sph_ode *ode, double a, double b, double dt) {
  double t0 = omp_get_wtime();
#pragma omp parallel
  for (int v = 0; v < ode->nvec; ++v) {
    double *y = ode->y[v];
    const double *y0 = ode->y0[v], *r = ode->rate[v];
    long n = (long)ode->len[v];
#pragma omp for schedule(static) nowait
    for (long i = 0; i < n; ++i)
      y[i] = a * y0[i] + b * (y[i] + dt * r[i]);
  }
  ode->seconds += omp_get_wtime() - t0;
}

/* one stage: rates at (y, ts), the combination, the constraints at te */
static sph_status stage(sph_ode *ode, int k, double ts, double te, double a,
                        double b, double dt, sph_error *err) {
  sph_status st = ode->rhs(ode->ctx, k, ts, dt, err);
  if (st != SPH_OK)
    return st;
  combine(ode, a, b, dt);
  if (ode->constrain)
    st = ode->constrain(ode->ctx, te, err);
  return st;
}

sph_status sph_tvd_rk2_step(sph_ode *ode, double t, double dt, sph_error *err) {
  save(ode);
  /* u* = u^n + dt f(u^n) */
  SPH_TRY(stage(ode, 0, t, t + dt, 0.0, 1.0, dt, err));
  /* u^{n+1} = 1/2 u^n + 1/2 (u* + dt f(u*)) */
  return stage(ode, 1, t + dt, t + dt, 0.5, 0.5, dt, err);
}

sph_status sph_ssp_rk3_step(sph_ode *ode, double t, double dt, sph_error *err) {
  save(ode);
  /* eq. 30a: U* = U^n + dt R(U^n) */
  SPH_TRY(stage(ode, 0, t, t + dt, 0.0, 1.0, dt, err));
  /* eq. 30b: U** = 3/4 U^n + 1/4 (U* + dt R(U*)), at t + dt / 2 */
  SPH_TRY(stage(ode, 1, t + dt, t + 0.5 * dt, 0.75, 0.25, dt, err));
  /* eq. 30c: U^{n+1} = 1/3 U^n + 2/3 (U** + dt R(U**)) */
  return stage(ode, 2, t + 0.5 * dt, t + dt, 1.0 / 3.0, 2.0 / 3.0, dt, err);
}

sph_status sph_ode_add(sph_ode *ode, double *y, size_t len, double **y0,
                       double **rate, sph_error *err) {
  if (ode->nvec == SPH_ODE_MAX)
    return sph_error_set(err, SPH_ERR_ARG, "more than %d state arrays",
                         SPH_ODE_MAX);
  *y0 = calloc(len ? len : 1, sizeof **y0);
  *rate = calloc(len ? len : 1, sizeof **rate);
  if (!*y0 || !*rate)
    return sph_error_set(err, SPH_ERR_NOMEM, "integrator arrays");
  int v = ode->nvec++;
  ode->y[v] = y;
  ode->y0[v] = *y0;
  ode->rate[v] = *rate;
  ode->len[v] = len;
  return SPH_OK;
}
