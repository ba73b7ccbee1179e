/* Constitutive models: first Piola-Kirchhoff stress P(F, H, J), strain
 * energy per unit reference volume and p-wave speed.
 *
 * The stress takes the three strain measures of seed 000 so that mixed
 * methods pass their independent H and J; displacement or {p,F} methods pass
 * H = cof F and J = det F. Models (one ops table each):
 *  - linear-elastic: small strain, eps = sym(F) - I, P = lambda tr(eps) I +
 *    2 mu eps (for the cable, seed 000 sec. 8.1); not objective, by design;
 *  - neo-hookean: seed 003 eq. 6-7, psi = mu/2 (J^-2/3 F:F - 3) +
 *    kappa/2 (J - 1)^2, P = mu J^-2/3 (F - 1/3 (F:F) F^-T) + p H with
 *    F^-T = H / J, p = kappa (J - 1);
 *  - mooney-rivlin: polyconvex model of seed 000 eq. 8-12 with
 *    2 varsigma + 3 sqrt(3) xi = mu; xi = 0 recovers neo-hookean.
 * Energies are shifted so that W(I) = 0. */
#ifndef SPH_MATERIAL_H
#define SPH_MATERIAL_H

#include "sph/status.h"

typedef struct sph_material sph_material;

typedef struct sph_material_ops {
  const char *name;      /* scene name: "neo-hookean", ... */
  const char *reference; /* seed and equations */
  void (*stress)(const sph_material *m, const double F[9], const double H[9],
                 double J, double P[9]);
  double (*energy)(const sph_material *m, const double F[9], const double H[9],
                   double J);
  /* acoustic tensors Q_ik = dP_id / dF_kd of P(F, cof F, det F) for the
   * material directions e_d, d = 0, 1, 2, at Q + 9 d (may be NULL: finite
   * differences of `stress`) */
  void (*acoustic)(const sph_material *m, const double F[9], double Q[27]);
} sph_material_ops;

struct sph_material {
  const sph_material_ops *ops;
  char name[64];  /* the scene's name for this material */
  double density; /* reference density rho0, kg/m^3 */
  double youngs_modulus;
  double poisson_ratio;
  double mu;       /* shear modulus */
  double lambda;   /* first Lame parameter */
  double kappa;    /* bulk modulus */
  double varsigma; /* Mooney-Rivlin (seed 000 eq. 8) */
  double xi;
};

/* Parameters as a scene states them: density plus either (E, nu) or
 * (mu, kappa); for mooney-rivlin optionally xi (varsigma follows from mu). */
typedef struct sph_material_params {
  const char *model;
  double density;
  int has_youngs; /* E and nu given */
  double youngs_modulus, poisson_ratio;
  int has_moduli; /* mu and kappa given */
  double shear_modulus, bulk_modulus;
  int has_xi;
  double xi;
} sph_material_params;

/* Fills `m` from parameters; SPH_ERR_RANGE for nu outside (-1, 0.5), density
 * or moduli <= 0, xi outside [0, mu / (3 sqrt 3)]; SPH_ERR_ARG for an unknown
 * model (the message lists the known ones). */
sph_status sph_material_create(sph_material *m, const sph_material_params *p,
                               sph_error *err);

/* Known model names, NULL-terminated. */
const char *const *sph_material_models(void);

/* p-wave speed in the reference state: sqrt((lambda + 2 mu) / rho0). */
double sph_material_wave_speed(const sph_material *m);

/* The acoustic tensors of the material directions e_0, e_1, e_2 at F (with
 * H = cof F, J = det F), symmetrised, at Q + 9 d: rho0 c^2 are their
 * eigenvalues. Analytic where the model gives it, else forward finite
 * differences of the stress. */
void sph_material_acoustic_tensors(const sph_material *m, const double F[9],
                                   double Q[27]);

static inline void sph_material_stress(const sph_material *m, const double F[9],
                                       const double H[9], double J,
                                       double P[9]) {
  m->ops->stress(m, F, H, J, P);
}

static inline double sph_material_energy(const sph_material *m,
                                         const double F[9], const double H[9],
                                         double J) {
  return m->ops->energy(m, F, H, J);
}

#endif
