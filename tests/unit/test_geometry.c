/* Geometry: signed distances, exact measures, face lattices with tributary
 * volumes, clipped lattices, seeded jitter and relaxation, expressions. */
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sph/expr.h"
#include "sph/geometry.h"

static sph_body box_body(double lo[3], double hi[3], int n0, int n1, int n2) {
  sph_body b;
  memset(&b, 0, sizeof b);
  snprintf(b.name, sizeof b.name, "box");
  b.shape.kind = SPH_SHAPE_BOX;
  memcpy(b.shape.min, lo, 3 * sizeof *lo);
  memcpy(b.shape.max, hi, 3 * sizeof *hi);
  b.lattice = SPH_LATTICE_FACES;
  b.count[0] = n0;
  b.count[1] = n1;
  b.count[2] = n2;
  return b;
}

START_TEST(face_lattice_has_tributary_volumes) {
  double lo[3] = {-0.5, 0, -0.5}, hi[3] = {0.5, 6, 0.5};
  sph_body b = box_body(lo, hi, 5, 25, 5);
  double *x, *v;
  size_t n;
  ck_assert_int_eq(sph_body_generate(&b, 3, &x, &v, &n, NULL), SPH_OK);
  ck_assert_uint_eq(n, 625);
  double sum = 0.0, vmin = 1e9;
  for (size_t i = 0; i < n; ++i) {
    sum += v[i];
    vmin = v[i] < vmin ? v[i] : vmin;
  }
  ck_assert(fabs(sum - 6.0) < 1e-13);
  ck_assert(fabs(vmin - 0.25 * 0.25 * 0.25 / 8) < 1e-15);
  /* the last particle sits exactly on the max corner */
  ck_assert(x[3 * (n - 1)] == 0.5 && x[3 * (n - 1) + 1] == 6.0);
  free(x);
  free(v);
  /* 2D */
  double lo2[3] = {0, 0, 0}, hi2[3] = {1, 0.5, 0};
  b = box_body(lo2, hi2, 21, 11, 0);
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, NULL), SPH_OK);
  ck_assert_uint_eq(n, 231);
  sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    sum += v[i];
    ck_assert(x[3 * i + 2] == 0.0);
  }
  ck_assert(fabs(sum - 0.5) < 1e-14);
  free(x);
  free(v);
  b.count[0] = 1;
  sph_error err;
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
}
END_TEST

static sph_body round_body(sph_shape_kind kind, double dp) {
  sph_body b;
  memset(&b, 0, sizeof b);
  snprintf(b.name, sizeof b.name, "round");
  b.shape.kind = kind;
  b.shape.center[0] = 0.1;
  b.shape.center[1] = -0.2;
  b.shape.radius = 0.04;
  b.shape.inner_radius = 0.03;
  b.shape.outer_radius = 0.04;
  b.shape.axis = 2;
  b.shape.length = 0.05;
  b.lattice = SPH_LATTICE_CELL_CENTRED;
  b.spacing = dp;
  b.seed = 1;
  b.jitter = 0.25;
  b.relax_steps = 40;
  return b;
}

START_TEST(clipped_lattices_fill_their_shapes) {
  struct {
    sph_shape_kind kind;
    int dim;
  } cases[] = {{SPH_SHAPE_DISC, 2},     {SPH_SHAPE_RING, 2},
               {SPH_SHAPE_SPHERE, 3},   {SPH_SHAPE_SHELL, 3},
               {SPH_SHAPE_CYLINDER, 3}, {SPH_SHAPE_RING, 3}};
  for (size_t c = 0; c < sizeof cases / sizeof *cases; ++c) {
    double dp = cases[c].dim == 2 ? 0.001 : 0.002;
    sph_body b = round_body(cases[c].kind, dp);
    double *x, *v;
    size_t n;
    ck_assert_int_eq(sph_body_generate(&b, cases[c].dim, &x, &v, &n, NULL),
                     SPH_OK);
    double worst = -1.0, sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
      double d = sph_shape_distance(&b.shape, cases[c].dim, x + 3 * i);
      worst = d > worst ? d : worst;
      sum += v[i];
    }
    ck_assert(worst < 0.0);
    /* a clipped lattice misses or adds at most about a half-cell layer at
     * the surface: |sum V - measure| <= area * dp / 2 relative */
    double m = sph_shape_measure(&b.shape, cases[c].dim);
    double ratio = sum / m;
    ck_assert_msg(fabs(ratio - 1.0) < 0.1, "shape %d dim %d ratio %g",
                  (int)cases[c].kind, cases[c].dim, ratio);
    free(x);
    free(v);
  }
}
END_TEST

START_TEST(distances_and_measures) {
  sph_shape s;
  memset(&s, 0, sizeof s);
  s.kind = SPH_SHAPE_BOX;
  s.max[0] = s.max[1] = s.max[2] = 1.0;
  double p[3] = {0.5, 0.5, 0.5}, q[3] = {2.0, 0.5, 0.5}, r[3] = {2, 2, 0.5};
  ck_assert(fabs(sph_shape_distance(&s, 3, p) + 0.5) < 1e-15);
  ck_assert(fabs(sph_shape_distance(&s, 3, q) - 1.0) < 1e-15);
  ck_assert(fabs(sph_shape_distance(&s, 3, r) - sqrt(2.0)) < 1e-15);
  ck_assert(fabs(sph_shape_measure(&s, 3) - 1.0) < 1e-15);
  s.kind = SPH_SHAPE_SHELL;
  s.inner_radius = 0.03;
  s.outer_radius = 0.04;
  memset(s.center, 0, sizeof s.center);
  double a[3] = {0.035, 0, 0}, o[3] = {0, 0, 0};
  ck_assert(fabs(sph_shape_distance(&s, 3, a) + 0.005) < 1e-15);
  ck_assert(fabs(sph_shape_distance(&s, 3, o) - 0.03) < 1e-15);
  ck_assert(fabs(sph_shape_measure(&s, 3) -
                 4.0 / 3.0 * M_PI * (6.4e-5 - 2.7e-5)) < 1e-18);
  s.kind = SPH_SHAPE_RING;
  ck_assert(fabs(sph_shape_measure(&s, 2) - M_PI * 7e-4) < 1e-15);
  s.kind = SPH_SHAPE_CYLINDER;
  s.radius = 1.0;
  s.length = 2.0;
  s.axis = 1;
  double c1[3] = {0, 1, 0}, c2[3] = {0, 3, 0}, c3[3] = {2, -1, 0};
  ck_assert(fabs(sph_shape_distance(&s, 3, c1) + 1.0) < 1e-15);
  ck_assert(fabs(sph_shape_distance(&s, 3, c2) - 1.0) < 1e-15);
  ck_assert(fabs(sph_shape_distance(&s, 3, c3) - sqrt(2.0)) < 1e-15);
  ck_assert(fabs(sph_shape_measure(&s, 3) - 2 * M_PI) < 1e-14);
  double lo[3], hi[3];
  sph_shape_bounds(&s, 3, lo, hi);
  ck_assert(lo[1] == 0.0 && hi[1] == 2.0 && lo[0] == -1.0 && hi[2] == 1.0);
}
END_TEST

/* min nearest-neighbour distance and its coefficient of variation */
static void nn_stats(const double *x, size_t n, double *dmin, double *cv) {
  double s = 0, s2 = 0;
  *dmin = INFINITY;
  for (size_t i = 0; i < n; ++i) {
    double best = INFINITY;
    for (size_t j = 0; j < n; ++j) {
      if (i == j)
        continue;
      double d = hypot(x[3 * i] - x[3 * j], x[3 * i + 1] - x[3 * j + 1]);
      best = d < best ? d : best;
    }
    s += best;
    s2 += best * best;
    *dmin = best < *dmin ? best : *dmin;
  }
  double mean = s / n;
  *cv = sqrt(s2 / n - mean * mean) / mean;
}

START_TEST(jitter_and_relax_are_seeded_and_inside) {
  sph_body b = round_body(SPH_SHAPE_RING, 0.001);
  b.distribution = SPH_DIST_JITTER;
  double *x1, *v1, *x2, *v2, *x3, *v3;
  size_t n1, n2, n3;
  ck_assert_int_eq(sph_body_generate(&b, 2, &x1, &v1, &n1, NULL), SPH_OK);
  ck_assert_int_eq(sph_body_generate(&b, 2, &x2, &v2, &n2, NULL), SPH_OK);
  ck_assert_uint_eq(n1, n2);
  ck_assert_int_eq(memcmp(x1, x2, 3 * n1 * sizeof *x1), 0);
  b.seed = 2;
  ck_assert_int_eq(sph_body_generate(&b, 2, &x3, &v3, &n3, NULL), SPH_OK);
  ck_assert_int_ne(memcmp(x1, x3, 3 * n1 * sizeof *x1), 0);
  free(x2);
  free(v2);
  free(x3);
  free(v3);
  /* relaxation: inside, repeatable, more uniform than the jittered start */
  b.seed = 1;
  b.distribution = SPH_DIST_RELAX;
  ck_assert_int_eq(sph_body_generate(&b, 2, &x2, &v2, &n2, NULL), SPH_OK);
  ck_assert_int_eq(sph_body_generate(&b, 2, &x3, &v3, &n3, NULL), SPH_OK);
  ck_assert_int_eq(memcmp(x2, x3, 3 * n2 * sizeof *x2), 0);
  double sum = 0.0, worst = -1.0;
  for (size_t i = 0; i < n2; ++i) {
    sum += v2[i];
    double d = sph_shape_distance(&b.shape, 2, x2 + 3 * i);
    worst = d > worst ? d : worst;
  }
  ck_assert(worst < 0.0);
  ck_assert(fabs(sum - sph_shape_measure(&b.shape, 2)) < 1e-12 * sum);
  double dmin_j, cv_j, dmin_r, cv_r;
  nn_stats(x1, n1, &dmin_j, &cv_j);
  nn_stats(x2, n2, &dmin_r, &cv_r);
  ck_assert_msg(dmin_r > dmin_j && cv_r < cv_j,
                "jittered: min %g cv %g, relaxed: min %g cv %g", dmin_j, cv_j,
                dmin_r, cv_r);
  free(x1);
  free(v1);
  free(x2);
  free(v2);
  free(x3);
  free(v3);
}
END_TEST

START_TEST(shape_and_dimension_errors) {
  sph_body b = round_body(SPH_SHAPE_SPHERE, 0.01);
  double *x, *v;
  size_t n;
  sph_error err;
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  ck_assert_ptr_nonnull(strstr(err.message, "round"));
  b = round_body(SPH_SHAPE_DISC, 0.01);
  ck_assert_int_eq(sph_body_generate(&b, 3, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  b = round_body(SPH_SHAPE_RING, 0.5); /* spacing far larger than the ring */
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  ck_assert_ptr_nonnull(strstr(err.message, "no particles"));
}
END_TEST

START_TEST(expressions) {
  sph_expr *e;
  sph_error err;
  ck_assert_int_eq(sph_expr_create(&e, "sin(pi*y/(2*6))", &err), SPH_OK);
  ck_assert(fabs(sph_expr_eval(e, 0, 3, 0, 0) - sin(M_PI / 4)) < 1e-15);
  ck_assert_str_eq(sph_expr_text(e), "sin(pi*y/(2*6))");
  sph_expr_destroy(e);
  ck_assert_int_eq(sph_expr_create(&e, "5*z/3 + t", &err), SPH_OK);
  ck_assert(fabs(sph_expr_eval(e, 0, 0, 3, 1) - 6.0) < 1e-15);
  sph_expr_destroy(e);
  ck_assert_int_eq(sph_expr_create(&e, "sin((", &err), SPH_ERR_SYNTAX);
  ck_assert_int_eq(sph_expr_create(&e, "omega*x", &err), SPH_ERR_ARG);
  ck_assert_ptr_nonnull(strstr(err.message, "omega"));
}
END_TEST

int main(void) {
  Suite *s = suite_create("geometry");
  TCase *tc = tcase_create("geometry");
  tcase_set_timeout(tc, 60);
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, face_lattice_has_tributary_volumes);
  tcase_add_test(tc, clipped_lattices_fill_their_shapes);
  tcase_add_test(tc, distances_and_measures);
  tcase_add_test(tc, jitter_and_relax_are_seeded_and_inside);
  tcase_add_test(tc, shape_and_dimension_errors);
  tcase_add_test(tc, expressions);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
