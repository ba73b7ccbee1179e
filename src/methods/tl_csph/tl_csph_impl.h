/* Private state of the tl-csph method (seed 001 sec. 2). */
#ifndef SPH_TL_CSPH_IMPL_H
#define SPH_TL_CSPH_IMPL_H

#include "integrators/integrator_impl.h"
#include "methods/common/common_impl.h"

typedef struct tl_csph {
  sph_ref ref;
  double cfl;
  int current_wave_speed; /* dt from the current state's c_p */
  double *x, *p, *F, *P;  /* particle fields */
  double *dp;             /* rate of momentum */
  sph_leapfrog lf;
  int timer_force;
  int timer_integration; /* the integrator's updates, the finite check */
  struct sph_sim *sim;
} tl_csph;

#endif
