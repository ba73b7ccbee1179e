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
 * Energies are shifted so that W(I) = 0. The models are listed in
 * material_list.h; each owns its keys beyond the common ones, their checks
 * and its parameters (sph_material.own). */
#ifndef SPH_MATERIAL_H
#define SPH_MATERIAL_H

#include <stddef.h>

#include "sph/status.h"

typedef struct sph_material sph_material;
typedef struct sph_material_params sph_material_params;

/* The most parameters a model keeps of its own (sph_material.own), and the
 * most own keys of all models a material block may give. */
#define SPH_MATERIAL_OWN_MAX 4
#define SPH_MATERIAL_GIVEN_MAX 16
/* The most keys of a material block (sph_material_keys' list). */
#define SPH_MATERIAL_KEYS_MAX 32

typedef struct sph_material_ops {
  const char *name;      /* scene name: "neo-hookean", ... */
  const char *reference; /* seed and equations */
  /* the model's own keys beyond density and the elastic constants, numbers,
   * NULL-terminated (NULL: none) */
  const char *const *keys;
  /* checks the model's own parameters (sph_material_param) once the elastic
   * constants are set and fills m->own; errors name the key in err->key.
   * NULL: nothing of its own */
  sph_status (*init)(sph_material *m, const sph_material_params *p,
                     sph_error *err);
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
  double mu;     /* shear modulus */
  double lambda; /* first Lame parameter */
  double kappa;  /* bulk modulus */
  /* the model's own parameters, laid out by its file (Mooney-Rivlin:
   * varsigma, xi) */
  double own[SPH_MATERIAL_OWN_MAX];
};

/* Parameters as a scene states them: density plus either (E, nu) or
 * (mu, kappa), and the model's own keys given (for mooney-rivlin xi;
 * varsigma follows from mu). */
struct sph_material_params {
  const char *model;
  double density;
  int has_youngs; /* E and nu given */
  double youngs_modulus, poisson_ratio;
  int has_moduli; /* mu and kappa given */
  double shear_modulus, bulk_modulus;
  const char *own_key[SPH_MATERIAL_GIVEN_MAX]; /* among some model's keys */
  double own_value[SPH_MATERIAL_GIVEN_MAX];
  int nown;
};

/* Fills `m` from parameters: sph_material_find, sph_material_elastic and
 * sph_material_own. SPH_ERR_ARG for an unknown model (the message lists the
 * known ones). */
sph_status sph_material_create(sph_material *m, const sph_material_params *p,
                               sph_error *err);

/* The steps of sph_material_create after m->ops is set, for a reader that
 * checks keys as it reads them (the scene): the elastic constants
 * (SPH_ERR_RANGE for density or moduli <= 0, nu outside (-1, 0.5) with
 * err->key "poisson_ratio"; SPH_ERR_ARG unless exactly one pair is given),
 * then the model's own keys (SPH_ERR_ARG for a key of another model; the
 * model's checks, such as xi in [0, mu / (3 sqrt 3)]), errors naming the
 * key in err->key. */
sph_status sph_material_elastic(sph_material *m, const sph_material_params *p,
                                sph_error *err);
sph_status sph_material_own(sph_material *m, const sph_material_params *p,
                            sph_error *err);

/* Own key `key`'s value in p, or def when not given. */
double sph_material_param(const sph_material_params *p, const char *key,
                          double def);

/* The registry (registry.c, made from material_list.h): known model names,
 * NULL-terminated; the model of a name (NULL: none); the names as one
 * "a, b, c" list. */
const char *const *sph_material_models(void);
const sph_material_ops *sph_material_find(const char *name);
const char *sph_material_known(void);

/* Every key a material block may hold, NULL-terminated in out[cap]: the
 * common keys (model, density, the elastic constants; *ncommon of them),
 * then each model's own keys in registry order, once each. */
size_t sph_material_keys(const char **out, size_t cap, size_t *ncommon);

/* The models that own `key`, as "a, b" in buf. */
void sph_material_owners(const char *key, char *buf, size_t size);

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
