/* Explicit time integrators over a list of state arrays. A method fills the
 * rates from the current state in `rhs` and fixes the state after each
 * update in `constrain` (prescribed values). */
#ifndef SPH_INTEGRATOR_IMPL_H
#define SPH_INTEGRATOR_IMPL_H

#include <stddef.h>

#include "sph/status.h"

#define SPH_ODE_MAX 8

typedef struct sph_ode {
  int nvec;
  double *y[SPH_ODE_MAX];    /* state, updated in place */
  double *y0[SPH_ODE_MAX];   /* state at the start of the step */
  double *rate[SPH_ODE_MAX]; /* rates the rhs fills */
  size_t len[SPH_ODE_MAX];
  /* stage = 0, 1, ...; t = stage time; dt = the step */
  sph_status (*rhs)(void *ctx, int stage, double t, double dt, sph_error *err);
  sph_status (*constrain)(void *ctx, double t, sph_error *err);
  void *ctx;
  double seconds; /* wall time of the integrator's own updates, summed */
} sph_ode;

/* Appends the state array y of len doubles, allocating its start-of-step
 * copy and its rates (zeroed; *y0 and *rate receive them, the caller frees
 * them). */
sph_status sph_ode_add(sph_ode *ode, double *y, size_t len, double **y0,
                       double **rate, sph_error *err);

/* Two-stage TVD Runge-Kutta (seed 000 eq. 43):
 * u* = u^n + dt f(u^n); u** = u* + dt f(u*); u^{n+1} = (u^n + u**) / 2. */
sph_status sph_tvd_rk2_step(sph_ode *ode, double t, double dt, sph_error *err);

/* Three-stage SSP-RK3 (seed 004 eq. 30, Shu-Osher): u* = u^n + dt f(u^n);
 * u** = 3/4 u^n + 1/4 (u* + dt f(u*)); u^{n+1} = 1/3 u^n + 2/3 (u** +
 * dt f(u**)); stages at t, t + dt, t + dt / 2 (rhs stage 0, 1, 2). */
sph_status sph_ssp_rk3_step(sph_ode *ode, double t, double dt, sph_error *err);

/* Either of the two, chosen once by a method at set-up. */
typedef sph_status (*sph_rk_step)(sph_ode *ode, double t, double dt,
                                  sph_error *err);

/* Leap-frog (kick-drift-kick) for positions x and momenta per reference
 * volume p = rho0 v: `rates` fills dp from the current x and p; the rates
 * of the end of a step are reused at the start of the next. */
typedef struct sph_leapfrog {
  size_t n;
  double *x, *p, *dp;
  const double *rho0;
  int have_rates;
  sph_status (*rates)(void *ctx, double t, sph_error *err);
  sph_status (*constrain)(void *ctx, double t, sph_error *err);
  void *ctx;
  double seconds; /* wall time of the kicks and the drift, summed */
} sph_leapfrog;

sph_status sph_leapfrog_step(sph_leapfrog *lf, double t, double dt,
                             sph_error *err);

#endif
