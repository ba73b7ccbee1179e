/* Private state of the ul-csph method (seed 001 sec. 3.1). */
#ifndef SPH_UL_CSPH_IMPL_H
#define SPH_UL_CSPH_IMPL_H

#include "integrators/integrator_impl.h"
#include "methods/tl_common_impl.h"

typedef struct ul_csph {
  tl_reference ref; /* X, V, nl, L, w of the current reference x^r */
  double cfl;
  int update_every;      /* steps between reference updates */
  double since;          /* steps since the last update (a state array) */
  double *V0;            /* initial volumes (n_ext) */
  double *Fr, *Jr;       /* F^r and det F^r per point (9 n_ext, n_ext) */
  double *x, *p, *F, *P; /* particle fields */
  double *dp;            /* rate of momentum */
  sph_leapfrog lf;
  int timer_force, timer_update;
  struct sph_sim *sim;
} ul_csph;

#endif
