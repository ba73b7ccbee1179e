/* Reference solutions (include/sph/reference.h): the period measured from
 * zero crossings of a particle's displacement, its checkpoint state and its
 * input errors; the swinging cube's deformed initial state for methods that
 * carry F and for those that derive it from the positions. */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "sph/reference.h"
#include "sph/scene.h"
#include "sph/sim.h"
#include "sph/sink.h"

/* a 2D box and the given reference line */
static sph_status load_plate(const char *reference, sph_scene **s,
                             sph_sim **sim, sph_error *err) {
  char text[2048], path[64] = "/tmp/sph_reference_XXXXXX";
  snprintf(text, sizeof text,
           "name: plate\ndimension: 2\nmethod: {name: ul-sph}\n"
           "materials: {m: {model: neo-hookean, density: 1000, "
           "youngs_modulus: 2e6, poisson_ratio: 0.3975}}\n"
           "bodies:\n  - {name: p, material: m, shape: {box: {min: [0, 0], "
           "max: [0.2, 0.02]}}, particles: {spacing: 0.004}}\n"
           "time: {end: 1}\n%s\n",
           reference);
  int fd = mkstemp(path);
  ck_assert_int_ge(fd, 0);
  ck_assert_int_eq(write(fd, text, strlen(text)), (ssize_t)strlen(text));
  close(fd);
  *sim = NULL;
  sph_status st = sph_scene_load(s, path, NULL, 0, err);
  unlink(path);
  if (st == SPH_OK && (st = sph_sim_create(sim, *s, err)) != SPH_OK)
    sph_scene_destroy(*s);
  return st;
}

/* moves every particle by u in y and shows the frame to the reference */
static void show(sph_sim *sim, double t, double u) {
  sph_particles *ps = sim->ps;
  for (size_t a = 0; a < ps->n; ++a)
    ps->field[SPH_FIELD_POSITION][3 * a + 1] =
        ps->field[SPH_FIELD_POSITION0][3 * a + 1] + u;
  sph_frame fr = {.time = t, .sim = sim, .ps = ps};
  sph_reference_observe(sim->reference, &fr);
}

START_TEST(period_from_zero_crossings) {
  /* u = A sin(2 pi t / T + phase) sampled 25 times a period over 3.3
   * periods: the crossings are interpolated to O((w dt)^3) */
  sph_scene *s;
  sph_sim *sim;
  sph_error err;
  ck_assert_msg(load_plate("reference: {period: {at: [0.2, 0.01], "
                           "component: y}, value: 0.25, tolerance: 0.02}",
                           &s, &sim, &err) == SPH_OK,
                "%s", err.message);
  const double T = 0.26, dt = T / 25;
  for (int k = 0; k * dt <= 3.3 * T; ++k)
    show(sim, k * dt, 1e-3 * sin(2 * M_PI * k * dt / T + 0.3));
  sph_reference_error e;
  sph_reference_errors(sim->reference, sim, &e);
  ck_assert_msg(fabs(e.period - T) < 1e-4 * T, "period %.9g", e.period);
  ck_assert(fabs(e.period_error - fabs(e.period - 0.25) / 0.25) < 1e-15);
  ck_assert(e.period_value == 0.25 && e.period_tolerance == 0.02);
  ck_assert(isnan(e.l2_velocity) && isnan(e.l2_stress));
  /* the measurement is state a checkpoint carries */
  sph_state_array arr;
  ck_assert_int_eq(sph_reference_state(sim->reference, &arr), 1);
  ck_assert_str_eq(arr.name, "reference");
  ck_assert(arr.len > 0 && arr.data);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
}
END_TEST

START_TEST(period_needs_two_crossings) {
  sph_scene *s;
  sph_sim *sim;
  sph_error err;
  ck_assert(load_plate("reference: {period: {at: [0.2, 0.01]}, value: 0.25}",
                       &s, &sim, &err) == SPH_OK);
  for (int k = 0; k < 10; ++k) /* one crossing only */
    show(sim, 0.01 * k, k < 5 ? 1e-3 : -1e-3);
  sph_reference_error e;
  sph_reference_errors(sim->reference, sim, &e);
  ck_assert(isnan(e.period) && isnan(e.period_error));
  ck_assert(isnan(e.period_tolerance));
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
}
END_TEST

START_TEST(period_input_errors) {
  static const struct {
    const char *yaml, *says;
  } bad[] = {
      {"reference: {period: {at: [0.2]}, value: 0.25}", "2 numbers"},
      {"reference: {period: {at: [0.2, 0], component: z}, value: 0.25}",
       "component z"},
      {"reference: {period: {at: [0.2, 0]}, value: -1}", "positive"},
      {"reference: {period: {at: [0.2, 0]}}", "value"},
      {"reference: {period: {at: [0.2, 0]}, value: 1, every: 2}", "every"},
      {"reference: {period: {at: [0.2, 0], axis: y}, value: 1}", "axis"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; ++i) {
    sph_scene *s;
    sph_sim *sim;
    sph_error err;
    ck_assert(load_plate(bad[i].yaml, &s, &sim, &err) != SPH_OK);
    ck_assert_msg(strstr(err.message, bad[i].says), "%s: %s", bad[i].yaml,
                  err.message);
    ck_assert_int_gt(err.line, 0);
  }
}
END_TEST

/* the swinging cube at t = 0 with `method`: x = X + u0 and F = I + grad u0
 * whether the method carries F or derives it */
static void cube_starts_deformed(const char *method) {
  char path[512], set[128];
  snprintf(path, sizeof path, "%s/scenes/swinging_cube.yaml", SPH_SOURCE_DIR);
  snprintf(set, sizeof set, "method=%s", method);
  const char *sets[] = {set, "bodies.0.particles.spacing=0.25"};
  sph_scene *s;
  sph_sim *sim;
  sph_error err;
  ck_assert_msg(sph_scene_load(&s, path, sets, 2, &err) == SPH_OK, "%s",
                err.message);
  ck_assert_msg(sph_sim_create(&sim, s, &err) == SPH_OK, "%s", err.message);
  ck_assert(sim->method->derive(sim, &err) == SPH_OK);
  sph_reference_error e;
  sph_reference_errors(sim->reference, sim, &e);
  /* u = U0 f(X) to the round-off of x - X (eps |X| / U0 ~ 4e-13), v = 0;
   * P is the method's own estimate */
  ck_assert_msg(e.l2_displacement < 1e-12 && e.l2_velocity == 0.0,
                "%s: e_u %g e_v %g", method, e.l2_displacement, e.l2_velocity);
  ck_assert_msg(e.l2_stress < 0.2, "%s: e_P %g", method, e.l2_stress);
  const double *F = sim->ps->field[SPH_FIELD_DEFGRAD];
  double dev = 0.0;
  for (size_t a = 0; a < sim->ps->n; ++a)
    for (int k = 0; k < 9; ++k)
      dev = fmax(dev, fabs(F[9 * a + k] - (k % 4 == 0)));
  ck_assert_msg(dev > 1e-4, "%s: F = I (largest |F - I| %g)", method, dev);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
}

START_TEST(cube_initial_state) {
  cube_starts_deformed("{name: tl-jst, angular_momentum_projection: false, "
                       "jst_projection: false}");
  cube_starts_deformed("{name: tl-csph}");
}
END_TEST

START_TEST(cube_refused_by_ul_sph) {
  char path[512];
  snprintf(path, sizeof path, "%s/scenes/swinging_cube.yaml", SPH_SOURCE_DIR);
  const char *sets[] = {"method={name: ul-sph}", "boundaries=[]"};
  sph_scene *s;
  sph_sim *sim;
  sph_error err;
  ck_assert(sph_scene_load(&s, path, sets, 2, &err) == SPH_OK);
  ck_assert(sph_sim_create(&sim, s, &err) != SPH_OK);
  ck_assert_msg(strstr(err.message, "deformed state"), "%s", err.message);
  sph_scene_destroy(s);
}
END_TEST

int main(void) {
  Suite *s = suite_create("reference");
  TCase *tc = tcase_create("reference");
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, period_from_zero_crossings);
  tcase_add_test(tc, period_needs_two_crossings);
  tcase_add_test(tc, period_input_errors);
  tcase_add_test(tc, cube_initial_state);
  tcase_add_test(tc, cube_refused_by_ul_sph);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
