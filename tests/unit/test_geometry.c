/* Geometry and expressions: signed distances, exact measures, face lattices
 * with tributary volumes (docs/benchmarks.md D.5), clipped cell-centred
 * lattices, seeded jitter, relaxation, libmatheval expressions. */
#include "test_util.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "scene/expr.h"
#include "scene/geometry.h"

#define EPS DBL_EPSILON

static sph_body make_body(const char *name, sph_shape_kind kind) {
  sph_body b;
  memset(&b, 0, sizeof b);
  snprintf(b.name, sizeof b.name, "%s", name);
  b.shape.kind = kind;
  b.lattice = SPH_LATTICE_CELL_CENTRED;
  return b;
}

static sph_body box_faces(const double lo[3], const double hi[3], int n0,
                          int n1, int n2) {
  sph_body b = make_body("column", SPH_SHAPE_BOX);
  memcpy(b.shape.min, lo, 3 * sizeof *lo);
  memcpy(b.shape.max, hi, 3 * sizeof *hi);
  b.lattice = SPH_LATTICE_FACES;
  b.count[0] = n0;
  b.count[1] = n1;
  b.count[2] = n2;
  return b;
}

/* round shapes centred off the origin; axis z for the axial ones */
static sph_body round_body(sph_shape_kind kind, double dp) {
  sph_body b = make_body("round", kind);
  b.shape.center[0] = 0.1;
  b.shape.center[1] = -0.2;
  b.shape.center[2] = 0.3;
  b.shape.radius = 0.04;
  b.shape.inner_radius = 0.02;
  b.shape.outer_radius = 0.04;
  b.shape.axis[2] = 1.0;
  b.shape.length = 0.05;
  b.spacing = dp;
  b.seed = 1;
  b.jitter = 0.25;
  b.relax_steps = 40;
  return b;
}

static double sum_of(const double *v, size_t n) {
  double s = 0.0;
  for (size_t i = 0; i < n; ++i)
    s += v[i];
  return s;
}

static double worst_distance(const sph_body *b, int dim, const double *x,
                             size_t n) {
  double worst = -INFINITY;
  for (size_t i = 0; i < n; ++i) {
    double d = sph_shape_distance(&b->shape, dim, x + 3 * i);
    worst = d > worst ? d : worst;
  }
  return worst;
}

START_TEST(face_lattice_has_tributary_volumes) {
  /* the B-column of seed 000: 5 x 25 x 5 particles on 1 x 6 x 1, dp 0.25 */
  const double lo[3] = {-0.5, 0, -0.5}, hi[3] = {0.5, 6, 0.5};
  sph_body b = box_faces(lo, hi, 5, 25, 5);
  double *x, *v;
  size_t n;
  ck_assert_int_eq(sph_body_generate(&b, 3, &x, &v, &n, NULL), SPH_OK);
  ck_assert_uint_eq(n, 625);
  const double dp = 0.25, dp3 = dp * dp * dp;
  /* volumes: dp^3 halved once per face a particle lies on */
  size_t classes[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < n; ++i) {
    int on = 0;
    for (int c = 0; c < 3; ++c) {
      ck_assert(x[3 * i + c] >= lo[c] && x[3 * i + c] <= hi[c]);
      on += x[3 * i + c] == lo[c] || x[3 * i + c] == hi[c];
    }
    ck_assert(fabs(v[i] - dp3 / (1 << on)) <= 4 * EPS * dp3);
    classes[on]++;
  }
  /* 3 x 23 x 3 interior, 8 corners */
  ck_assert_uint_eq(classes[0], 207);
  ck_assert_uint_eq(classes[3], 8);
  /* sum V = body volume up to the round-off of n additions */
  ck_assert(fabs(sum_of(v, n) - 6.0) <= n * EPS * 6.0);
  /* lattice order: x slowest, z fastest; the last particle on the max
   * corner exactly */
  ck_assert(x[0] == -0.5 && x[1] == 0.0 && x[2] == -0.5);
  ck_assert(x[3] == -0.5 && x[4] == 0.0 && x[5] == -0.25);
  ck_assert(x[3 * (n - 1)] == 0.5 && x[3 * (n - 1) + 1] == 6.0 &&
            x[3 * (n - 1) + 2] == 0.5);
  free(x);
  free(v);

  /* 2D: count[2] ignored, z = 0 */
  const double lo2[3] = {0, 0, 0}, hi2[3] = {1, 0.5, 0};
  b = box_faces(lo2, hi2, 21, 11, 0);
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, NULL), SPH_OK);
  ck_assert_uint_eq(n, 231);
  for (size_t i = 0; i < n; ++i)
    ck_assert(x[3 * i + 2] == 0.0);
  ck_assert(fabs(sum_of(v, n) - 0.5) <= n * EPS * 0.5);
  ck_assert(fabs(v[0] - 0.05 * 0.05 / 4) <= 4 * EPS * 0.05 * 0.05);
  free(x);
  free(v);
}
END_TEST

START_TEST(cell_lattice_tiles_a_box) {
  sph_body b = make_body("block", SPH_SHAPE_BOX);
  const double L[3] = {0.05, 0.03, 0.02};
  for (int c = 0; c < 3; ++c) {
    b.shape.min[c] = -0.01 * c;
    b.shape.max[c] = b.shape.min[c] + L[c];
  }
  b.spacing = 0.0045; /* 11.1, 6.7, 4.4 cells: 11 x 7 x 4 */
  for (int dim = 2; dim <= 3; ++dim) {
    double *x, *v;
    size_t n;
    ck_assert_int_eq(sph_body_generate(&b, dim, &x, &v, &n, NULL), SPH_OK);
    ck_assert_uint_eq(n, dim == 2 ? 77 : 308);
    double m = sph_shape_measure(&b.shape, dim);
    ck_assert(fabs(sum_of(v, n) - m) <= n * EPS * m);
    /* centres half a cell inside, cells of L / n exactly */
    double h[3] = {L[0] / 11, L[1] / 7, L[2] / 4};
    for (int c = 0; c < dim; ++c)
      ck_assert(fabs(x[c] - (b.shape.min[c] + 0.5 * h[c])) <= 4 * EPS);
    ck_assert(worst_distance(&b, dim, x, n) < 0.0);
    if (dim == 2)
      for (size_t i = 0; i < n; ++i)
        ck_assert(x[3 * i + 2] == 0.0);
    free(x);
    free(v);
  }
}
END_TEST

/* Measure of the shape grown (grow > 0) or shrunk by `grow` on every
 * surface; for a cylinder or tube an upper bound when grown. */
static double offset_measure(const sph_shape *s, int dim, double grow) {
  double ro = s->outer_radius + grow, ri = fmax(s->inner_radius - grow, 0.0);
  double R = s->radius + grow, L = s->length + 2 * grow;
  switch (s->kind) {
  case SPH_SHAPE_DISC:
    return M_PI * R * R;
  case SPH_SHAPE_SPHERE:
    return 4.0 / 3.0 * M_PI * R * R * R;
  case SPH_SHAPE_SHELL:
    return 4.0 / 3.0 * M_PI * (ro * ro * ro - ri * ri * ri);
  case SPH_SHAPE_RING:
    return M_PI * (ro * ro - ri * ri) * (dim == 2 ? 1.0 : L);
  case SPH_SHAPE_CYLINDER:
    return M_PI * R * R * L;
  case SPH_SHAPE_BOX:
  case SPH_SHAPE_MESH: /* test_mesh.c */
  case SPH_SHAPE_POLYGON:
  case SPH_SHAPE_PARTICLES: /* test_cloud.c */
    break;
  }
  return NAN;
}

START_TEST(clipped_lattices_fill_their_shapes) {
  static const struct {
    sph_shape_kind kind;
    int dim;
    double dp;
  } cases[] = {{SPH_SHAPE_DISC, 2, 0.001},     {SPH_SHAPE_RING, 2, 0.0005},
               {SPH_SHAPE_SPHERE, 3, 0.001},   {SPH_SHAPE_SHELL, 3, 0.001},
               {SPH_SHAPE_CYLINDER, 3, 0.001}, {SPH_SHAPE_RING, 3, 0.001}};
  for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k) {
    int dim = cases[k].dim;
    double dp = cases[k].dp;
    sph_body b = round_body(cases[k].kind, dp);
    double *x, *v;
    size_t n;
    ck_assert_int_eq(sph_body_generate(&b, dim, &x, &v, &n, NULL), SPH_OK);
    ck_assert(worst_distance(&b, dim, x, n) < 0.0);
    double cell = pow(dp, dim);
    for (size_t i = 0; i < n; ++i)
      ck_assert(v[i] == cell);
    /* A counted cell lies within its half-diagonal delta of its centre, and
     * every point deeper than delta lies in a counted cell, so
     * |shape shrunk by delta| <= n dp^d <= |shape grown by delta|. */
    double delta = 0.5 * sqrt((double)dim) * dp, filled = (double)n * cell;
    double lower = offset_measure(&b.shape, dim, -delta);
    double upper = offset_measure(&b.shape, dim, delta);
    ck_assert_msg(filled >= lower && filled <= upper,
                  "shape %d, %dD: n dp^d / measure = %.5f outside [%.4f, "
                  "%.4f]",
                  (int)b.shape.kind, dim,
                  filled / sph_shape_measure(&b.shape, dim),
                  lower / sph_shape_measure(&b.shape, dim),
                  upper / sph_shape_measure(&b.shape, dim));
    free(x);
    free(v);
  }
}
END_TEST

static void check_distance(const sph_shape *s, int dim, double px, double py,
                           double pz, double expect) {
  const double X[3] = {px, py, pz};
  double d = sph_shape_distance(s, dim, X);
  ck_assert_msg(fabs(d - expect) <= 16 * EPS * (1.0 + fabs(px) + fabs(py)),
                "shape %d dim %d at (%g, %g, %g): %.17g, expected %.17g",
                (int)s->kind, dim, px, py, pz, d, expect);
}

static void check_measure(const sph_shape *s, int dim, double expect) {
  double m = sph_shape_measure(s, dim);
  ck_assert_msg(fabs(m - expect) <= 8 * EPS * expect,
                "shape %d dim %d: measure %.17g, expected %.17g", (int)s->kind,
                dim, m, expect);
}

START_TEST(distances_bounds_and_measures) {
  sph_shape s;
  double lo[3], hi[3];
  /* box [0,1] x [0,2] x [0,1] */
  memset(&s, 0, sizeof s);
  s.kind = SPH_SHAPE_BOX;
  s.max[0] = 1.0;
  s.max[1] = 2.0;
  s.max[2] = 1.0;
  check_distance(&s, 3, 0.5, 0.5, 0.5, -0.5);
  check_distance(&s, 3, 0.5, 1.9, 0.5, -0.1);
  check_distance(&s, 3, 2.0, 0.5, 0.5, 1.0);
  check_distance(&s, 3, 2.0, 3.0, 0.5, sqrt(2.0));
  check_distance(&s, 3, 2.0, 3.0, 2.0, sqrt(3.0));
  check_distance(&s, 2, 0.5, 1.9, 7.0, -0.1); /* 2D ignores z */
  check_measure(&s, 3, 2.0);
  check_measure(&s, 2, 2.0);
  /* disc: centre (1, 2), R 0.5 */
  memset(&s, 0, sizeof s);
  s.kind = SPH_SHAPE_DISC;
  s.center[0] = 1.0;
  s.center[1] = 2.0;
  s.radius = 0.5;
  check_distance(&s, 2, 1.0, 2.0, 0.0, -0.5);
  check_distance(&s, 2, 1.0, 2.25, 0.0, -0.25);
  check_distance(&s, 2, 4.0, 6.0, 3.0, 4.5);
  check_measure(&s, 2, M_PI * 0.25);
  sph_shape_bounds(&s, 2, lo, hi);
  ck_assert(lo[0] == 0.5 && hi[0] == 1.5 && lo[1] == 1.5 && hi[1] == 2.5);
  ck_assert(lo[2] == 0.0 && hi[2] == 0.0);
  /* 2D ring (annulus): centre (1, 2), radii 0.25 and 0.5 */
  s.kind = SPH_SHAPE_RING;
  s.inner_radius = 0.25;
  s.outer_radius = 0.5;
  check_distance(&s, 2, 1.0, 2.0, 0.0, 0.25);
  check_distance(&s, 2, 1.375, 2.0, 0.0, -0.125);
  check_distance(&s, 2, 1.0, 2.3, 0.0, -0.05);
  check_distance(&s, 2, 1.0, 3.0, 0.0, 0.5);
  check_measure(&s, 2, M_PI * (0.25 - 0.0625));
  /* sphere and shell: centre (1, 2, 3) */
  s.center[2] = 3.0;
  s.kind = SPH_SHAPE_SPHERE;
  check_distance(&s, 3, 1.0, 2.0, 3.0, -0.5);
  check_distance(&s, 3, 1.0, 2.0, 3.1, -0.4);
  check_distance(&s, 3, 3.0, 4.0, 4.0, 2.5);
  check_measure(&s, 3, 4.0 / 3.0 * M_PI * 0.125);
  sph_shape_bounds(&s, 3, lo, hi);
  ck_assert(lo[2] == 2.5 && hi[2] == 3.5);
  s.kind = SPH_SHAPE_SHELL;
  check_distance(&s, 3, 1.0, 2.0, 3.0, 0.25);
  check_distance(&s, 3, 1.0, 2.0, 3.375, -0.125);
  check_distance(&s, 3, 1.0, 2.4, 3.0, -0.1);
  check_distance(&s, 3, 1.0, 2.0, 4.0, 0.5);
  check_measure(&s, 3, 4.0 / 3.0 * M_PI * (0.125 - 0.015625));
  /* cylinder: base centre (0, 0, 0), axis y, R 1, length 2 */
  memset(&s, 0, sizeof s);
  s.kind = SPH_SHAPE_CYLINDER;
  s.radius = 1.0;
  s.length = 2.0;
  s.axis[1] = 1.0;
  check_distance(&s, 3, 0.0, 1.0, 0.0, -1.0);
  check_distance(&s, 3, 0.0, 0.25, 0.0, -0.25);
  check_distance(&s, 3, 0.6, 1.0, 0.8, 0.0);
  check_distance(&s, 3, 0.0, 3.0, 0.0, 1.0);
  check_distance(&s, 3, 0.0, -1.0, 0.5, 1.0);
  check_distance(&s, 3, 2.0, -1.0, 0.0, sqrt(2.0));
  check_distance(&s, 3, 0.0, 1.0, -3.0, 2.0);
  check_measure(&s, 3, 2 * M_PI);
  sph_shape_bounds(&s, 3, lo, hi);
  ck_assert(lo[1] == 0.0 && hi[1] == 2.0 && lo[0] == -1.0 && hi[0] == 1.0);
  ck_assert(lo[2] == -1.0 && hi[2] == 1.0);
  /* the same cylinder turned about x, axis (0, 0.6, 0.8) = R e_y: the
   * distance at R X is the distance at X; bounds from the end discs */
  sph_shape t = s;
  memcpy(t.axis, (double[3]){0.0, 0.6, 0.8}, sizeof t.axis);
  const double P[7][3] = {{0, 1, 0},    {0, 0.25, 0}, {0.6, 1, 0.8}, {0, 3, 0},
                          {0, -1, 0.5}, {2, -1, 0},   {0, 1, -3}};
  for (int k = 0; k < 7; ++k)
    check_distance(&t, 3, P[k][0], 0.6 * P[k][1] - 0.8 * P[k][2],
                   0.8 * P[k][1] + 0.6 * P[k][2],
                   sph_shape_distance(&s, 3, P[k]));
  sph_shape_bounds(&t, 3, lo, hi);
  ck_assert(lo[0] == -1.0 && hi[0] == 1.0);
  ck_assert(fabs(lo[1] + 0.8) < 4 * EPS && fabs(hi[1] - 2.0) < 4 * EPS);
  ck_assert(fabs(lo[2] + 0.6) < 4 * EPS && fabs(hi[2] - 2.2) < 4 * EPS);
  /* 3D ring: a tube of radii 0.5, 1 along x from x = 1, length 3 */
  s.kind = SPH_SHAPE_RING;
  s.center[0] = 1.0;
  s.axis[0] = 1.0;
  s.axis[1] = 0.0;
  s.length = 3.0;
  s.inner_radius = 0.5;
  s.outer_radius = 1.0;
  check_distance(&s, 3, 2.5, 0.75, 0.0, -0.25);
  check_distance(&s, 3, 1.1, 0.0, 0.75, -0.1);
  check_distance(&s, 3, 2.5, 0.0, 0.0, 0.5);
  check_distance(&s, 3, 2.5, 0.0, 2.0, 1.0);
  check_distance(&s, 3, 0.0, 0.75, 0.0, 1.0);
  check_distance(&s, 3, 5.0, 0.0, 0.0, sqrt(1.0 + 0.25));
  check_measure(&s, 3, M_PI * 0.75 * 3.0);
  check_measure(&s, 2, M_PI * 0.75);
  sph_shape_bounds(&s, 3, lo, hi);
  ck_assert(lo[0] == 1.0 && hi[0] == 4.0 && lo[1] == -1.0 && hi[2] == 1.0);
}
END_TEST

/* smallest nearest-neighbour distance and the coefficient of variation of
 * the nearest-neighbour distances (brute force) */
static void nn_stats(const double *x, size_t n, double *dmin, double *cv) {
  double s = 0, s2 = 0;
  *dmin = INFINITY;
  for (size_t i = 0; i < n; ++i) {
    double best = INFINITY;
    for (size_t j = 0; j < n; ++j) {
      if (i == j)
        continue;
      double d = 0.0;
      for (int c = 0; c < 3; ++c)
        d += (x[3 * i + c] - x[3 * j + c]) * (x[3 * i + c] - x[3 * j + c]);
      best = d < best ? d : best;
    }
    best = sqrt(best);
    s += best;
    s2 += best * best;
    *dmin = best < *dmin ? best : *dmin;
  }
  double mean = s / (double)n;
  *cv = sqrt(fmax(s2 / (double)n - mean * mean, 0.0)) / mean;
}

START_TEST(jitter_is_seeded_and_bounded) {
  const double dp = 0.001;
  sph_body b = round_body(SPH_SHAPE_RING, dp);
  double *x0, *v0, *x1, *v1, *x2, *v2, *x3, *v3;
  size_t n0, n1, n2, n3;
  ck_assert_int_eq(sph_body_generate(&b, 2, &x0, &v0, &n0, NULL), SPH_OK);
  b.distribution = SPH_DIST_JITTER;
  ck_assert_int_eq(sph_body_generate(&b, 2, &x1, &v1, &n1, NULL), SPH_OK);
  ck_assert_int_eq(sph_body_generate(&b, 2, &x2, &v2, &n2, NULL), SPH_OK);
  ck_assert_uint_eq(n1, n0);
  ck_assert_uint_eq(n2, n1);
  ck_assert_int_eq(memcmp(x1, x2, 3 * n1 * sizeof *x1), 0);
  ck_assert_int_eq(memcmp(v1, v0, n0 * sizeof *v0), 0);
  b.seed = 2;
  ck_assert_int_eq(sph_body_generate(&b, 2, &x3, &v3, &n3, NULL), SPH_OK);
  ck_assert_uint_eq(n3, n1);
  ck_assert_int_ne(memcmp(x1, x3, 3 * n1 * sizeof *x1), 0);
  /* offsets within +-jitter dp per axis, spanning that range */
  double amax = 0.0, bound = b.jitter * dp, slack = 4 * EPS * 0.3;
  size_t moved = 0;
  for (size_t i = 0; i < n1; ++i) {
    ck_assert(x1[3 * i + 2] == 0.0);
    moved += x1[3 * i] != x0[3 * i];
    for (int c = 0; c < 2; ++c) {
      double a = fabs(x1[3 * i + c] - x0[3 * i + c]);
      ck_assert(a <= bound + slack);
      amax = a > amax ? a : amax;
    }
  }
  ck_assert(amax > 0.99 * bound);
  ck_assert(moved > 9 * n1 / 10);
  ck_assert(worst_distance(&b, 2, x1, n1) < 0.0);
  free(x0);
  free(v0);
  free(x1);
  free(v1);
  free(x2);
  free(v2);
  free(x3);
  free(v3);

  /* a face lattice keeps its face particles on the faces */
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 0.5, 0.25};
  b = box_faces(lo, hi, 9, 5, 3);
  b.distribution = SPH_DIST_JITTER;
  b.jitter = 0.4;
  b.seed = 7;
  ck_assert_int_eq(sph_body_generate(&b, 3, &x0, &v0, &n0, NULL), SPH_OK);
  size_t on_faces = 0;
  for (size_t i = 0; i < n0; ++i)
    for (int c = 0; c < 3; ++c) {
      ck_assert(x0[3 * i + c] >= lo[c] && x0[3 * i + c] <= hi[c]);
      on_faces += x0[3 * i + c] == lo[c] || x0[3 * i + c] == hi[c];
    }
  /* particles on faces, counted once per face: 2 (5 3 + 9 3 + 9 5) */
  ck_assert_uint_eq(on_faces, 2 * (15 + 27 + 45));
  ck_assert(fabs(sum_of(v0, n0) - 0.125) <= n0 * EPS * 0.125);
  free(x0);
  free(v0);
}
END_TEST

/* relaxes a body; checks it stays dp/2 inside, repeats bitwise, keeps the
 * exact total volume and improves on the jittered start */
static void check_relax(sph_body b, int dim) {
  double *xj, *vj, *x1, *v1, *x2, *v2;
  size_t nj, n1, n2;
  b.distribution = SPH_DIST_JITTER;
  ck_assert_int_eq(sph_body_generate(&b, dim, &xj, &vj, &nj, NULL), SPH_OK);
  b.distribution = SPH_DIST_RELAX;
  ck_assert_int_eq(sph_body_generate(&b, dim, &x1, &v1, &n1, NULL), SPH_OK);
  /* the same with one thread */
#ifdef _OPENMP
  int threads = omp_get_max_threads();
  omp_set_num_threads(1);
#endif
  ck_assert_int_eq(sph_body_generate(&b, dim, &x2, &v2, &n2, NULL), SPH_OK);
#ifdef _OPENMP
  omp_set_num_threads(threads);
#endif
  ck_assert_uint_eq(n1, nj);
  ck_assert_uint_eq(n2, n1);
  ck_assert_int_eq(memcmp(x1, x2, 3 * n1 * sizeof *x1), 0);
  double m = sph_shape_measure(&b.shape, dim);
  ck_assert(fabs(sum_of(v1, n1) - m) <= n1 * EPS * m);
  /* the wall projection leaves every particle dp/2 inside, up to the
   * round-off of coordinates of order 1 */
  double dp = pow(m / (double)n1, 1.0 / dim);
  double worst = worst_distance(&b, dim, x1, n1);
  ck_assert_msg(worst <= -0.5 * dp + 64 * EPS, "worst %.17g dp", worst / dp);
  for (size_t i = 0; dim == 2 && i < n1; ++i)
    ck_assert(x1[3 * i + 2] == 0.0);
  /* a real improvement: the closest pair opens up and the spread of the
   * nearest-neighbour distances at least halves */
  double dmin_j, cv_j, dmin_r, cv_r;
  nn_stats(xj, nj, &dmin_j, &cv_j);
  nn_stats(x1, n1, &dmin_r, &cv_r);
  ck_assert_msg(dmin_r > dmin_j && cv_r < 0.5 * cv_j,
                "%s: jittered min %.3f dp cv %.4f, relaxed min %.3f dp cv "
                "%.4f",
                b.name, dmin_j / dp, cv_j, dmin_r / dp, cv_r);
  free(xj);
  free(vj);
  free(x1);
  free(v1);
  free(x2);
  free(v2);
}

START_TEST(relaxation_is_uniform_inside_and_repeatable) {
  sph_body ring = round_body(SPH_SHAPE_RING, 0.001);
  snprintf(ring.name, sizeof ring.name, "ring");
  check_relax(ring, 2);
  sph_body disc = round_body(SPH_SHAPE_DISC, 0.001);
  snprintf(disc.name, sizeof disc.name, "disc");
  check_relax(disc, 2);
  sph_body box = make_body("plate", SPH_SHAPE_BOX);
  box.shape.max[0] = 0.05;
  box.shape.max[1] = 0.03;
  box.spacing = 0.001;
  box.jitter = 0.25;
  box.relax_steps = 40;
  check_relax(box, 2);
  check_relax(round_body(SPH_SHAPE_SPHERE, 0.005), 3);
}
END_TEST

START_TEST(shape_and_dimension_errors) {
  double *x = NULL, *v = NULL;
  size_t n = 1;
  sph_error err;
  sph_body b = round_body(SPH_SHAPE_SPHERE, 0.01);
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  ck_assert_ptr_nonnull(strstr(err.message, "'round'"));
  ck_assert_ptr_nonnull(strstr(err.message, "3D"));
  ck_assert(x == NULL && v == NULL && n == 0);
  b = round_body(SPH_SHAPE_SHELL, 0.01);
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  b = round_body(SPH_SHAPE_DISC, 0.01);
  ck_assert_int_eq(sph_body_generate(&b, 3, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  ck_assert_ptr_nonnull(strstr(err.message, "2D"));
  b = round_body(SPH_SHAPE_RING, 0.01);
  b.shape.length = 0.0;
  ck_assert_int_eq(sph_body_generate(&b, 3, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  ck_assert_ptr_nonnull(strstr(err.message, "length"));
  /* spacing far larger than the ring */
  b = round_body(SPH_SHAPE_RING, 0.5);
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  ck_assert_ptr_nonnull(strstr(err.message, "body 'round' has no particles"));
  ck_assert_ptr_nonnull(strstr(err.message, "spacing 0.5"));
  b = round_body(SPH_SHAPE_DISC, 0.0);
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  /* face lattices: boxes only, two particles per axis at least */
  b = round_body(SPH_SHAPE_DISC, 0.01);
  b.lattice = SPH_LATTICE_FACES;
  b.count[0] = b.count[1] = 5;
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  b = box_faces(lo, hi, 5, 1, 5);
  ck_assert_int_eq(sph_body_generate(&b, 3, &x, &v, &n, &err),
                   SPH_ERR_GEOMETRY);
  ck_assert_ptr_nonnull(strstr(err.message, "'column'"));
  b = box_faces(lo, hi, 5, 5, 1);
  ck_assert_int_eq(sph_body_generate(&b, 2, &x, &v, &n, NULL), SPH_OK);
  ck_assert_uint_eq(n, 25);
  free(x);
  free(v);
}
END_TEST

/* runs sph_expr_create with stdout captured; returns the bytes printed */
static long create_quietly(sph_expr **e, const char *text, sph_error *err,
                           sph_status *st) {
  fflush(stdout);
  FILE *tmp = tmpfile();
  ck_assert_ptr_nonnull(tmp);
  int saved = dup(STDOUT_FILENO);
  dup2(fileno(tmp), STDOUT_FILENO);
  *st = sph_expr_create(e, text, err);
  fflush(stdout);
  dup2(saved, STDOUT_FILENO);
  close(saved);
  fseek(tmp, 0, SEEK_END);
  long printed = ftell(tmp);
  fclose(tmp);
  return printed;
}

START_TEST(expressions) {
  sph_expr *e;
  sph_error err;
  ck_assert_int_eq(sph_expr_create(&e, "sin(pi*y/(2*6))", &err), SPH_OK);
  ck_assert(fabs(sph_expr_eval(e, 0, 3, 0, 0) - sin(M_PI / 4)) <= 2 * EPS);
  ck_assert(fabs(sph_expr_eval(e, 5, 6, 7, 8) - 1.0) <= 2 * EPS);
  ck_assert_str_eq(sph_expr_text(e), "sin(pi*y/(2*6))");
  sph_expr_destroy(e);
  ck_assert_int_eq(sph_expr_create(&e, "5*z/3 + t - x^2", &err), SPH_OK);
  ck_assert(fabs(sph_expr_eval(e, 2, 100, 3, 1) - 2.0) <= 8 * EPS);
  sph_expr_destroy(e);
  ck_assert_int_eq(sph_expr_create(&e, "cosh(x) - (exp(x) + exp(-x))/2", &err),
                   SPH_OK);
  ck_assert(fabs(sph_expr_eval(e, 0.7, 0, 0, 0)) <= 8 * EPS);
  sph_expr_destroy(e);
  ck_assert_int_eq(sph_expr_create(&e, "2*pi", &err), SPH_OK);
  ck_assert(sph_expr_eval(e, 1, 2, 3, 4) == 2 * M_PI);
  sph_expr_destroy(e);
  /* malformed: parser errors and characters the scanner does not know,
   * which libmatheval would echo to stdout */
  const char *bad[] = {"sin((", "",    "2x",    "x $ 2",
                       "x < 1", "5.x", "y\n+1", "sin + 1"};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; ++i) {
    sph_status st;
    e = (sph_expr *)&err;
    ck_assert_int_eq(create_quietly(&e, bad[i], &err, &st), 0);
    ck_assert_int_eq(st, SPH_ERR_SYNTAX);
    ck_assert_ptr_null(e);
    ck_assert_ptr_nonnull(strstr(err.message, "cannot parse expression"));
  }
  ck_assert_int_eq(sph_expr_create(&e, "1 + 2x", &err), SPH_ERR_SYNTAX);
  ck_assert_ptr_nonnull(strstr(err.message, "position 6"));
  ck_assert_int_eq(sph_expr_create(&e, "sin(x", &err), SPH_ERR_SYNTAX);
  ck_assert_ptr_nonnull(strstr(err.message, "expected ')' at position 6"));
  /* unknown variables are named, with the ones allowed */
  ck_assert_int_eq(sph_expr_create(&e, "omega*x", &err), SPH_ERR_ARG);
  ck_assert_ptr_nonnull(strstr(err.message, "'omega'"));
  ck_assert_ptr_nonnull(strstr(err.message, "x, y, z"));
  ck_assert_int_eq(sph_expr_create(&e, "X + 1", &err), SPH_ERR_ARG);
  ck_assert_ptr_nonnull(strstr(err.message, "'X'"));
  /* a good expression parses after the failures */
  ck_assert_int_eq(sph_expr_create(&e, "x + y", &err), SPH_OK);
  ck_assert(sph_expr_eval(e, 1, 2, 0, 0) == 3.0);
  sph_expr_destroy(e);
}
END_TEST

int main(void) {
  Suite *s = suite_create("geometry");
  TCase *tc = tcase_create("geometry");
  tcase_set_timeout(tc, 120);
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, face_lattice_has_tributary_volumes);
  tcase_add_test(tc, cell_lattice_tiles_a_box);
  tcase_add_test(tc, clipped_lattices_fill_their_shapes);
  tcase_add_test(tc, distances_bounds_and_measures);
  tcase_add_test(tc, jitter_is_seeded_and_bounded);
  tcase_add_test(tc, relaxation_is_uniform_inside_and_repeatable);
  tcase_add_test(tc, shape_and_dimension_errors);
  tcase_add_test(tc, expressions);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
