/* Private state of the tl-jst method (seed 000). */
#ifndef SPH_TL_JST_IMPL_H
#define SPH_TL_JST_IMPL_H

#include <stddef.h>

#include "integrators/integrator_impl.h"
#include "methods/common/common_impl.h"

typedef enum tl_jst_fields { TL_JST_PF, TL_JST_PFJ, TL_JST_PFHJ } tl_jst_fields;
typedef enum tl_jst_force {
  TL_JST_CONSERVATIVE, /* seed 000 eq. 29c / 42 */
  TL_JST_SYMMETRIC,    /* seed 003 eq. 11 */
  TL_JST_EQ30,         /* seed 000 eq. 30: uncorrected gradient */
  TL_JST_EQ31          /* seed 000 eq. 31: corrected gradient of W~ */
} tl_jst_force;

typedef struct tl_jst {
  tl_jst_fields fields;
  tl_jst_force force;
  double cfl;
  int current_wave_speed; /* dt from the current state's c_p */
  int wave_speed_every;   /* the current c_p every that many steps */
  double c_held;          /* the c_p of the last of those steps (0: none) */
  sph_ref ref;            /* neighbours, gradients, materials */
  double *lap;            /* V_b Lap W~_b(X_a) per slot (NULL if unused) */
  double *fgrad;          /* eq. 31: grad W~1_b(X_a) per slot */
  double *fgrad_self;     /* eq. 31: grad W~1_a(X_a) per particle */
  size_t *rev;            /* eq. 31: slot of (b -> a) for slot (a -> b) */
  /* L[p] for the JST term, summed in the conservative sweep (NULL: the
   * term sums it) */
  double *lu_p;
  /* the pair sweep of the chosen force, picked once at set-up */
  void (*sweep)(struct tl_jst *m, long n);
  /* state (particle fields) and its RK copies and rates */
  double *x, *p, *F, *H, *J;
  double *x0, *p0, *F0, *H0, *J0;
  double *dx, *dp, *dF, *dH, *dJ;
  double *P;       /* first Piola-Kirchhoff stress of the stage */
  double *xmoment; /* X^chi of seed 000 eq. 45 */
  sph_ode ode;
  sph_rk_step integrate; /* TVD-RK2 or SSP-RK3 */
  int timer_force;
  int timer_integration; /* the integrator's updates, the finite check */
  struct sph_sim *sim;
} tl_jst;

#endif
