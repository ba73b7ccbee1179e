/* One rank's share of the particles without the whole set
 * (sph_scene_build_share, issue 20): every share's particles equal the
 * whole set's after sph_particles_sort_morton at their storage indices, bit
 * for bit, and the shares cover the storage indices once (2D and 3D, face
 * and cell lattices, jitter, several bodies with transforms and initial
 * velocities, a grid beyond the Morton order's 2^21 clamp, relaxed
 * bodies); bodies that overlap give the whole set's error. */
#include "test_util.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/particles.h"
#include "scene/geometry.h"
#include "scene/scene.h"
#include "test_scene_util.h"

static int same(const void *a, const void *b, size_t n) {
  return memcmp(a, b, n) == 0;
}

/* the shares of `size` ranks against the sorted whole set */
static void check_shares(const char *text, double cell, int size) {
  sph_scene *s = sph_test_scene_text(text);
  sph_error err;
  sph_particles *all = NULL;
  ck_assert_int_eq(sph_scene_build_particles(s, &all, &err), SPH_OK);
  ck_assert_int_eq(sph_particles_sort_morton(all, cell, &err), SPH_OK);
  size_t N = all->n, seen = 0;
  char *hit = calloc(N, 1);
  for (int r = 0; r < size; ++r) {
    sph_particles *ps = NULL;
    int64_t *gidx = NULL;
    size_t total = 0;
    int64_t first;
    ck_assert_int_eq(sph_scene_build_share(s, cell, r, size, &ps, &gidx, &total,
                                           &first, &err),
                     SPH_OK);
    ck_assert_int_eq(first, INT64_MAX);
    ck_assert_ptr_nonnull(ps);
    ck_assert_uint_eq(total, N);
    ck_assert_uint_eq(ps->n, N * (size_t)(r + 1) / (size_t)size -
                                 N * (size_t)r / (size_t)size);
    for (size_t i = 0; i < ps->n; ++i) {
      int64_t g = gidx[i];
      ck_assert(g >= 0 && (size_t)g < N && !hit[g]);
      hit[g] = 1;
      ++seen;
      /* a rank keeps the storage indices of its share */
      ck_assert((size_t)g >= N * (size_t)r / (size_t)size &&
                (size_t)g < N * (size_t)(r + 1) / (size_t)size);
      ck_assert_msg(same(ps->field[SPH_FIELD_POSITION0] + 3 * i,
                         all->field[SPH_FIELD_POSITION0] + 3 * g,
                         3 * sizeof(double)),
                    "rank %d particle %zu (storage %lld)", r, i, (long long)g);
      ck_assert(same(ps->field[SPH_FIELD_VOLUME0] + i,
                     all->field[SPH_FIELD_VOLUME0] + g, sizeof(double)));
      ck_assert(same(ps->field[SPH_FIELD_VELOCITY] + 3 * i,
                     all->field[SPH_FIELD_VELOCITY] + 3 * g,
                     3 * sizeof(double)));
      ck_assert_int_eq(ps->id[i], all->id[g]);
      ck_assert_int_eq(ps->body[i], all->body[g]);
      ck_assert_uint_eq(ps->flags[i], all->flags[g]);
    }
    sph_particles_destroy(ps);
    free(gidx);
  }
  ck_assert_uint_eq(seen, N);
  free(hit);
  sph_particles_destroy(all);
  sph_scene_destroy(s);
}

/* a jittered face lattice (a turned column) beside a jittered cylinder
 * and a ball of cells, a clamp and a probe */
static const char *const scene3 = SPH_TEST_SCENE_HEAD(
    3) "  - name: column\n"
       "    material: m\n"
       "    shape: {box: {min: [-0.5, 0, -0.5], max: [0.5, 6, 0.5]}}\n"
       "    particles: {count: [6, 31, 5], distribution: jitter, jitter: "
       "0.3, seed: 7}\n"
       "    transform: {rotate: {axis: [1, 1, 0], angle: 20}, translate: "
       "[0.1, 0.2, 0.3]}\n"
       "    initial_velocity: {rotation: {axis: y, omega: 105, profile: "
       "\"sin(pi*y/(2*6))\"}}\n"
       "  - name: can\n"
       "    material: m\n"
       "    shape: {cylinder: {center: [3, 0, 0], axis: z, radius: 0.7, "
       "length: 2}}\n"
       "    particles: {spacing: 0.17, distribution: jitter, seed: 3}\n"
       "    initial_velocity: {uniform: [1, 2, 3]}\n"
       "  - name: ball\n"
       "    material: m\n"
       "    shape: {sphere: {center: [-3, 2, 0], radius: 0.8}}\n"
       "    particles: {spacing: 0.15}\n"
       "boundaries:\n"
       "  - {name: base, select: {plane: {axis: y, at: 0.2}}, clamp: "
       "true}\n"
       "output:\n"
       "  probes: [{name: p, at: [3, 0, 1]}]\n";

/* a turned jittered plate of cells beside a jittered ring */
static const char *const scene2 = SPH_TEST_SCENE_HEAD(
    2) "  - name: plate\n"
       "    material: m\n"
       "    shape: {box: {min: [0, 0], max: [2, 0.4]}}\n"
       "    particles: {spacing: 0.021, distribution: jitter, jitter: "
       "0.45, seed: 11}\n"
       "    transform: {rotate: {angle: 30}, translate: [0.5, -1]}\n"
       "    initial_velocity: {expression: [\"x*y\", \"-x\", \"0\"]}\n"
       "  - name: ring\n"
       "    material: m\n"
       "    shape: {ring: {center: [-1, 1], inner_radius: 0.2, "
       "outer_radius: 0.35}}\n"
       "    particles: {spacing: 0.02, distribution: jitter, seed: 5}\n"
       "boundaries:\n"
       "  - {name: left, select: {box: {min: [-2, 0.5], max: [-0.5, 1]}}, "
       "clamp: true}\n";

/* a bar whose cells pass the 2^21 clamp of the Morton order along x */
static const char *const bar2 = SPH_TEST_SCENE_HEAD(
    2) "  - name: bar\n"
       "    material: m\n"
       "    shape: {box: {min: [0, 0], max: [1, 1e-7]}}\n"
       "    particles: {count: [3000, 2], distribution: jitter, seed: 2}\n";

/* the creation index of the first particle with a neighbour of another
 * body closer than dp / 2, by brute force */
static int64_t first_overlap(const sph_scene *s) {
  size_t n = 0;
  double *X = NULL;
  int32_t *body = NULL;
  sph_error err;
  for (size_t b = 0; b < s->nbodies; ++b) {
    double *x, *v;
    size_t m;
    ck_assert_int_eq(
        sph_body_generate(&s->bodies[b], s->dimension, &x, &v, &m, &err),
        SPH_OK);
    X = realloc(X, 3 * (n + m) * sizeof *X);
    body = realloc(body, (n + m) * sizeof *body);
    for (size_t i = 0; i < m; ++i, ++n) {
      sph_body_world(&s->bodies[b], x + 3 * i, X + 3 * n);
      body[n] = (int32_t)b;
    }
    free(x);
    free(v);
  }
  double r = 0.5 * sph_scene_min_spacing(s);
  int64_t first = -1;
  for (size_t a = 0; a < n && first < 0; ++a)
    for (size_t b = 0; b < n && first < 0; ++b) {
      double d2 = 0.0;
      for (int c = 0; c < 3; ++c)
        d2 += (X[3 * a + c] - X[3 * b + c]) * (X[3 * a + c] - X[3 * b + c]);
      if (body[a] != body[b] && d2 < r * r)
        first = (int64_t)a;
    }
  free(X);
  free(body);
  return first;
}

/* bodies that overlap: the shares' error of the lowest creation index is
 * the whole set's, message and all */
static void check_overlap(const char *text, double cell, int size) {
  sph_scene *s = sph_test_scene_text(text);
  sph_error whole, err, best;
  sph_particles *all = NULL;
  ck_assert_int_eq(sph_scene_build_particles(s, &all, &whole),
                   SPH_ERR_GEOMETRY);
  int64_t low = INT64_MAX;
  for (int r = 0; r < size; ++r) {
    sph_particles *ps = NULL;
    int64_t *gidx = NULL, first;
    size_t total;
    sph_status st = sph_scene_build_share(s, cell, r, size, &ps, &gidx, &total,
                                          &first, &err);
    ck_assert(st == SPH_OK || first < INT64_MAX);
    if (st != SPH_OK && first < low)
      low = first, best = err;
    sph_particles_destroy(ps);
    free(gidx);
  }
  ck_assert_int_eq(low, first_overlap(s));
  ck_assert_str_eq(best.message, whole.message);
  sph_scene_destroy(s);
}

/* a turned box resting into a cylinder of cells; a third body apart */
static const char *const overlap3 = SPH_TEST_SCENE_HEAD(
    3) "  - name: far\n"
       "    material: m\n"
       "    shape: {sphere: {center: [-3, 0, 0], radius: 0.5}}\n"
       "    particles: {spacing: 0.1}\n"
       "  - name: can\n"
       "    material: m\n"
       "    shape: {cylinder: {center: [0, 0, 0], axis: y, radius: 0.7, "
       "length: 1}}\n"
       "    particles: {spacing: 0.1, distribution: jitter, seed: 3}\n"
       "  - name: lid\n"
       "    material: m\n"
       "    shape: {box: {min: [-0.5, 0.97, -0.5], max: [0.5, 1.3, 0.5]}}\n"
       "    particles: {count: [11, 4, 11], distribution: jitter, seed: "
       "4}\n"
       "    transform: {rotate: {axis: [1, 0, 1], angle: 3}}\n";

START_TEST(share_overlap) {
  /* many small shares: the pair found across shares */
  static const int sizes[] = {1, 2, 3, 4, 17, 50, 200};
  for (size_t k = 0; k < sizeof sizes / sizeof *sizes; ++k)
    check_overlap(overlap3, 0.26, sizes[k]);
}
END_TEST

START_TEST(share_3d) {
  for (int size = 1; size <= 4; ++size)
    check_shares(scene3, 0.41, size);
  check_shares(scene3, 0.08, 3); /* fewer particles a cell */
  /* cells smaller than half the spacing: the overlap check needs the
   * whole set */
  sph_scene *s = sph_test_scene_text(scene3);
  sph_particles *ps = NULL;
  int64_t *gidx = NULL, first;
  size_t total;
  sph_error err;
  ck_assert_int_eq(
      sph_scene_build_share(s, 0.07, 0, 2, &ps, &gidx, &total, &first, &err),
      SPH_OK);
  ck_assert_ptr_null(ps);
  sph_scene_destroy(s);
}
END_TEST

START_TEST(share_2d) {
  for (int size = 1; size <= 3; ++size)
    check_shares(scene2, 0.052, size);
}
END_TEST

/* two relaxed rings (seed 002's colliding rings, coarser), the second
 * turned */
static const char *rings2 = SPH_TEST_SCENE_HEAD(
    2) "  - name: left\n"
       "    material: m\n"
       "    shape: {ring: {center: [-0.045, 0], inner_radius: 0.03, "
       "outer_radius: 0.04}}\n"
       "    particles: {spacing: 0.002, distribution: relax, seed: 1}\n"
       "    initial_velocity: {uniform: [7, 0, 0]}\n"
       "  - name: right\n"
       "    material: m\n"
       "    shape: {ring: {center: [0, 0], inner_radius: 0.03, "
       "outer_radius: 0.04}}\n"
       "    particles: {spacing: 0.002, distribution: relax, seed: 2, "
       "relax_steps: 40}\n"
       "    transform: {rotate: {angle: 30}, translate: [0.045, 0]}\n";

START_TEST(share_relax) {
  /* one rank relaxes each body through its own lists (the serial lists'
   * grid, stencil and order): the whole set's points */
  for (int size = 1; size <= 3; ++size)
    check_shares(rings2, 0.0052, size);
}
END_TEST

START_TEST(share_clamp) {
  /* 3.0e6 cells across the bar: its last 900 particles share the last
   * cell, in creation order */
  check_shares(bar2, 1.0 / 3.0e6, 2);
}
END_TEST

static Suite *suite(void) {
  Suite *s = suite_create("share");
  TCase *t = tcase_create("share");
  tcase_set_timeout(t, 300);
  tcase_add_test(t, share_3d);
  tcase_add_test(t, share_2d);
  tcase_add_test(t, share_clamp);
  tcase_add_test(t, share_overlap);
  tcase_add_test(t, share_relax);
  suite_add_tcase(s, t);
  return s;
}

int main(void) { return sph_test_run(suite()); }
