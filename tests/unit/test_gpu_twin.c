/* The device algorithm without a device (docs/gpu.md): the host twin of the
 * GPU step (src/gpu/tl_jst_twin.c), which calls the per-particle functions
 * the CUDA kernels call, against the CPU's tl-jst pF on a jittered twisting
 * column with its base clamped, step by step, every field. The twin does
 * each particle's products and sums in the CPU method's order (the scalar
 * form of its register sums, no contraction into fused multiply-adds in
 * C11), so the tolerance is zero: equal to the bit. The device itself
 * (pow may differ from glibc's by an ulp) is held to 1e-12 relative by
 * tests/gpu/test_gpu_step.c on a machine with a GPU. */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gpu/gpu.h"
#include "scene/scene.h"
#include "solver/sim.h"
#include "test_column.h"
#include "test_scene_util.h"

/* a jittered 3 x 11 x 3 column, twisted, its base clamped */
static sph_scene *column(const char *method) {
  char text[2048];
  sph_test_column_text(text, sizeof text, method, 3, 3.0);
  return sph_test_scene_text(text);
}

/* the CPU's state array `name` */
static const sph_state_array *cpu_array(sph_state_array *arr, int count,
                                        const char *name) {
  for (int i = 0; i < count; ++i)
    if (strcmp(arr[i].name, name) == 0)
      return &arr[i];
  ck_abort_msg("no state array %s", name);
  return NULL;
}

static void twin_equals_cpu(const char *method, int steps) {
  sph_scene *s = column(method);
  sph_sim *sim;
  sph_error err;
  ck_assert_msg(sph_sim_create(&sim, s, &err) == SPH_OK, "%s", err.message);
  sph_gpu_tl_jst g;
  int stages;
  ck_assert_msg(sph_gpu_tl_jst_host_create(sim, &g, &stages, &err) == SPH_OK,
                "%s", err.message);
  double dt = 0.5 * sph_sim_stable_dt(sim);
  sph_state_array arr[8];
  int count = sim->method->state(sim, arr);
  const double *twin[3] = {g.x, g.p, g.F};
  const char *names[3] = {"x", "p", "F"};
  for (int k = 0; k < steps; ++k) {
    ck_assert_msg(sph_sim_step(sim, dt, &err) == SPH_OK, "%s", err.message);
    sph_gpu_tl_jst_twin_step(&g, stages, dt);
    for (int f = 0; f < 3; ++f) {
      const sph_state_array *c = cpu_array(arr, count, names[f]);
      ck_assert_msg(memcmp(twin[f], c->data, c->len * sizeof(double)) == 0,
                    "%s, step %d: %s differs from the CPU's by %.3g relative",
                    method, k + 1, names[f],
                    sph_test_rel_diff(twin[f], c->data, c->len));
    }
  }
  sph_gpu_tl_jst_host_destroy(&g);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
}

START_TEST(twin_tvd_rk2) {
  twin_equals_cpu("{name: tl-jst, fields: pF, jst: {eps4_p: 0}, "
                  "angular_momentum_projection: false, jst_projection: false}",
                  20);
}
END_TEST

START_TEST(twin_ssp_rk3) {
  twin_equals_cpu("{name: tl-jst, fields: pF, integrator: ssp-rk3, "
                  "jst: {eps4_p: 0}, angular_momentum_projection: false, "
                  "jst_projection: false}",
                  20);
}
END_TEST

/* with the JST term on p (eq. 35-38): fourth order, and second and fourth */
START_TEST(twin_jst) {
  twin_equals_cpu("{name: tl-jst, fields: pF, jst: {eps4_p: 0.125}, "
                  "angular_momentum_projection: false, jst_projection: false}",
                  20);
  twin_equals_cpu("{name: tl-jst, fields: pF, integrator: ssp-rk3, "
                  "jst: {eps2_p: 0.1, eps4_p: 0.125}, "
                  "angular_momentum_projection: false, jst_projection: false}",
                  20);
}
END_TEST

/* the shipped twisting column's method: JST with its projection (eq. 49)
 * and the angular momentum projection (eq. 45-48), in TVD-RK2 about X^chi
 * and in SSP-RK3 about the stage's x */
START_TEST(twin_projections) {
  twin_equals_cpu("{name: tl-jst, jst: {eps4_p: 0}}", 10);
  twin_equals_cpu("{name: tl-jst, angular_momentum_projection: false}", 10);
  twin_equals_cpu("{name: tl-jst}", 20);
  twin_equals_cpu("{name: tl-jst, integrator: ssp-rk3}", 20);
}
END_TEST

/* what the device step lacks is refused, naming the part */
START_TEST(twin_refuses_missing_parts) {
  static const char *const methods[] = {
      "{name: tl-jst, essential_bc: lagrange}",
      "{name: tl-jst, fields: pFJ, jst: {eps4_p: 0}, "
      "angular_momentum_projection: false, jst_projection: false}",
      "{name: tl-jst, force: symmetric, jst: {eps4_p: 0}, "
      "angular_momentum_projection: false, jst_projection: false}",
      "{name: ul-sph}"};
  static const char *const named[] = {"lagrange_projection", "pFJ",
                                      "conservative", "method"};
  for (int i = 0; i < 4; ++i) {
    sph_scene *s = column(methods[i]);
    sph_sim *sim;
    sph_error err;
    ck_assert_msg(sph_sim_create(&sim, s, &err) == SPH_OK, "%s", err.message);
    sph_gpu_tl_jst g;
    int stages;
    ck_assert_int_eq(sph_gpu_tl_jst_host_create(sim, &g, &stages, &err),
                     SPH_ERR_UNSUPPORTED);
    ck_assert_msg(strstr(err.message, named[i]), "%s", err.message);
    sph_sim_destroy(sim);
    sph_scene_destroy(s);
  }
}
END_TEST

int main(void) {
  sph_test_enable_fp_traps();
  Suite *s = suite_create("gpu_twin");
  TCase *tc = tcase_create("twin");
  tcase_add_test(tc, twin_tvd_rk2);
  tcase_add_test(tc, twin_ssp_rk3);
  tcase_add_test(tc, twin_jst);
  tcase_add_test(tc, twin_projections);
  tcase_add_test(tc, twin_refuses_missing_parts);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
