/* Reference solutions (include/sph/reference.h): the period measured from
 * zero crossings of a particle's displacement, its checkpoint state and its
 * input errors; the swinging cube's deformed initial state for methods that
 * carry F and for those that derive it from the positions; the swinging cube
 * for non-equal (A, B, C) against an independent evaluation of eq. 52 that
 * the test first shows to solve linear elastodynamics. */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "io/sink.h"
#include "scene/scene.h"
#include "solver/reference.h"
#include "solver/sim.h"

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
  ck_assert_msg(sph_reference_errors(sim->reference, sim, &e, &err) == SPH_OK,
                "%s", err.message);
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
  ck_assert_msg(sph_reference_errors(sim->reference, sim, &e, &err) == SPH_OK,
                "%s", err.message);
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
/* the swinging cube at spacing 0.25 with one override, derived at t = 0 */
static sph_sim *load_cube(const char *set, sph_scene **s) {
  char path[512];
  snprintf(path, sizeof path, "%s/scenes/swinging_cube.yaml", SPH_SOURCE_DIR);
  const char *sets[] = {set, "bodies.0.particles.spacing=0.25"};
  sph_sim *sim;
  sph_error err;
  ck_assert_msg(sph_scene_load(s, path, sets, 2, &err) == SPH_OK, "%s",
                err.message);
  ck_assert_msg(sph_sim_create(&sim, *s, &err) == SPH_OK, "%s", err.message);
  ck_assert(sim->method->derive(sim, &err) == SPH_OK);
  return sim;
}

static void cube_starts_deformed(const char *method) {
  char set[128];
  snprintf(set, sizeof set, "method=%s", method);
  sph_scene *s;
  sph_sim *sim = load_cube(set, &s);
  sph_reference_error e;
  sph_error err;
  ck_assert_msg(sph_reference_errors(sim->reference, sim, &e, &err) == SPH_OK,
                "%s", err.message);
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

/* refusals: ul-sph (stress starts at zero), a placed body */
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
  /* eq. 52 is written in the world frame: a placed body is refused */
  const char *placed[] = {"bodies.0.transform={rotate: {axis: x, angle: 360}}"};
  ck_assert(sph_scene_load(&s, path, placed, 1, &err) == SPH_OK);
  ck_assert(sph_sim_create(&sim, s, &err) == SPH_ERR_ARG);
  ck_assert_msg(strstr(err.message, "world frame"), "%s", err.message);
  ck_assert_str_eq(err.key, "reference");
  sph_scene_destroy(s);
}
END_TEST

/* Independent evaluation of seed 000 eq. 52 for amplitudes A (E = 17e6,
 * nu = 0.3, rho = 1100 as scenes/swinging_cube.yaml): the mean of A moves at
 * the dilatational frequency, the rest at the shear frequency; with
 * `one_frequency` everything moves at the dilatational one (the reference as
 * it was before). */
typedef struct {
  double A[3], U0, lambda, mu, rho, wd, ws;
  int one_frequency;
} cube_mode;

static cube_mode cube_mode_make(double A, double B, double C, int one) {
  cube_mode m = {.A = {A, B, C}, .U0 = 5e-4, .rho = 1100.0};
  const double E = 17e6, nu = 0.3;
  m.lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  m.mu = E / (2.0 * (1.0 + nu));
  m.wd = M_PI * sqrt(3.0) / 2.0 * sqrt((m.lambda + 2.0 * m.mu) / m.rho);
  m.ws = M_PI * sqrt(3.0) / 2.0 * sqrt(m.mu / m.rho);
  m.one_frequency = one;
  return m;
}

static double cube_u(const cube_mode *m, int i, const double X[3], double t) {
  const double h = M_PI / 2.0, mean = (m->A[0] + m->A[1] + m->A[2]) / 3.0;
  double f = 1.0;
  for (int k = 0; k < 3; ++k)
    f *= k == i ? sin(h * X[k]) : cos(h * X[k]);
  if (m->one_frequency)
    return m->U0 * m->A[i] * f * cos(m->wd * t);
  return m->U0 * f *
         (mean * cos(m->wd * t) + (m->A[i] - mean) * cos(m->ws * t));
}

/* d u_i / d X_j by central differences */
static double cube_du(const cube_mode *m, int i, int j, const double X[3],
                      double t, double d) {
  double Xp[3] = {X[0], X[1], X[2]}, Xm[3] = {X[0], X[1], X[2]};
  Xp[j] += d;
  Xm[j] -= d;
  return (cube_u(m, i, Xp, t) - cube_u(m, i, Xm, t)) / (2.0 * d);
}

/* largest |rho u'' - div sigma| over sample points and times, relative to
 * |rho u''|, by central differences of step d */
static double cube_residual(const cube_mode *m) {
  const double d = 1e-3, dt = 1e-6;
  double worst = 0.0;
  for (int s = 0; s < 5; ++s) {
    const double X[3] = {0.13 + 0.17 * s, 0.71 - 0.11 * s, 0.29 + 0.09 * s};
    const double t = 0.0011 + 0.0023 * s;
    for (int i = 0; i < 3; ++i) {
      const double acc = (cube_u(m, i, X, t + dt) - 2.0 * cube_u(m, i, X, t) +
                          cube_u(m, i, X, t - dt)) /
                         (dt * dt);
      /* div sigma_i = sum_j d/dX_j (mu (u_ij + u_ji) + lambda div u d_ij) */
      double div = 0.0;
      for (int j = 0; j < 3; ++j) {
        double Xp[3] = {X[0], X[1], X[2]}, Xm[3] = {X[0], X[1], X[2]};
        Xp[j] += d;
        Xm[j] -= d;
        double sp =
            m->mu * (cube_du(m, i, j, Xp, t, d) + cube_du(m, j, i, Xp, t, d));
        double sm =
            m->mu * (cube_du(m, i, j, Xm, t, d) + cube_du(m, j, i, Xm, t, d));
        if (i == j)
          for (int k = 0; k < 3; ++k) {
            sp += m->lambda * cube_du(m, k, k, Xp, t, d);
            sm += m->lambda * cube_du(m, k, k, Xm, t, d);
          }
        div += (sp - sm) / (2.0 * d);
      }
      worst = fmax(worst,
                   fabs(m->rho * acc - div) / (m->rho * m->U0 * m->wd * m->wd));
    }
  }
  return worst;
}

/* the reference's errors when the particles carry this mode's exact fields
 * at time t */
static sph_reference_error cube_errors_of(const cube_mode *m, double t) {
  char amp[160];
  snprintf(amp, sizeof amp,
           "reference={analytic: swinging_cube, U0: 5.0e-4, A: %.17g, "
           "B: %.17g, C: %.17g}",
           m->A[0], m->A[1], m->A[2]);
  sph_scene *s;
  sph_sim *sim = load_cube(amp, &s);
  sph_particles *ps = sim->ps;
  const double h = 1e-6;
  for (size_t a = 0; a < ps->n; ++a) {
    const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * a;
    double G[9];
    for (int i = 0; i < 3; ++i) {
      ps->field[SPH_FIELD_DISPLACEMENT][3 * a + i] = cube_u(m, i, X, t);
      ps->field[SPH_FIELD_VELOCITY][3 * a + i] =
          (cube_u(m, i, X, t + h) - cube_u(m, i, X, t - h)) / (2.0 * h);
      for (int j = 0; j < 3; ++j)
        G[3 * i + j] = cube_du(m, i, j, X, t, 1e-6);
    }
    double *P = ps->field[SPH_FIELD_PK1] + 9 * a;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        P[3 * i + j] = m->mu * (G[3 * i + j] + G[3 * j + i]) +
                       (i == j) * m->lambda * (G[0] + G[4] + G[8]);
  }
  sim->t = t;
  sph_reference_error e;
  sph_error err;
  ck_assert_msg(sph_reference_errors(sim->reference, sim, &e, &err) == SPH_OK,
                "%s", err.message);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
  return e;
}

START_TEST(cube_any_amplitudes) {
  const double amps[][3] = {{1, 1, 1}, {1, 1, -2}, {1, 0.5, -1.5}, {1, 0, 0}};
  for (size_t c = 0; c < sizeof amps / sizeof *amps; ++c) {
    cube_mode m = cube_mode_make(amps[c][0], amps[c][1], amps[c][2], 0);
    /* the test's field solves elastodynamics (central differences:
     * truncation ~ (pi d / 2)^2 ~ 1e-6, round-off ~ eps / dt^2 w^2 ~ 1e-6) */
    double r = cube_residual(&m);
    ck_assert_msg(r < 1e-4, "A = (%g %g %g): residual %g", m.A[0], m.A[1],
                  m.A[2], r);
    /* the reference agrees with it at a time when the two frequencies have
     * drifted apart (differences of step 1e-6: errors ~ 1e-9) */
    sph_reference_error e = cube_errors_of(&m, 0.0123);
    ck_assert_msg(e.l2_displacement < 1e-7 && e.l2_velocity < 1e-7 &&
                      e.l2_stress < 1e-7,
                  "A = (%g %g %g): e_u %g e_v %g e_P %g", m.A[0], m.A[1],
                  m.A[2], e.l2_displacement, e.l2_velocity, e.l2_stress);
    /* one frequency for every component solves it only for A = B = C */
    cube_mode one = cube_mode_make(amps[c][0], amps[c][1], amps[c][2], 1);
    double r1 = cube_residual(&one);
    int equal = m.A[0] == m.A[1] && m.A[1] == m.A[2];
    ck_assert_msg(equal ? r1 < 1e-4 : r1 > 0.1, "one frequency: residual %g",
                  r1);
  }
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
  tcase_add_test(tc, cube_any_amplitudes);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
