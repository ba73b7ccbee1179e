/* Private state of the tl-bond method (seed 004). */
#ifndef SPH_TL_BOND_IMPL_H
#define SPH_TL_BOND_IMPL_H

#include "integrators/integrator_impl.h"
#include "methods/common/common_impl.h"

typedef struct tl_bond {
  sph_ref ref;    /* neighbours, volumes, materials, images */
  int bond;       /* stress at the bond-based F^c (eq. 37-39), else at F */
  int pair_speed; /* c_p,ij of eq. 32 in dt and JST, else c_p^Lin */
  double cfl;
  double cp_now; /* largest c_p,ij of the step (the JST's c_p) */
  sph_rk_step integrate;
  /* per slot k = (a -> b), constant in the reference configuration */
  double *gv; /* V_b grad W~_b(X_a), eq. 24 */
  /* dp_a += P_a fa_ab + P_b fb_ab: both V_b (grad W~_b(X_a) -
   * grad W~_a(X_b)) / 2 (eq. 22), or V_b grad W~_b(X_a) and
   * -V_b grad W~_a(X_b) (the force whose power balances eq. 24) */
  double *fa, *fb;
  double *q;       /* V_b W~_b(X_a) (X_b - X_a) / |X_b - X_a|^2, eq. 37-39 */
  double *lap;     /* V_b Lap W~_b(X_a), eq. 27 */
  double *lap_sym; /* V_b (Lap W~_b(X_a) + Lap W~_a(X_b)) / 2, eq. 28 */
  double
      *lap_adj; /* V_b Lap W~_a(X_b): the adjoint outer sums (NULL: eq. 28) */
  double *lap_diag; /* per point: sum_b (lap_adj - lap), ibid. */
  /* per point */
  double *Mc;  /* I - sum_b (X_b - X_a) (x) q_ab, 9 each */
  double *Fc;  /* the F the stress is evaluated at, 9 each */
  double *lam; /* smallest principal stretch (eq. 32) */
  double *v;   /* velocity p / rho0 of the stage */
  /* state (x, p, F: the reference's arrays), RK copies and rates */
  double *x, *p, *F, *P;
  double *x0, *p0, *F0;
  double *dx, *dp, *dF;
  sph_ode ode;
  int timer_force;
  int timer_integration; /* the integrator's updates, the finite check */
  struct sph_sim *sim;
} tl_bond;

#endif
