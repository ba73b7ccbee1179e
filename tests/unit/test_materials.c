/* Materials, run against every model of the registry: P = 0 at F = I,
 * P = dW/dF by finite differences, objectivity, positive energy away from
 * rigid motion, small-strain agreement, and parameter checks. */
#include "test_util.h"

#include <math.h>
#include <string.h>

#include "core/tensor.h"
#include "materials/material.h"

static uint64_t rng = 1;
static double urand(void) { /* splitmix64 */
  uint64_t z = (rng += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

static sph_material make(const char *model, double nu) {
  sph_material m;
  sph_material_params p = {.model = model,
                           .density = 1100,
                           .has_youngs = 1,
                           .youngs_modulus = 17e6,
                           .poisson_ratio = nu};
  if (!strcmp(model, "mooney-rivlin")) {
    p.own_key[0] = "xi";
    p.own_value[0] = 0.3 * 17e6 / (2 * (1 + nu)) / (3 * sqrt(3.0));
    p.nown = 1;
  }
  ck_assert_int_eq(sph_material_create(&m, &p, NULL), SPH_OK);
  return m;
}

static void random_F(double F[9], double amp) {
  do {
    for (int k = 0; k < 9; ++k)
      F[k] = (k % 4 == 0) + amp * (2 * urand() - 1);
  } while (sph_mat3_det(F) < 0.2);
}

static void consistent_stress(const sph_material *m, const double F[9],
                              double P[9]) {
  double H[9];
  sph_mat3_cofactor(F, H);
  sph_material_stress(m, F, H, sph_mat3_det(F), P);
}

static double consistent_energy(const sph_material *m, const double F[9]) {
  double H[9];
  sph_mat3_cofactor(F, H);
  return sph_material_energy(m, F, H, sph_mat3_det(F));
}

static void random_rotation(double Q[9]) {
  double a[3] = {urand() - 0.5, urand() - 0.5, urand() - 0.5};
  double th = 2 * M_PI * urand(), n = sph_vec3_norm(a);
  for (int i = 0; i < 3; ++i)
    a[i] /= n;
  double c = cos(th), s = sin(th);
  double K[9] = {0, -a[2], a[1], a[2], 0, -a[0], -a[1], a[0], 0};
  sph_mat3_identity(Q);
  double K2[9];
  sph_mat3_mul(K, K, K2);
  for (int k = 0; k < 9; ++k)
    Q[k] += s * K[k] + (1 - c) * K2[k];
}

START_TEST(zero_stress_at_identity) {
  for (const char *const *name = sph_material_models(); *name; ++name) {
    sph_material m = make(*name, 0.45);
    double I[9], P[9];
    sph_mat3_identity(I);
    sph_material_stress(&m, I, I, 1.0, P);
    for (int k = 0; k < 9; ++k)
      ck_assert_msg(fabs(P[k]) < 1e-9 * m.mu, "%s P[%d] = %g", *name, k, P[k]);
    ck_assert(fabs(sph_material_energy(&m, I, I, 1.0)) < 1e-9 * m.mu);
  }
}
END_TEST

START_TEST(stress_is_energy_derivative) {
  /* central differences with step e: truncation ~ e^2 W''' and round-off
   * ~ eps W / e; e = 1e-6 gives ~1e-7 relative to mu */
  rng = 11;
  for (const char *const *name = sph_material_models(); *name; ++name) {
    sph_material m = make(*name, 0.45);
    double worst = 0.0;
    for (int trial = 0; trial < 20; ++trial) {
      double F[9], P[9];
      random_F(F, trial < 10 ? 0.05 : 0.35);
      consistent_stress(&m, F, P);
      for (int k = 0; k < 9; ++k) {
        double e = 1e-6, Fp[9], Fm[9];
        memcpy(Fp, F, sizeof Fp);
        memcpy(Fm, F, sizeof Fm);
        Fp[k] += e;
        Fm[k] -= e;
        double fd =
            (consistent_energy(&m, Fp) - consistent_energy(&m, Fm)) / (2 * e);
        double d = fabs(fd - P[k]) / m.kappa;
        worst = d > worst ? d : worst;
      }
    }
    ck_assert_msg(worst < 1e-6, "%s: |P - dW/dF| / kappa = %g", *name, worst);
  }
}
END_TEST

/* the analytic acoustic tensors against central differences of the stress
 * (step 1e-6: truncation ~ e^2 P''' and round-off ~ eps P / e, ~1e-8 of
 * kappa); the models without one fall back to forward differences, checked
 * the same way (their step 1e-7: ~1e-6 of kappa) */
/* dP_id / dF_kd by central differences of step 1e-6 */
static double dP_dF(const sph_material *m, const double F[9], int i, int d,
                    int k) {
  double e = 1e-6, Fp[9], Fm[9], Pp[9], Pm[9];
  memcpy(Fp, F, sizeof Fp);
  memcpy(Fm, F, sizeof Fm);
  Fp[3 * k + d] += e;
  Fm[3 * k + d] -= e;
  consistent_stress(m, Fp, Pp);
  consistent_stress(m, Fm, Pm);
  return (Pp[3 * i + d] - Pm[3 * i + d]) / (2 * e);
}

START_TEST(acoustic_tensor_is_stress_derivative) {
  rng = 17;
  for (const char *const *name = sph_material_models(); *name; ++name) {
    sph_material m = make(*name, 0.45);
    double worst = 0.0;
    for (int trial = 0; trial < 20; ++trial) {
      double F[9], Q[27];
      random_F(F, trial < 10 ? 0.05 : 0.35);
      sph_material_acoustic_tensors(&m, F, Q);
      for (int d = 0; d < 3; ++d)
        for (int k = 0; k < 3; ++k)
          for (int i = 0; i < 3; ++i) {
            /* the symmetric part, as the tensors are returned */
            double fd = 0.5 * (dP_dF(&m, F, i, d, k) + dP_dF(&m, F, k, d, i));
            double dev = fabs(Q[9 * d + 3 * i + k] - fd) / m.kappa;
            worst = dev > worst ? dev : worst;
          }
    }
    ck_assert_msg(worst < 1e-5, "%s: |Q - dP/dF| / kappa = %g", *name, worst);
  }
}
END_TEST

START_TEST(mooney_rivlin_conjugates) {
  /* with independent H and J: P = dW/dF + dW/dH x F + dW/dJ H */
  rng = 5;
  sph_material m = make("mooney-rivlin", 0.45);
  double F[9], H[9], P[9];
  random_F(F, 0.3);
  sph_mat3_cofactor(F, H);
  for (int k = 0; k < 9; ++k)
    H[k] *= 1.0 + 0.02 * (urand() - 0.5); /* H off its consistent value */
  double J = sph_mat3_det(F) * 1.03;
  sph_material_stress(&m, F, H, J, P);
  double e = 1e-6, dF[9], dH[9], dJ;
  for (int k = 0; k < 9; ++k) {
    double Fp[9], Fm[9], Hp[9], Hm[9];
    memcpy(Fp, F, sizeof Fp);
    memcpy(Fm, F, sizeof Fm);
    memcpy(Hp, H, sizeof Hp);
    memcpy(Hm, H, sizeof Hm);
    Fp[k] += e;
    Fm[k] -= e;
    Hp[k] += e;
    Hm[k] -= e;
    dF[k] = (sph_material_energy(&m, Fp, H, J) -
             sph_material_energy(&m, Fm, H, J)) /
            (2 * e);
    dH[k] = (sph_material_energy(&m, F, Hp, J) -
             sph_material_energy(&m, F, Hm, J)) /
            (2 * e);
  }
  dJ = (sph_material_energy(&m, F, H, J + e) -
        sph_material_energy(&m, F, H, J - e)) /
       (2 * e);
  double cross[9];
  sph_mat3_tensor_cross(dH, F, cross);
  double worst = 0.0;
  for (int k = 0; k < 9; ++k) {
    double d = fabs(dF[k] + cross[k] + dJ * H[k] - P[k]) / m.kappa;
    worst = d > worst ? d : worst;
  }
  ck_assert_msg(worst < 1e-6, "conjugate stresses off by %g kappa", worst);
}
END_TEST

START_TEST(objectivity) {
  rng = 3;
  for (const char *const *name = sph_material_models(); *name; ++name) {
    sph_material m = make(*name, 0.45);
    double worst = 0.0, worst_w = 0.0;
    for (int trial = 0; trial < 10; ++trial) {
      double F[9], Q[9], QF[9], P[9], PQ[9], QP[9];
      random_F(F, 0.3);
      random_rotation(Q);
      sph_mat3_mul(Q, F, QF);
      consistent_stress(&m, F, P);
      consistent_stress(&m, QF, PQ);
      sph_mat3_mul(Q, P, QP);
      for (int k = 0; k < 9; ++k) {
        double d = fabs(PQ[k] - QP[k]) / m.kappa;
        worst = d > worst ? d : worst;
      }
      double dw = fabs(consistent_energy(&m, QF) - consistent_energy(&m, F));
      worst_w = dw / m.kappa > worst_w ? dw / m.kappa : worst_w;
    }
    if (!strcmp(*name, "linear-elastic")) {
      /* small-strain Hooke is not frame indifferent: finite rotations make
       * stress, which is why it is only used for the small-strain cable */
      ck_assert_msg(worst > 1e-3, "linear-elastic unexpectedly objective");
    } else {
      ck_assert_msg(worst < 1e-12, "%s: P(QF) - Q P(F) = %g kappa", *name,
                    worst);
      ck_assert_msg(worst_w < 1e-12, "%s: W(QF) - W(F) = %g kappa", *name,
                    worst_w);
    }
  }
}
END_TEST

START_TEST(energy_positive_and_small_strain_agreement) {
  rng = 9;
  sph_material ms[3];
  int n = 0;
  for (const char *const *name = sph_material_models(); *name; ++name)
    ms[n++] = make(*name, 0.3);
  for (int i = 0; i < n; ++i) {
    double F[9];
    random_F(F, 0.2);
    ck_assert(consistent_energy(&ms[i], F) > 0.0);
  }
  /* F = I + eps G: every model gives the linear stress to O(eps^2) */
  double G[9], F[9];
  for (int k = 0; k < 9; ++k)
    G[k] = 2 * urand() - 1;
  for (double eps = 1e-3; eps >= 1e-4; eps /= 10) {
    for (int k = 0; k < 9; ++k)
      F[k] = (k % 4 == 0) + eps * G[k];
    double P0[9];
    consistent_stress(&ms[0], F, P0);
    for (int i = 1; i < n; ++i) {
      double P[9], d = 0.0;
      consistent_stress(&ms[i], F, P);
      for (int k = 0; k < 9; ++k)
        d = fmax(d, fabs(P[k] - P0[k]));
      /* difference relative to the stress scale kappa*eps is O(eps) */
      ck_assert_msg(d / (ms[i].kappa * eps) < 10 * eps,
                    "%s differs from linear by %g at eps %g", ms[i].ops->name,
                    d / (ms[i].kappa * eps), eps);
    }
  }
}
END_TEST

START_TEST(rubber_numbers) {
  sph_material m = make("neo-hookean", 0.45);
  ck_assert(fabs(m.mu - 5.862e6) < 1e3);
  ck_assert(fabs(m.kappa - 5.667e7) < 1e4);
  double c = sph_material_wave_speed(&m);
  ck_assert_msg(fabs(c - 242.0) < 1.0, "c_p = %g", c);
}
END_TEST

START_TEST(parameter_errors) {
  sph_material m;
  sph_error err;
  sph_material_params p = {.model = "neo-hookean",
                           .density = 1000,
                           .has_youngs = 1,
                           .youngs_modulus = 1e6,
                           .poisson_ratio = 0.5};
  ck_assert_int_eq(sph_material_create(&m, &p, &err), SPH_ERR_RANGE);
  ck_assert_str_eq(err.key, "poisson_ratio"); /* checked once, here */
  p.poisson_ratio = -1.0;
  ck_assert_int_eq(sph_material_create(&m, &p, &err), SPH_ERR_RANGE);
  p.poisson_ratio = 0.3;
  p.density = 0.0;
  ck_assert_int_eq(sph_material_create(&m, &p, &err), SPH_ERR_RANGE);
  p.density = 1000;
  p.youngs_modulus = -1;
  ck_assert_int_eq(sph_material_create(&m, &p, &err), SPH_ERR_RANGE);
  p.youngs_modulus = 1e6;
  p.model = "rubbery";
  ck_assert_int_eq(sph_material_create(&m, &p, &err), SPH_ERR_ARG);
  ck_assert_ptr_nonnull(strstr(err.message, "neo-hookean"));
  p.model = "neo-hookean";
  p.has_moduli = 1; /* both pairs given */
  ck_assert_int_eq(sph_material_create(&m, &p, &err), SPH_ERR_ARG);
  p.has_youngs = 0;
  p.shear_modulus = 0.3571e6;
  p.bulk_modulus = 1.67e6;
  ck_assert_int_eq(sph_material_create(&m, &p, &err), SPH_OK);
  ck_assert(fabs(m.mu - 0.3571e6) < 1e-6 && fabs(m.kappa - 1.67e6) < 1e-6);
  p.model = "mooney-rivlin";
  p.own_key[0] = "xi";
  p.own_value[0] = m.mu; /* > mu / (3 sqrt 3) */
  p.nown = 1;
  ck_assert_int_eq(sph_material_create(&m, &p, &err), SPH_ERR_RANGE);
  ck_assert_str_eq(err.key, "xi");
  p.model = "neo-hookean"; /* xi is mooney-rivlin's own */
  ck_assert_int_eq(sph_material_create(&m, &p, &err), SPH_ERR_ARG);
  ck_assert_str_eq(err.message, "xi applies to mooney-rivlin only, not "
                                "neo-hookean");
}
END_TEST

int main(void) {
  Suite *s = suite_create("materials");
  TCase *tc = tcase_create("materials");
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, zero_stress_at_identity);
  tcase_add_test(tc, stress_is_energy_derivative);
  tcase_add_test(tc, acoustic_tensor_is_stress_derivative);
  tcase_add_test(tc, mooney_rivlin_conjugates);
  tcase_add_test(tc, objectivity);
  tcase_add_test(tc, energy_positive_and_small_strain_agreement);
  tcase_add_test(tc, rubber_numbers);
  tcase_add_test(tc, parameter_errors);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
