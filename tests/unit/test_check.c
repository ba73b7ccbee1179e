/* The assertion tier (src/core/check.h): SPH_CHECK fires with
 * SPH_ERR_INTERNAL naming its file and line; the always-on checks of the
 * particle order, the kernel, the correction cloud and the time step fire
 * on corrupted input; the neighbour-list scan the debug tier runs after
 * every build fires on each kind of corrupted list. Built twice: test_check
 * (the build's own setting) and test_check_debug (SPH_DEBUG_CHECKS=1 for
 * this file and the core sources compiled into it), where SPH_DEBUG_CHECK
 * fires and the library's debug scans run on the builds below. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/check.h"
#include "core/corrections.h"
#include "core/kernel.h"
#include "core/neighbors.h"
#include "core/particles.h"
#ifndef SPH_TEST_CORE_ONLY
#include "solver/sim.h"
#include "test_scene_util.h"
#endif

static int evaluated;

static int count_eval(int v) {
  ++evaluated;
  return v;
}

static int check_line;
static sph_status fails_check(int v, sph_error *err) {
  check_line = __LINE__ + 1;
  SPH_CHECK(v == 1, err, "v is %d", v);
  return SPH_OK;
}

static sph_status fails_debug_check(sph_error *err) {
  SPH_DEBUG_CHECK(count_eval(0), err, "expensive scan found %d", 42);
  return SPH_OK;
}

START_TEST(check_fills_internal_error) {
  sph_error err;
  ck_assert_int_eq(fails_check(1, &err), SPH_OK);
  ck_assert_int_eq(fails_check(2, &err), SPH_ERR_INTERNAL);
  ck_assert_int_eq(err.code, SPH_ERR_INTERNAL);
  char want[64];
  snprintf(want, sizeof want, "test_check.c:%d: v is 2", check_line);
  ck_assert_msg(strstr(err.message, want), "%s", err.message);
  ck_assert_str_eq(sph_status_name(SPH_ERR_INTERNAL), "SPH_ERR_INTERNAL");
  ck_assert_str_eq(sph_status_message(SPH_ERR_INTERNAL),
                   "internal invariant violated");
  ck_assert_int_eq(SPH_ERR_INTERNAL + 1, SPH_STATUS_COUNT); /* appended */
  ck_assert_int_eq(fails_check(3, NULL), SPH_ERR_INTERNAL); /* NULL record */
}
END_TEST

START_TEST(debug_check_only_in_debug_builds) {
  sph_error err;
  evaluated = 0;
  sph_status st = fails_debug_check(&err);
  if (SPH_DEBUG_CHECKS_ON) {
    ck_assert_int_eq(st, SPH_ERR_INTERNAL);
    ck_assert_int_eq(evaluated, 1);
    ck_assert_msg(strstr(err.message, "expensive scan found 42"), "%s",
                  err.message);
  } else {
    ck_assert_int_eq(st, SPH_OK);
    ck_assert_int_eq(evaluated, 0); /* the condition is not evaluated */
  }
}
END_TEST

/* a jittered 2D lattice of nx x ny points of spacing 1 */
static double *lattice(size_t nx, size_t ny) {
  double *x = calloc(3 * nx * ny, sizeof *x);
  for (size_t i = 0; i < nx; ++i)
    for (size_t j = 0; j < ny; ++j) {
      double *p = x + 3 * (i * ny + j);
      p[0] = (double)i + 0.1 * sin(3.0 * (double)(i + 2 * j));
      p[1] = (double)j + 0.1 * cos(5.0 * (double)(2 * i + j));
    }
  return x;
}

static void assert_internal(sph_status st, const sph_error *err,
                            const char *text) {
  ck_assert_int_eq(st, SPH_ERR_INTERNAL);
  ck_assert_msg(strstr(err->message, text), "'%s' lacks '%s'", err->message,
                text);
}

START_TEST(neighbor_scan_fires_on_corrupted_lists) {
  size_t n = 100;
  double *x = lattice(10, 10), r = 2.1;
  sph_neighbors *nl;
  sph_error err;
  ck_assert_int_eq(sph_neighbors_create(&nl, &err), SPH_OK);
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, n, 2, r, NULL, SPH_PAIRS_ALL, &err), SPH_OK);
  ck_assert_int_eq(sph_neighbors_check(nl, x, 2, r, &err), SPH_OK);
  size_t a = 55, k = nl->offset[a]; /* an interior particle */
  ck_assert_uint_ge(nl->offset[a + 1] - k, 4);
  int32_t *l = nl->index + k;

  /* out of order */
  int32_t t = l[0];
  l[0] = l[1], l[1] = t;
  assert_internal(sph_neighbors_check(nl, x, 2, r, &err), &err,
                  "neighbour list of particle 55 is not strictly ascending");
  l[1] = l[0], l[0] = t;
  /* a duplicate */
  l[1] = l[0];
  assert_internal(sph_neighbors_check(nl, x, 2, r, &err), &err,
                  "not strictly ascending");
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, n, 2, r, NULL, SPH_PAIRS_ALL, &err), SPH_OK);
  /* the particle itself, an index out of range */
  l = nl->index + nl->offset[0];
  t = l[0];
  l[0] = 0;
  assert_internal(sph_neighbors_check(nl, x, 2, r, &err), &err,
                  "neighbour list of particle 0 holds 0");
  l[0] = -3;
  assert_internal(sph_neighbors_check(nl, x, 2, r, &err), &err,
                  "neighbour list of particle 0 holds -3");
  l[0] = t;
  /* beyond the radius: the same lists checked with a smaller one */
  assert_internal(sph_neighbors_check(nl, x, 2, 1.5, &err), &err,
                  "beyond the radius 1.5");
  /* counts that disagree with the offsets */
  nl->count += 1;
  assert_internal(sph_neighbors_check(nl, x, 2, r, &err), &err,
                  "neighbour offsets");
  nl->count -= 1;
  ck_assert_int_eq(sph_neighbors_check(nl, x, 2, r, &err), SPH_OK);
  sph_neighbors_destroy(nl);
  free(x);
}
END_TEST

START_TEST(neighbor_scan_fires_on_asymmetric_lists) {
  /* 0 - 1 - 2 on a line, radius 1.5: 1's list lacks 2 */
  double x[9] = {0, 0, 0, 1, 0, 0, 2, 0, 0};
  size_t offset[4] = {0, 1, 2, 3};
  int32_t index[3] = {1, 0, 1};
  sph_neighbors nl = {.n = 3, .count = 3, .offset = offset, .index = index};
  sph_error err;
  assert_internal(sph_neighbors_check(&nl, x, 1, 1.5, &err), &err,
                  "neighbour lists not symmetric: 1 is in the list of 2, "
                  "not 2 in that of 1");
  size_t good_offset[4] = {0, 1, 3, 4};
  int32_t good[4] = {1, 0, 2, 1};
  nl =
      (sph_neighbors){.n = 3, .count = 4, .offset = good_offset, .index = good};
  ck_assert_int_eq(sph_neighbors_check(&nl, x, 1, 1.5, &err), SPH_OK);
  ck_assert_int_eq(sph_neighbors_check(&nl, x, 1, 1.0, &err),
                   SPH_ERR_INTERNAL); /* |x_a - x_b| < radius strictly */
}
END_TEST

START_TEST(particle_order_check_fires_on_bad_ids) {
  sph_particles *ps;
  sph_error err;
  ck_assert_int_eq(sph_particles_create(&ps, 4, 2, &err), SPH_OK);
  for (int i = 0; i < 4; ++i) {
    double X[3] = {(double)(i % 2), (double)(i / 2), 0};
    ck_assert_int_eq(sph_particles_append(ps, X, 1.0, 0, &err), SPH_OK);
  }
  ps->id[2] = 9;
  assert_internal(sph_particles_sort_morton(ps, 1.0, &err), &err,
                  "particle order: id 9 of 4 particles");
  ps->id[2] = 2;
  ck_assert_int_eq(sph_particles_sort_morton(ps, 1.0, &err), SPH_OK);
  for (size_t j = 0; j < 4; ++j)
    ck_assert_int_eq(ps->id[sph_particles_slot(ps, j)], (int64_t)j);
  sph_particles_destroy(ps);
}
END_TEST

START_TEST(kernel_check_fires_on_degenerate_support) {
  sph_kernel k;
  sph_error err;
  ck_assert_int_eq(sph_kernel_create(&k, SPH_KERNEL_CUBIC, 3, 1e-3, &err),
                   SPH_OK);
  /* h^3 underflows: an infinite normalisation */
  assert_internal(sph_kernel_create(&k, SPH_KERNEL_CUBIC, 3, 1e-120, &err),
                  &err, "normalisation inf");
  /* 3 h overflows: an infinite support */
  assert_internal(sph_kernel_create(&k, SPH_KERNEL_QUINTIC, 1, 1e308, &err),
                  &err, "support inf");
}
END_TEST

START_TEST(correction_cloud_check_fires) {
  size_t n = 100;
  double *x = lattice(10, 10), V[100];
  for (size_t a = 0; a < n; ++a)
    V[a] = 1.0;
  sph_kernel k;
  sph_neighbors *nl;
  sph_error err;
  ck_assert_int_eq(sph_kernel_create(&k, SPH_KERNEL_WENDLAND_C2, 2, 1.3, &err),
                   SPH_OK);
  ck_assert_int_eq(sph_neighbors_create(&nl, &err), SPH_OK);
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, n, 2, k.support, NULL, SPH_PAIRS_ALL, &err),
      SPH_OK);
  double *grad = malloc(3 * nl->count * sizeof *grad), L[900];
  sph_cloud c = {.n = n, .dim = 2, .x = x, .volume = V, .nl = nl, .kernel = &k};
  /* with debug checks every L M = I is verified here */
  ck_assert_int_eq(
      sph_correction_gradient(&c, SPH_GRAD_CORRECTED, grad, NULL, L, &err),
      SPH_OK);
  ck_assert_int_eq(
      sph_correction_gradient(&c, SPH_GRAD_W1, grad, NULL, NULL, &err), SPH_OK);
  c.n = n + 1; /* more points than the lists */
  assert_internal(
      sph_correction_gradient(&c, SPH_GRAD_CORRECTED, grad, NULL, L, &err),
      &err, "correction cloud of 101 points with lists of 100");
  c.n = n;
  sph_kernel bad = k;
  bad.support = 0.0;
  c.kernel = &bad;
  assert_internal(sph_correction_laplacian(&c, grad, &err), &err,
                  "kernel support 0");
  free(grad);
  sph_neighbors_destroy(nl);
  free(x);
}
END_TEST

#ifndef SPH_TEST_CORE_ONLY
static sph_sim *small_sim(sph_scene **scene) {
  *scene = sph_test_scene_text(
      SPH_TEST_SCENE_HEAD(2) "  - name: plate\n"
                             "    material: m\n"
                             "    shape: {box: {min: [0, 0], max: [1, 0.5]}}\n"
                             "    particles: {count: [10, 5]}\n");
  sph_sim *sim;
  sph_error err;
  ck_assert_int_eq(sph_sim_create(&sim, *scene, &err), SPH_OK);
  return sim;
}

START_TEST(step_checks_fire) {
  sph_scene *scene;
  sph_sim *sim = small_sim(&scene);
  sph_error err;
  ck_assert_int_eq(sph_sim_step(sim, 1.0, &err), SPH_OK);
  /* a cap that is not positive: no step of dt <= 0 */
  assert_internal(sph_sim_step(sim, 0.0, &err), &err,
                  "sim.c:"); /* file and line of the check */
  ck_assert_msg(strstr(err.message, "time step 0 at t"), "%s", err.message);
  assert_internal(sph_sim_step(sim, -1.0, &err), &err, "time step -1");
  /* a timer index out of its table */
  int timer = sim->timer_stable_dt;
  sim->timer_stable_dt = SPH_MAX_TIMERS;
  assert_internal(sph_sim_step(sim, 1.0, &err), &err, "timer 8 of");
  sim->timer_stable_dt = timer;
  /* more terms than the table */
  int nterms = sim->nterms;
  sim->nterms = SPH_MAX_TERMS + 1;
  assert_internal(sph_sim_step(sim, 1.0, &err), &err, "17 terms");
  sim->nterms = nterms;
  unsigned long steps = sim->steps;
  ck_assert_int_eq(sph_sim_step(sim, 1.0, &err), SPH_OK);
  ck_assert_uint_eq(sim->steps, steps + 1);
  sph_sim_destroy(sim);
  sph_scene_destroy(scene);
}
END_TEST

/* a term that leaves a NaN in F after the step's last update, where
 * neither the method (it checks x and p) nor the next rates read it */
static sph_status nan_constrain(sph_term *term, sph_sim *sim, sph_stage *state,
                                sph_error *err) {
  (void)term, (void)err;
  if (state->t > sim->t && state->F)
    ((double *)state->F)[9 * 3 + 1] = NAN;
  return SPH_OK;
}

static const sph_term_ops nan_ops = {.name = "nan", .constrain = nan_constrain};

START_TEST(debug_state_check_fires_on_nan) {
  sph_scene *scene = sph_test_scene_text(
      "name: t\ndimension: 2\nmethod: {name: tl-csph}\n"
      "materials:\n  m: {model: neo-hookean, density: 1000, "
      "youngs_modulus: 1e6, poisson_ratio: 0.3}\n"
      "time: {end: 0.1}\nbodies:\n  - name: plate\n    material: m\n"
      "    shape: {box: {min: [0, 0], max: [1, 0.5]}}\n"
      "    particles: {count: [10, 5]}\n");
  sph_sim *sim;
  sph_error err;
  ck_assert_int_eq(sph_sim_create(&sim, scene, &err), SPH_OK);
  ck_assert_int_eq(sph_sim_step(sim, 1.0, &err), SPH_OK);
  ck_assert_int_eq(sph_sim_add_term(sim, &nan_ops, NULL, &err), SPH_OK);
  sph_status st = sph_sim_step(sim, 1.0, &err);
  if (SPH_DEBUG_CHECKS_ON) { /* the state scan after each step */
    ck_assert_int_eq(st, SPH_ERR_NUMERIC);
    ck_assert_msg(strstr(err.message, "state F[28] is nan"), "%s", err.message);
    ck_assert_msg(strstr(err.message, "src/solver/sim.c:"), "%s", err.message);
  } else {
    ck_assert_int_eq(st, SPH_OK); /* found by the next step or frame */
  }
  sph_sim_destroy(sim);
  sph_scene_destroy(scene);
}
END_TEST
#endif

int main(void) {
  Suite *s = suite_create(SPH_DEBUG_CHECKS_ON ? "check_debug" : "check");
  TCase *tc = tcase_create("core");
  tcase_add_test(tc, check_fills_internal_error);
  tcase_add_test(tc, debug_check_only_in_debug_builds);
  tcase_add_test(tc, neighbor_scan_fires_on_corrupted_lists);
  tcase_add_test(tc, neighbor_scan_fires_on_asymmetric_lists);
  tcase_add_test(tc, particle_order_check_fires_on_bad_ids);
  tcase_add_test(tc, kernel_check_fires_on_degenerate_support);
  tcase_add_test(tc, correction_cloud_check_fires);
  suite_add_tcase(s, tc);
#ifndef SPH_TEST_CORE_ONLY
  TCase *ts = tcase_create("sim");
  tcase_add_test(ts, step_checks_fire);
  tcase_add_test(ts, debug_state_check_fires_on_nan);
  suite_add_tcase(s, ts);
#endif
  SRunner *sr = srunner_create(s);
  srunner_run_all(sr, CK_NORMAL);
  int failed = srunner_ntests_failed(sr);
  srunner_free(sr);
  return failed ? 1 : 0;
}
