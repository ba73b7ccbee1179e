/* Private state of the ul-sph method (seed 002). */
#ifndef SPH_UL_SPH_IMPL_H
#define SPH_UL_SPH_IMPL_H

#include <stddef.h>

#include "core/neighbors.h"
#include "solver/sim.h"

typedef enum ul_shear {
  UL_SHEAR_ORIGINAL,          /* SPH-OG: eq. 6-8, 17-18 */
  UL_SHEAR_ARTIFICIAL_STRESS, /* SPH-OAS: OG + Gray et al. (2001) */
  UL_SHEAR_LAPLACIAN          /* SPH-ENOG: eq. 23-24 */
} ul_shear;

/* The options of the method block (ul_sph_options.c). */
typedef struct ul_sph_options {
  ul_shear shear;
  int dual;          /* time_stepping: dual (else single) */
  int pressure_term; /* continuity: riemann (else average) */
  int limited;       /* dissipation: limited (else full) */
  int state_energy;  /* energy: state (else booked) */
  double cfl_ac, cfl_ad;
  double zeta;         /* shear: laplacian */
  double as_eps, as_n; /* shear: artificial-stress */
} ul_sph_options;

/* The method block's options into o (dim: the scene's dimension, of zeta's
 * default). */
sph_status ul_sph_options_parse(sph_node *opt, int dim, ul_sph_options *o,
                                sph_error *err);

struct ul_sph;

/* the two pair loops of a run, chosen once at set-up */
typedef struct ul_sph_loops {
  void (*accelerations)(struct ul_sph *m, double *acc, double *accs);
  void (*continuity)(struct ul_sph *m, double dt);
} ul_sph_loops;

typedef struct ul_sph {
  struct sph_sim *sim;
  ul_sph_loops loops;
  ul_shear shear;
  int dual;          /* dual-criteria stepping (eq. 25-29), else single */
  int pressure_term; /* (P_L - P_R) in U* of the continuity equation */
  int limited;       /* limiter beta of eq. 16, else beta = 1 (full) */
  int state_energy;  /* strain energy from the state, else booked */
  double cfl_ad, cfl_ac, zeta;
  double c0_max;              /* largest c0 of the bodies (eq. 26) */
  double as_eps, as_n, as_w0; /* artificial stress: epsilon, n, W(dp) */
  size_t n;   /* owned particles (over MPI ranks: this rank's) */
  size_t ng;  /* ghosts after them (over MPI ranks), else 0 */
  size_t cap; /* particles the arrays hold: n, or the domain's capacity */
  /* per particle */
  double *x, *v, *rho, *drho, *p, *m; /* x, v: particle fields */
  const double *rho0, *c0, *G;
  double *acc;       /* acceleration of the acoustic step (3) */
  double *acc_shear; /* eq. 24, accumulated (3), laplacian only */
  double *sigma;     /* shear stress (9): OG, OAS, or for output */
  double *R;         /* artificial stress (9), OAS only */
  double *B;         /* correction matrix eq. 31 (9), stress output only */
  double *work;      /* work done against the shear force per particle */
  double *vol;       /* m / rho of the half step */
  int stress;        /* integrate sigma (OG, OAS, or stress output) */
  /* configuration: neighbours and pair geometry of the last update */
  sph_neighbors *nl;
  double *e, *r, *dW; /* per slot: 3, 1, 1 */
  size_t slot_cap;
  double config[2]; /* time of the next configuration update, updates */
  double *xcfg;     /* positions at the last update (3) */
  int timer_config, timer_pressure, timer_shear;
  int timer_integration; /* position Verlet's own loops, the finite check */
} ul_sph;

#endif
