/* Leap-frog in kick-drift-kick form (the "standard leap-frog scheme" of
 * seed 001 sec. 2.3), second order, one rate evaluation per step:
 * p^{n+1/2} = p^n + dt/2 f(x^n); x^{n+1} = x^n + dt p^{n+1/2} / rho0;
 * p^{n+1} = p^{n+1/2} + dt/2 f(x^{n+1}). */
#include <omp.h>

#include "integrators/integrator_impl.h"

static void kick(sph_leapfrog *lf, double h) {
  double t0 = omp_get_wtime();
  long n = (long)(3 * lf->n);
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i)
    lf->p[i] += h * lf->dp[i];
  lf->seconds += omp_get_wtime() - t0;
}

sph_status sph_leapfrog_step(sph_leapfrog *lf, double t, double dt,
                             sph_error *err) {
  sph_status st;
  if (!lf->have_rates && (st = lf->rates(lf->ctx, t, err)) != SPH_OK)
    return st;
  kick(lf, 0.5 * dt);
  if (lf->constrain && (st = lf->constrain(lf->ctx, t, err)) != SPH_OK)
    return st;
  double t0 = omp_get_wtime();
  long n = (long)lf->n;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c)
      lf->x[3 * a + c] += dt * lf->p[3 * a + c] / lf->rho0[a];
  lf->seconds += omp_get_wtime() - t0;
  if ((st = lf->rates(lf->ctx, t + dt, err)) != SPH_OK)
    return st;
  kick(lf, 0.5 * dt);
  lf->have_rates = 1;
  if (lf->constrain)
    st = lf->constrain(lf->ctx, t + dt, err);
  return st;
}
