/* Kernels: unit integral and zero gradient integral on a fine lattice in
 * 1D/2D/3D, derivatives against finite differences, continuity at the
 * piece boundaries, compact support, finite Laplacian at r = 0. */
#include "test_util.h"

#include <math.h>

#include "sph/kernel.h"

static double lattice_integral(const sph_kernel *k, double dx, int grad_axis) {
  int n = (int)ceil(k->support / dx) + 1;
  int nj = k->dim >= 2 ? n : 0, nl = k->dim >= 3 ? n : 0;
  double s = 0.0, vol = pow(dx, k->dim);
  for (int i = -n; i <= n; ++i)
    for (int j = -nj; j <= nj; ++j)
      for (int l = -nl; l <= nl; ++l) {
        /* offset by dx/3 so no lattice point sits at the origin */
        double r3[3] = {(i + 1.0 / 3.0) * dx, j * dx, l * dx};
        double r = sqrt(r3[0] * r3[0] + r3[1] * r3[1] + r3[2] * r3[2]);
        if (grad_axis < 0) {
          s += sph_kernel_eval(k, r) * vol;
        } else {
          double g[3];
          sph_kernel_gradient(k, r3, r, g);
          s += g[grad_axis] * vol;
        }
      }
  return s;
}

START_TEST(integrates_to_one) {
  /* midpoint-type lattice sums of a C2 (or smoother) compactly supported
   * function converge like dx^2 at worst; with dx = h/20 (h/12 in 3D) the
   * error is below 1e-5 for every kernel here */
  for (int t = 0; t < SPH_KERNEL_COUNT; ++t)
    for (int d = 1; d <= 3; ++d) {
      sph_kernel k;
      ck_assert_int_eq(sph_kernel_create(&k, t, d, 1.0, NULL), SPH_OK);
      double dx = d == 3 ? 1.0 / 12.0 : 1.0 / 20.0;
      double e = fabs(lattice_integral(&k, dx, -1) - 1.0);
      ck_assert_msg(e < 1e-5, "%s d=%d integral error %g",
                    sph_kernel_type_name(t), d, e);
    }
}
END_TEST

START_TEST(gradient_integrates_to_zero) {
  for (int t = 0; t < SPH_KERNEL_COUNT; ++t)
    for (int d = 1; d <= 3; ++d) {
      sph_kernel k;
      sph_kernel_create(&k, t, d, 0.7, NULL);
      double dx = d == 3 ? 0.7 / 8.0 : 0.7 / 16.0;
      /* the lattice is symmetric in every axis but x (offset), so the y
       * and z integrals vanish by symmetry to round-off; the x integral by
       * smoothness of W to truncation order */
      for (int c = 0; c < d; ++c) {
        double s = lattice_integral(&k, dx, c);
        ck_assert_msg(fabs(s) < (c == 0 ? 1e-4 : 1e-12),
                      "%s d=%d axis %d gradient integral %g",
                      sph_kernel_type_name(t), d, c, s);
      }
    }
}
END_TEST

START_TEST(derivatives_match_finite_differences) {
  for (int t = 0; t < SPH_KERNEL_COUNT; ++t)
    for (int d = 1; d <= 3; ++d) {
      sph_kernel k;
      sph_kernel_create(&k, t, d, 1.3, NULL);
      double worst1 = 0.0, worst2 = 0.0, scale = k.norm;
      for (int i = 1; i < 60; ++i) {
        double r = k.support * i / 60.0, e = 1e-5 * k.h;
        double fd1 =
            (sph_kernel_eval(&k, r + e) - sph_kernel_eval(&k, r - e)) / (2 * e);
        double fd2 =
            (sph_kernel_dwdr(&k, r + e) - sph_kernel_dwdr(&k, r - e)) / (2 * e);
        double e1 = fabs(fd1 - sph_kernel_dwdr(&k, r)) * k.h / scale;
        double e2 = fabs(fd2 - sph_kernel_d2wdr2(&k, r)) * k.h * k.h / scale;
        worst1 = e1 > worst1 ? e1 : worst1;
        /* W'' of the cubic spline jumps at q = 1 and q = 2: skip the
         * samples whose stencil straddles a break */
        double q = r / k.h;
        if (fabs(q - 1.0) > 1e-3 && fabs(q - 2.0) > 1e-3)
          worst2 = e2 > worst2 ? e2 : worst2;
      }
      /* central differences: O(e^2) truncation, O(eps/e) round-off */
      ck_assert_msg(worst1 < 1e-8, "%s d=%d dW/dr error %g",
                    sph_kernel_type_name(t), d, worst1);
      ck_assert_msg(worst2 < 1e-6, "%s d=%d d2W/dr2 error %g",
                    sph_kernel_type_name(t), d, worst2);
    }
}
END_TEST

START_TEST(continuous_and_compact) {
  for (int t = 0; t < SPH_KERNEL_COUNT; ++t)
    for (int d = 1; d <= 3; ++d) {
      sph_kernel k;
      sph_kernel_create(&k, t, d, 1.0, NULL);
      for (double q = 1.0; q < k.kappa; q += 1.0) {
        double lo = q - 1e-12, hi = q + 1e-12;
        ck_assert(fabs(sph_kernel_eval(&k, lo) - sph_kernel_eval(&k, hi)) <
                  1e-10);
        ck_assert(fabs(sph_kernel_dwdr(&k, lo) - sph_kernel_dwdr(&k, hi)) <
                  1e-10);
      }
      ck_assert(sph_kernel_eval(&k, k.support) == 0.0);
      ck_assert(fabs(sph_kernel_dwdr(&k, k.support)) < 1e-15);
      ck_assert(sph_kernel_eval(&k, 1.5 * k.support) == 0.0);
      ck_assert(sph_kernel_eval(&k, 0.0) > 0.0);
      ck_assert(sph_kernel_dwdr(&k, 0.5 * k.h) < 0.0);
      /* Laplacian at 0 equals d * W''(0) and is the limit of the r > 0 form */
      double l0 = sph_kernel_laplacian(&k, 0.0);
      ck_assert(isfinite(l0));
      ck_assert(fabs(l0 - d * sph_kernel_d2wdr2(&k, 0.0)) < 1e-12 * fabs(l0));
      ck_assert(fabs(sph_kernel_laplacian(&k, 1e-7) - l0) < 1e-5 * fabs(l0));
    }
}
END_TEST

START_TEST(laplacian_matches_radial_form) {
  /* Lap W = W'' + (d-1) W'/r against a finite-difference Laplacian */
  for (int t = 0; t < SPH_KERNEL_COUNT; ++t)
    for (int d = 2; d <= 3; ++d) {
      sph_kernel k;
      sph_kernel_create(&k, t, d, 1.0, NULL);
      double e = 1e-4, x[3] = {0.31, 0.42, d == 3 ? 0.17 : 0.0};
      double r0 = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
      double fd = 0.0;
      for (int c = 0; c < d; ++c) {
        double xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]};
        xp[c] += e;
        xm[c] -= e;
        fd += (sph_kernel_eval(
                   &k, sqrt(xp[0] * xp[0] + xp[1] * xp[1] + xp[2] * xp[2])) -
               2 * sph_kernel_eval(&k, r0) +
               sph_kernel_eval(
                   &k, sqrt(xm[0] * xm[0] + xm[1] * xm[1] + xm[2] * xm[2]))) /
              (e * e);
      }
      ck_assert_msg(fabs(fd - sph_kernel_laplacian(&k, r0)) < 1e-5 * k.norm,
                    "%s d=%d Laplacian %g vs FD %g", sph_kernel_type_name(t), d,
                    sph_kernel_laplacian(&k, r0), fd);
    }
}
END_TEST

START_TEST(rejects_bad_parameters) {
  sph_kernel k;
  sph_error err;
  ck_assert_int_eq(sph_kernel_create(&k, SPH_KERNEL_CUBIC, 4, 1.0, &err),
                   SPH_ERR_ARG);
  ck_assert_int_eq(sph_kernel_create(&k, SPH_KERNEL_CUBIC, 3, 0.0, &err),
                   SPH_ERR_ARG);
  ck_assert_int_eq(sph_kernel_type_from_name("wendland-c2"),
                   SPH_KERNEL_WENDLAND_C2);
  ck_assert_int_eq(sph_kernel_type_from_name("gauss"), -1);
  ck_assert_str_eq(sph_kernel_type_name(SPH_KERNEL_QUINTIC), "quintic");
}
END_TEST

int main(void) {
  Suite *s = suite_create("kernel");
  TCase *tc = tcase_create("kernel");
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, integrates_to_one);
  tcase_add_test(tc, gradient_integrates_to_zero);
  tcase_add_test(tc, derivatives_match_finite_differences);
  tcase_add_test(tc, continuous_and_compact);
  tcase_add_test(tc, laplacian_matches_radial_form);
  tcase_add_test(tc, rejects_bad_parameters);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
