/* Particle files as bodies (shape: {particles: {file}}, src/scene/cloud.c):
 * the built-in box's particles written as a CSV give them back bit for bit,
 * the spacing estimate is the brute-force median nearest-neighbour
 * distance, units scale positions and volumes, the body's transform moves
 * the file's particles, and +0 and -0 are one position. */
#include "test_scene_util.h"
#include "test_util.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/particles.h"
#include "scene/cloud.h"
#include "scene/scene.h"

static char csv_path[64];

static sph_particles *particles_of(int dim, const char *shape,
                                   const char *particles,
                                   const char *transform) {
  char text[2048];
  sph_test_one_body(text, sizeof text, dim, "tl-jst", shape, particles,
                    transform);
  return sph_test_scene_particles(text, shape);
}

/* ps's particles as a CSV (17 digits: exact) at csv_path */
static void write_csv(const sph_particles *ps, int volumes) {
  snprintf(csv_path, sizeof csv_path, "/tmp/sph_cloud_%d.csv", (int)getpid());
  FILE *f = fopen(csv_path, "w");
  ck_assert_ptr_nonnull(f);
  fprintf(f, "x, y, z%s\n", volumes ? ", volume" : "");
  for (size_t i = 0; i < ps->n; ++i) {
    const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * i;
    fprintf(f, "%.17g, %.17g, %.17g", X[0], X[1], X[2]);
    if (volumes)
      fprintf(f, ", %.17g", ps->field[SPH_FIELD_VOLUME0][i]);
    fputc('\n', f);
  }
  fclose(f);
}

START_TEST(test_box_csv_is_the_box) {
  sph_particles *b = particles_of(3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}",
                                  "{count: [5, 6, 7]}", NULL);
  write_csv(b, 1);
  char shape[128];
  snprintf(shape, sizeof shape, "{particles: {file: %s}}", csv_path);
  sph_particles *p = particles_of(3, shape, NULL, NULL);
  unlink(csv_path);
  sph_test_assert_same_particles(b, p, "box.csv");
  sph_particles_destroy(b);
  sph_particles_destroy(p);
}
END_TEST

static double brute_median(const sph_cloud *c) {
  double *d = malloc(c->n * sizeof *d);
  for (size_t i = 0; i < c->n; ++i) {
    d[i] = INFINITY;
    for (size_t j = 0; j < c->n; ++j) {
      const double *X = c->x + 3 * i, *Y = c->x + 3 * j;
      double d2 = (X[0] - Y[0]) * (X[0] - Y[0]) +
                  (X[1] - Y[1]) * (X[1] - Y[1]) + (X[2] - Y[2]) * (X[2] - Y[2]);
      if (j != i && sqrt(d2) < d[i])
        d[i] = sqrt(d2);
    }
  }
  for (size_t i = 1; i < c->n; ++i) /* insertion sort: few points */
    for (size_t k = i; k > 0 && d[k] < d[k - 1]; --k) {
      double t = d[k];
      d[k] = d[k - 1];
      d[k - 1] = t;
    }
  double m = d[(c->n - 1) / 2];
  free(d);
  return m;
}

START_TEST(test_spacing_is_the_median_distance) {
  snprintf(csv_path, sizeof csv_path, "/tmp/sph_cloud_%d.csv", (int)getpid());
  for (int dim = 2; dim <= 3; ++dim) {
    FILE *f = fopen(csv_path, "w");
    ck_assert_ptr_nonnull(f);
    fprintf(f, dim == 3 ? "id, x, y, z\n" : "id; y; x\n");
    uint64_t s = 12345;
    for (int i = 0; i < 700; ++i) { /* clustered and spread: an LCG */
      double v[3];
      for (int k = 0; k < 3; ++k) {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        v[k] = (double)(s >> 11) * 0x1.0p-53 * (i < 200 ? 0.1 : 3.0);
      }
      fprintf(f, dim == 3 ? "%d, %.17g, %.17g, %.17g\n" : "%d; %.17g; %.17g\n",
              i, v[0], v[1], v[2]);
    }
    fclose(f);
    sph_cloud *c;
    sph_error err;
    sph_status st = sph_cloud_read(csv_path, dim, 1.0, &c, &err);
    ck_assert_msg(st == SPH_OK, "%s", err.message);
    ck_assert_uint_eq(c->n, 700);
    ck_assert(!c->has_volume);
    ck_assert(c->nn_median > 0.0);
    ck_assert(c->nn_median == brute_median(c));
    ck_assert(c->step[0] == 0.0); /* not a lattice: no checkerboard parity */
    sph_cloud_destroy(c);
  }
  unlink(csv_path);
}
END_TEST

START_TEST(test_units_and_transform) {
  snprintf(csv_path, sizeof csv_path, "/tmp/sph_cloud_%d.csv", (int)getpid());
  FILE *f = fopen(csv_path, "w");
  fprintf(f, "x,y,volume\n");
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 3; ++j)
      fprintf(f, "%d,%d,%g\n", 10 * i, 10 * j, i == 0 ? 50.0 : 100.0);
  fclose(f);
  char shape[128];
  snprintf(shape, sizeof shape, "{particles: {file: %s, units: mm}}", csv_path);
  sph_particles *p = particles_of(2, shape, NULL, NULL);
  sph_particles *t = particles_of(2, shape, "{spacing: 0.01}",
                                  "{rotate: {angle: 90}, translate: [2, 1]}");
  ck_assert_uint_eq(p->n, 12);
  sph_cloud *c;
  sph_error err;
  ck_assert_int_eq(sph_cloud_read(csv_path, 2, 1e-3, &c, &err), SPH_OK);
  ck_assert_double_eq_tol(c->step[0], 1e-2, 1e-15); /* a lattice's steps */
  ck_assert_double_eq_tol(c->step[1], 1e-2, 1e-15);
  sph_cloud_destroy(c);
  ck_assert_uint_eq(t->n, 12);
  for (size_t a = 0; a < p->n; ++a) {
    const double *X = p->field[SPH_FIELD_POSITION0] + 3 * a;
    const double *Y = t->field[SPH_FIELD_POSITION0] + 3 * a;
    ck_assert_double_eq_tol(X[0], 1e-2 * (double)(a / 3), 1e-15);
    ck_assert_double_eq_tol(X[1], 1e-2 * (double)(a % 3), 1e-15);
    ck_assert_double_eq_tol(p->field[SPH_FIELD_VOLUME0][a], a < 3 ? 5e-5 : 1e-4,
                            1e-18);
    /* (x, y) -> (2 - y, 1 + x) */
    ck_assert_double_eq_tol(Y[0], 2.0 - X[1], 1e-14);
    ck_assert_double_eq_tol(Y[1], 1.0 + X[0], 1e-14);
  }
  sph_particles_destroy(p);
  sph_particles_destroy(t);
}
END_TEST

START_TEST(test_signed_zero_is_one_position) {
  snprintf(csv_path, sizeof csv_path, "/tmp/sph_cloud_%d.csv", (int)getpid());
  FILE *f = fopen(csv_path, "w");
  fprintf(f, "x, y\n0, 1\n1, 1\n-0, 1\n");
  fclose(f);
  sph_cloud *c;
  sph_error err;
  ck_assert_int_eq(sph_cloud_read(csv_path, 2, 1.0, &c, &err),
                   SPH_ERR_GEOMETRY);
  ck_assert_msg(strstr(err.message, "two particles at one position") &&
                    strstr(err.message, "line 2 and line 4"),
                "%s", err.message);
  unlink(csv_path);
}
END_TEST

static Suite *cloud_suite(void) {
  Suite *s = suite_create("cloud");
  TCase *tc = tcase_create("core");
  tcase_set_timeout(tc, 60);
  tcase_add_test(tc, test_box_csv_is_the_box);
  tcase_add_test(tc, test_spacing_is_the_median_distance);
  tcase_add_test(tc, test_units_and_transform);
  tcase_add_test(tc, test_signed_zero_is_one_position);
  suite_add_tcase(s, tc);
  return s;
}

int main(void) { return sph_test_run(cloud_suite()); }
