/* Two-stage TVD Runge-Kutta of seed 000 eq. 43, monolithic over every state
 * array of the method. */
#include <omp.h>

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

sph_status sph_tvd_rk2_step(sph_ode *ode, double t, double dt, sph_error *err) {
  save(ode);
  /* u* = u^n + dt f(u^n) */
  sph_status st = ode->rhs(ode->ctx, 0, t, dt, err);
  if (st != SPH_OK)
    return st;
  combine(ode, 0.0, 1.0, dt);
  if (ode->constrain && (st = ode->constrain(ode->ctx, t + dt, err)) != SPH_OK)
    return st;
  /* u^{n+1} = 1/2 u^n + 1/2 (u* + dt f(u*)) */
  if ((st = ode->rhs(ode->ctx, 1, t + dt, dt, err)) != SPH_OK)
    return st;
  combine(ode, 0.5, 0.5, dt);
  if (ode->constrain)
    st = ode->constrain(ode->ctx, t + dt, err);
  return st;
}
