/* Seed 004's Gauss-point error norms (solver/reference_gauss.h, eq. 44-45):
 * the Gauss-Legendre rules; the first-order corrected kernel interpolant
 * reproducing a linear field and its gradient to round-off on a jittered
 * lattice, with its gradient the derivative of the interpolant (central
 * differences); the binning (particles outside the box); the norms of a
 * linear displacement at round-off and of a zero displacement against the
 * plate's mode at their analytic values U sqrt(2) and U pi; and through a
 * scene (reference: {analytic: swinging_plate, norm: gauss}) beside the
 * nodal errors, with nodal the default and a bad choice refused. */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "scene/scene.h"
#include "solver/reference.h"
#include "solver/reference_gauss.h"
#include "solver/sim.h"

START_TEST(legendre_rules) {
  double x[5], w[5];
  for (int n = 1; n <= 5; ++n) {
    ck_assert(sph_gauss_legendre(n, x, w));
    /* exact for every degree up to 2n - 1 */
    for (int p = 0; p <= 2 * n - 1; ++p) {
      double s = 0.0;
      for (int i = 0; i < n; ++i)
        s += w[i] * pow(x[i], p);
      double exact = p % 2 ? 0.0 : 2.0 / (p + 1);
      ck_assert_msg(fabs(s - exact) < 1e-14, "n %d degree %d: %.17g", n, p, s);
    }
  }
  ck_assert(!sph_gauss_legendre(6, x, w));
}
END_TEST

/* a jittered lattice of spacing d over [0, 2]^2 (cells' centres), with
 * u = field(X) */
static void fill_plate(sph_gauss_norm *g, int n,
                       void (*field)(const double X[3], double u[3])) {
  double *t = sph_gauss_norm_table(g), d = 2.0 / n;
  unsigned s = 12345u;
  for (int j = 0; j < n * n; ++j) {
    double *row = t + SPH_GAUSS_ROW * j;
    for (int c = 0; c < 2; ++c) {
      s = s * 1103515245u + 12345u;
      double jit = ((s >> 8) / (double)(1u << 24) - 0.5) * 0.2 * d;
      row[SPH_GAUSS_X + c] = ((c ? j / n : j % n) + 0.5) * d + jit;
    }
    row[SPH_GAUSS_X + 2] = 0.0;
    row[SPH_GAUSS_V] = d * d;
    field(row + SPH_GAUSS_X, row + SPH_GAUSS_U);
  }
  sph_gauss_norm_bin(g);
}

static const double B_lin[9] = {0.3, -0.2, 0, 0.7, 0.1, 0, 0, 0, 0};

static void linear(const double X[3], double u[3]) {
  for (int i = 0; i < 3; ++i)
    u[i] = (i < 2 ? 0.01 * (i + 1) : 0.0) + B_lin[3 * i] * X[0] +
           B_lin[3 * i + 1] * X[1];
}

static void linear_exact(const void *ctx, const double X[3], double u[3],
                         double G[9]) {
  (void)ctx;
  linear(X, u);
  memcpy(G, B_lin, sizeof B_lin);
}

static void wavy(const double X[3], double u[3]) {
  u[0] = sin(1.3 * X[0]) * cos(0.7 * X[1]);
  u[1] = X[0] * X[1] * X[1];
  u[2] = 0.0;
}

static void zero(const double X[3], double u[3]) {
  (void)X;
  u[0] = u[1] = u[2] = 0.0;
}

static sph_gauss_norm *plate_norm(int n, double h_over_dp) {
  sph_kernel k;
  sph_error err;
  ck_assert(sph_kernel_create(&k, SPH_KERNEL_CUBIC, 2, h_over_dp * 2.0 / n,
                              &err) == SPH_OK);
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 2, 0};
  sph_gauss_norm *g;
  ck_assert_msg(sph_gauss_norm_create(&g, &k, lo, hi, 10, 5, (size_t)n * n,
                                      &err) == SPH_OK,
                "%s", err.message);
  return g;
}

START_TEST(interpolant_reproduces_linear) {
  sph_gauss_norm *g = plate_norm(10, 1.1);
  fill_plate(g, 10, linear);
  sph_error err;
  /* inside, near an edge and at a corner, where the support is cut */
  const double pts[][3] = {{1.03, 0.77, 0}, {0.01, 1.5, 0}, {2, 2, 0}};
  for (int p = 0; p < 3; ++p) {
    double u[3], G[9], ue[3], Ge[9];
    ck_assert(sph_gauss_norm_interpolate(g, pts[p], u, G, &err) == SPH_OK);
    linear_exact(NULL, pts[p], ue, Ge);
    for (int i = 0; i < 3; ++i)
      ck_assert_msg(fabs(u[i] - ue[i]) < 1e-14, "u %d: %g", i, u[i] - ue[i]);
    for (int i = 0; i < 9; ++i)
      ck_assert_msg(fabs(G[i] - Ge[i]) < 1e-13, "G %d: %g", i, G[i] - Ge[i]);
  }
  sph_gauss_norm_destroy(g);
}
END_TEST

START_TEST(interpolant_gradient_is_its_derivative) {
  sph_gauss_norm *g = plate_norm(10, 1.3);
  fill_plate(g, 10, wavy);
  sph_error err;
  const double pts[][3] = {{0.93, 1.21, 0}, {0.05, 0.11, 0}, {1.97, 0.6, 0}};
  const double e = 1e-6;
  for (int p = 0; p < 3; ++p) {
    double u[3], G[9];
    ck_assert(sph_gauss_norm_interpolate(g, pts[p], u, G, &err) == SPH_OK);
    for (int k = 0; k < 2; ++k) {
      double xp[3], xm[3], up[3], um[3], t[9];
      memcpy(xp, pts[p], sizeof xp);
      memcpy(xm, pts[p], sizeof xm);
      xp[k] += e;
      xm[k] -= e;
      ck_assert(sph_gauss_norm_interpolate(g, xp, up, t, &err) == SPH_OK);
      ck_assert(sph_gauss_norm_interpolate(g, xm, um, t, &err) == SPH_OK);
      for (int i = 0; i < 2; ++i) {
        double fd = (up[i] - um[i]) / (2 * e);
        ck_assert_msg(fabs(fd - G[3 * i + k]) < 1e-7 * (1 + fabs(fd)),
                      "point %d d u_%d / d X_%d: %.12g vs %.12g", p, i, k,
                      G[3 * i + k], fd);
      }
    }
  }
  sph_gauss_norm_destroy(g);
}
END_TEST

/* binning clamps particles outside the bins: they still count where near,
 * and a point without enough particles is an error, not a NaN */
START_TEST(bin_and_empty_support) {
  sph_gauss_norm *g = plate_norm(10, 1.1);
  fill_plate(g, 10, linear);
  double *row = sph_gauss_norm_table(g);
  row[SPH_GAUSS_X] = -50.0; /* far outside: in the corner bin, never near */
  linear(row + SPH_GAUSS_X, row + SPH_GAUSS_U);
  sph_gauss_norm_bin(g);
  sph_error err;
  double u[3], G[9], ue[3], Ge[9], X[3] = {0.5, 0.5, 0};
  ck_assert(sph_gauss_norm_interpolate(g, X, u, G, &err) == SPH_OK);
  linear_exact(NULL, X, ue, Ge);
  ck_assert(fabs(u[0] - ue[0]) < 1e-14 && fabs(u[1] - ue[1]) < 1e-14);
  double far[3] = {30.0, 30.0, 0};
  ck_assert(sph_gauss_norm_interpolate(g, far, u, G, &err) == SPH_ERR_RANGE);
  ck_assert_msg(strstr(err.message, "too few particles"), "%s", err.message);
  sph_gauss_norm_destroy(g);
}
END_TEST

/* the plate's mode at full amplitude: |f|^2 integrates to 2 and
 * |grad f|^2 to pi^2 over [0, 2]^2 */
static void plate_mode(const void *ctx, const double X[3], double u[3],
                       double G[9]) {
  const double U = *(const double *)ctx, a = M_PI / 2;
  double s0 = sin(a * X[0]), c0 = cos(a * X[0]);
  double s1 = sin(a * X[1]), c1 = cos(a * X[1]);
  u[0] = -U * s0 * c1;
  u[1] = U * c0 * s1;
  u[2] = 0.0;
  memset(G, 0, 9 * sizeof *G);
  G[0] = -U * a * c0 * c1;
  G[1] = U * a * s0 * s1;
  G[3] = -U * a * s0 * s1;
  G[4] = U * a * c0 * c1;
}

START_TEST(norms_linear_and_analytic) {
  sph_error err;
  double e[2];
  for (int n = 10; n <= 20; n += 10) {
    sph_gauss_norm *g = plate_norm(n, 1.1);
    fill_plate(g, n, linear);
    ck_assert(sph_gauss_norm_errors(g, linear_exact, NULL, e, &err) == SPH_OK);
    ck_assert_msg(e[0] < 1e-14 && e[1] < 1e-13, "linear: %g %g", e[0], e[1]);
    fill_plate(g, n, zero);
    const double U = 0.01;
    ck_assert(sph_gauss_norm_errors(g, plate_mode, &U, e, &err) == SPH_OK);
    ck_assert_msg(fabs(e[0] - U * sqrt(2.0)) < 1e-12 * U, "L2 %.15g", e[0]);
    ck_assert_msg(fabs(e[1] - U * M_PI) < 1e-12 * U, "H1 %.15g", e[1]);
    sph_gauss_norm_destroy(g);
  }
}
END_TEST

/* the plate scene at d = 0.2 with the given reference line */
static sph_status load_plate(const char *reference, sph_scene **s,
                             sph_sim **sim, sph_error *err) {
  char path[512], set[256];
  snprintf(path, sizeof path, "%s/scenes/swinging_plate_2d.yaml",
           SPH_SOURCE_DIR);
  snprintf(set, sizeof set, "reference=%s", reference);
  const char *sets[] = {set};
  *sim = NULL;
  sph_status st = sph_scene_load(s, path, sets, 1, err);
  if (st == SPH_OK && (st = sph_sim_create(sim, *s, err)) != SPH_OK)
    sph_scene_destroy(*s);
  return st;
}

START_TEST(scene_reports_both_norms) {
  sph_scene *s;
  sph_sim *sim;
  sph_error err;
  ck_assert_msg(load_plate("{analytic: swinging_plate, U: 0.01, norm: gauss}",
                           &s, &sim, &err) == SPH_OK,
                "%s", err.message);
  sph_particles *ps = sim->ps;
  ck_assert(sph_particles_require(ps, SPH_FIELD_DISPLACEMENT, &err) == SPH_OK);
  ck_assert(sph_particles_require(ps, SPH_FIELD_PK1, &err) == SPH_OK);
  memset(ps->field[SPH_FIELD_DISPLACEMENT], 0, 3 * ps->n * sizeof(double));
  /* a quarter period: u = U f(X), the particles still at rest */
  const double mu = 17e6 / (2 * 1.495);
  const double w = M_PI / 2 * sqrt(2 * mu / 1100);
  sim->t = M_PI / (2 * w);
  sph_reference_error e;
  ck_assert(sph_reference_errors(sim->reference, sim, &e, &err) == SPH_OK);
  ck_assert_msg(fabs(e.l2_displacement_gauss - 0.01 * sqrt(2.0)) < 1e-12,
                "%.15g", e.l2_displacement_gauss);
  ck_assert_msg(fabs(e.h1_displacement_gauss - 0.01 * M_PI) < 1e-12, "%.15g",
                e.h1_displacement_gauss);
  /* the nodal error beside them: a particle quadrature of the same, as a
   * root mean square over the area 4 and relative to U: sqrt(1/2) */
  ck_assert_msg(fabs(e.l2_displacement - sqrt(0.5)) < 1e-3, "%.15g",
                e.l2_displacement);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
  /* nodal is the default: no Gauss norms */
  ck_assert(load_plate("{analytic: swinging_plate, U: 0.01}", &s, &sim, &err) ==
            SPH_OK);
  ck_assert(sph_particles_require(sim->ps, SPH_FIELD_DISPLACEMENT, &err) ==
            SPH_OK);
  ck_assert(sph_particles_require(sim->ps, SPH_FIELD_PK1, &err) == SPH_OK);
  ck_assert(sph_reference_errors(sim->reference, sim, &e, &err) == SPH_OK);
  ck_assert(isnan(e.l2_displacement_gauss) && isnan(e.h1_displacement_gauss));
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
  /* a bad choice names the key */
  ck_assert(load_plate("{analytic: swinging_plate, norm: simpson}", &s, &sim,
                       &err) != SPH_OK);
  ck_assert_msg(strstr(err.message, "simpson") || strstr(err.key, "norm"),
                "%s (%s)", err.message, err.key);
}
END_TEST

int main(void) {
  Suite *s = suite_create("reference_gauss");
  TCase *tc = tcase_create("reference_gauss");
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, legendre_rules);
  tcase_add_test(tc, interpolant_reproduces_linear);
  tcase_add_test(tc, interpolant_gradient_is_its_derivative);
  tcase_add_test(tc, bin_and_empty_support);
  tcase_add_test(tc, norms_linear_and_analytic);
  tcase_add_test(tc, scene_reports_both_norms);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
