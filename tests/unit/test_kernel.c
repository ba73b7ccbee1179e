/* Kernels: unit integral and zero gradient integral on a fine lattice in
 * 1D/2D/3D, derivatives against finite differences, continuity at the
 * piece boundaries, compact support, Laplacian (finite at r = 0), argument
 * checks and the name table. */
#include "test_util.h"

#include <math.h>

#include "core/kernel.h"

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

/* Lattice sums with spacing dx = h/20. The kernels are C2 with kinks of
 * order 3 (|r|^3 at the origin for the 1D Wendland functions, jumps of the
 * splines' third derivative), so the sum of W converges as O((dx/h)^4)
 * ~ 6e-6 with O(0.1) constants: tolerance 1e-6 (measured worst 4.7e-8,
 * Wendland C2 in 1D). The gradient is one order rougher: O((dx/h)^3 / h) =
 * 1.25e-4 / h (measured worst 8.7e-6 / h). */
START_TEST(integrates_to_one) {
  for (int t = 0; t < SPH_KERNEL_COUNT; ++t)
    for (int d = 1; d <= 3; ++d) {
      sph_kernel k;
      ck_assert_int_eq(sph_kernel_create(&k, t, d, 1.0, NULL), SPH_OK);
      double e = fabs(lattice_integral(&k, k.h / 20.0, -1) - 1.0);
      ck_assert_msg(e < 1e-6, "%s d=%d integral error %g",
                    sph_kernel_type_name(t), d, e);
    }
}
END_TEST

START_TEST(gradient_integrates_to_zero) {
  for (int t = 0; t < SPH_KERNEL_COUNT; ++t)
    for (int d = 1; d <= 3; ++d) {
      sph_kernel k;
      ck_assert_int_eq(sph_kernel_create(&k, t, d, 0.7, NULL), SPH_OK);
      /* the lattice is symmetric in every axis but x (offset), so the y and
       * z integrals vanish by symmetry up to the round-off of sums of size
       * ~1/h; the x integral to truncation order */
      for (int c = 0; c < d; ++c) {
        double s = lattice_integral(&k, k.h / 20.0, c);
        double tol = (c == 0 ? 1.25e-4 : 1e-13) / k.h;
        ck_assert_msg(fabs(s) < tol, "%s d=%d axis %d gradient integral %g",
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
        /* the third derivative of the splines jumps at integer q, which
         * makes the difference of W' first order there: skip those */
        double q = r / k.h;
        if (fabs(q - 1.0) > 1e-3 && fabs(q - 2.0) > 1e-3)
          worst2 = e2 > worst2 ? e2 : worst2;
      }
      /* central differences: O(e^2) truncation ~1e-10, O(eps/e) round-off
       * ~1e-11, relative to norm / h^k */
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
      /* W, W' and W'' are continuous at the breaks of the piecewise
       * kernels (q = 1, 2); a step of 2e-12 h moves them by < 1e-11 W(0)
       * (in units of h) */
      for (double q = 1.0; q < k.kappa; q += 1.0) {
        double lo = q - 1e-12, hi = q + 1e-12;
        double tol = 1e-10 * sph_kernel_eval(&k, 0.0);
        ck_assert(fabs(sph_kernel_eval(&k, lo) - sph_kernel_eval(&k, hi)) <
                  tol);
        ck_assert(fabs(sph_kernel_dwdr(&k, lo) - sph_kernel_dwdr(&k, hi)) <
                  tol);
        ck_assert(fabs(sph_kernel_d2wdr2(&k, lo) - sph_kernel_d2wdr2(&k, hi)) <
                  tol);
      }
      /* zero at the support (to the round-off of the polynomial pieces),
       * exactly zero beyond it */
      ck_assert(fabs(sph_kernel_eval(&k, k.support)) < 1e-15 * k.norm);
      ck_assert(fabs(sph_kernel_dwdr(&k, k.support)) < 1e-15 * k.norm);
      for (double f = 1.0 + 1e-12; f < 3.0; f += 0.25) {
        ck_assert(sph_kernel_eval(&k, f * k.support) == 0.0);
        ck_assert(sph_kernel_dwdr(&k, f * k.support) == 0.0);
        ck_assert(sph_kernel_d2wdr2(&k, f * k.support) == 0.0);
        ck_assert(sph_kernel_laplacian(&k, f * k.support) == 0.0);
      }
      /* positive and decreasing inside the support */
      for (int i = 0; i < 50; ++i) {
        double r = k.support * i / 50.0;
        ck_assert(sph_kernel_eval(&k, r) > 0.0);
        if (i > 0)
          ck_assert(sph_kernel_dwdr(&k, r) < 0.0);
      }
      /* grad W = W'(r) rab / r, zero at r = 0 */
      double rab[3] = {0.3, -0.4, d == 3 ? 0.5 : 0.0}, g[3];
      double r = sqrt(rab[0] * rab[0] + rab[1] * rab[1] + rab[2] * rab[2]);
      sph_kernel_gradient(&k, rab, r, g);
      for (int c = 0; c < 3; ++c)
        ck_assert(fabs(g[c] - sph_kernel_dwdr(&k, r) * rab[c] / r) <
                  1e-15 * k.norm);
      double zero[3] = {0, 0, 0};
      sph_kernel_gradient(&k, zero, 0.0, g);
      ck_assert(g[0] == 0.0 && g[1] == 0.0 && g[2] == 0.0);
      /* the Laplacian at 0 is d W''(0), the limit of W'' + (d-1) W'/r,
       * which differs from it by O(r^2) for these kernels (O(r) for the 1D
       * Wendland functions) */
      double l0 = sph_kernel_laplacian(&k, 0.0);
      ck_assert(isfinite(l0));
      ck_assert(fabs(l0 - d * sph_kernel_d2wdr2(&k, 0.0)) < 1e-12 * fabs(l0));
      double rs = 1e-7 * k.h;
      double lr =
          sph_kernel_d2wdr2(&k, rs) + (d - 1) * sph_kernel_dwdr(&k, rs) / rs;
      ck_assert(fabs(lr - l0) < 1e-5 * fabs(l0));
      ck_assert(fabs(sph_kernel_laplacian(&k, rs) - lr) < 1e-12 * fabs(l0));
    }
}
END_TEST

START_TEST(laplacian_matches_radial_form) {
  /* Lap W = W'' + (d-1) W'/r against a finite-difference Laplacian:
   * O(e^2) truncation, O(eps / e^2) ~ 1e-8 round-off, relative to norm */
  for (int t = 0; t < SPH_KERNEL_COUNT; ++t)
    for (int d = 1; d <= 3; ++d) {
      sph_kernel k;
      sph_kernel_create(&k, t, d, 1.0, NULL);
      double e = 1e-4, x[3] = {0.31, d >= 2 ? 0.42 : 0.0, d == 3 ? 0.17 : 0.0};
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
  ck_assert_int_eq(sph_kernel_create(&k, SPH_KERNEL_CUBIC, 0, 1.0, &err),
                   SPH_ERR_ARG);
  ck_assert_int_eq(sph_kernel_create(&k, SPH_KERNEL_CUBIC, 3, 0.0, &err),
                   SPH_ERR_ARG);
  ck_assert_int_eq(sph_kernel_create(&k, SPH_KERNEL_CUBIC, 3, -1.0, &err),
                   SPH_ERR_ARG);
  ck_assert_int_eq(sph_kernel_create(&k, SPH_KERNEL_CUBIC, 3, NAN, &err),
                   SPH_ERR_ARG);
  ck_assert_int_eq(
      sph_kernel_create(&k, (sph_kernel_type)SPH_KERNEL_COUNT, 3, 1.0, &err),
      SPH_ERR_ARG);
  ck_assert_int_eq(sph_kernel_create(&k, SPH_KERNEL_QUINTIC, 2, 0.5, &err),
                   SPH_OK);
  ck_assert(k.kappa == 3.0 && k.support == 1.5 && k.dim == 2);
  ck_assert_int_eq(sph_kernel_type_from_name("wendland-c2"),
                   SPH_KERNEL_WENDLAND_C2);
  ck_assert_int_eq(sph_kernel_type_from_name("gauss"), -1);
  ck_assert_str_eq(sph_kernel_type_name(SPH_KERNEL_QUINTIC), "quintic");
  for (int t = 0; t < SPH_KERNEL_COUNT; ++t)
    ck_assert_int_eq(
        sph_kernel_type_from_name(sph_kernel_type_name((sph_kernel_type)t)), t);
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
