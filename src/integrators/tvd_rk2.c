/* Two-stage TVD Runge-Kutta of seed 000 eq. 43, monolithic over every state
 * array of the method. */
#include <string.h>

#include "integrators/integrator_impl.h"

/* y = a y0 + b (y + dt rate) */
static void combine(sph_ode *ode, double a, double b, double dt) {
  for (int v = 0; v < ode->nvec; ++v) {
    double *y = ode->y[v];
    const double *y0 = ode->y0[v], *r = ode->rate[v];
    long n = (long)ode->len[v];
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; ++i)
      y[i] = a * y0[i] + b * (y[i] + dt * r[i]);
  }
}

sph_status sph_tvd_rk2_step(sph_ode *ode, double t, double dt, sph_error *err) {
  for (int v = 0; v < ode->nvec; ++v)
    memcpy(ode->y0[v], ode->y[v], ode->len[v] * sizeof(double));
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
