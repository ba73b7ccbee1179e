/* A toy constitutive model for test_material_plugin: the small-strain Hooke
 * law stiffened by a factor of its own key `stiffening` (>= 1, default 1).
 * Its registry line is given on the test's command line
 * (-DSPH_MATERIAL_LIST_EXTRA(X)=X(toy, "toy")): one line plus this file. */
#include "materials/material_impl.h"

static const char *const toy_keys[] = {"stiffening", NULL};

static sph_status toy_init(sph_material *m, const sph_material_params *p,
                           sph_error *err) {
  double s = sph_material_param(p, "stiffening", 1.0);
  if (!(s >= 1.0))
    return sph_error_at(err, SPH_ERR_RANGE, NULL, 0, 0, "stiffening",
                        "stiffening must be >= 1, got %g", s);
  m->own[0] = s;
  return SPH_OK;
}

static void toy_stress(const sph_material *m, const double F[9],
                       const double H[9], double J, double P[9]) {
  (void)H, (void)J;
  double tr = F[0] + F[4] + F[8] - 3.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      P[3 * i + j] =
          m->own[0] * (m->mu * (F[3 * i + j] + F[3 * j + i] - 2.0 * (i == j)) +
                       (i == j) * m->lambda * tr);
}

static double toy_energy(const sph_material *m, const double F[9],
                         const double H[9], double J) {
  (void)H, (void)J;
  double tr = F[0] + F[4] + F[8] - 3.0, ee = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double e = 0.5 * (F[3 * i + j] + F[3 * j + i]) - (i == j);
      ee += e * e;
    }
  return m->own[0] * (0.5 * m->lambda * tr * tr + m->mu * ee);
}

const sph_material_ops sph_toy_ops = {
    .name = "toy",
    .reference = "tests/unit/toy_material.c",
    .keys = toy_keys,
    .init = toy_init,
    .stress = toy_stress,
    .energy = toy_energy,
};
