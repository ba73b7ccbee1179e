/* tl-bond (seed 004): the bond-corrected F reproduces a homogeneous
 * deformation (eq. 37-39 with eq. 5a), the symmetrised force conserves
 * linear momentum to round-off (eq. 22), SSP-RK3 is third order in dt
 * (eq. 30), the B6 swinging plate converges in L2 and H1 (sec. 5.1), and
 * every option is validated. */
#include "test_util.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/tensor.h"
#include "scene/scene.h"
#include "solver/reference.h"
#include "solver/run.h"
#include "solver/sim.h"

static void run_to_end(sph_sim *sim) {
  sph_error err;
  ck_assert_msg(sph_sim_advance(sim, sim->scene->t_end, ULONG_MAX, &err) ==
                    SPH_OK,
                "%s", err.message);
  ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
}

static sph_sim *load(const char *scene, const char *const *sets, size_t n,
                     sph_scene **s) {
  char path[512];
  snprintf(path, sizeof path, "%s/scenes/%s.yaml", SPH_SOURCE_DIR, scene);
  sph_error err;
  sph_sim *sim;
  ck_assert_msg(sph_scene_load(s, path, sets, n, &err) == SPH_OK, "%s",
                err.message);
  ck_assert_msg(sph_sim_create(&sim, *s, &err) == SPH_OK, "%s", err.message);
  return sim;
}

/* x = A X, F = A for every particle of a free 3D block: F^c = A to
 * round-off at every particle, surface and corners included, so the
 * stress output (from F^c) is the stress of A; also for the zeroth-order
 * kernel */
static void homogeneous(const char *correction) {
  const char *sets[] = {"method={name: tl-bond, correction: PLACEHOLDER}",
                        "bodies.0.particles.count=[5,25,5]",
                        "bodies.0.initial_velocity={expression: [0, 0, 0]}",
                        "boundaries=[]", "output.fields=[stress]"};
  char m[128];
  snprintf(m, sizeof m, "method={name: tl-bond, correction: %s}", correction);
  sets[0] = m;
  sph_scene *s;
  sph_sim *sim = load("twisting_column", sets, 5, &s);
  const double A[9] = {1.2, 0.1, -0.05, 0.03, 0.9, 0.2, -0.1, 0.07, 1.1};
  double *x = sim->ps->field[SPH_FIELD_POSITION];
  const double *X = sim->ps->field[SPH_FIELD_POSITION0];
  double *F = sim->ps->field[SPH_FIELD_DEFGRAD];
  for (size_t a = 0; a < sim->ps->n; ++a) {
    sph_mat3_vec(A, X + 3 * a, x + 3 * a);
    memcpy(F + 9 * a, A, sizeof A);
  }
  sph_error err;
  ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
  /* Cauchy stress of A, from the material itself */
  double H[9], P[9], At[9], S[9];
  sph_mat3_cofactor(A, H);
  double J = sph_mat3_det(A);
  sph_material_stress(&s->materials[0], A, H, J, P);
  sph_mat3_transpose(A, At);
  sph_mat3_mul(P, At, S);
  double smax = 0.0, dev = 0.0;
  for (int k = 0; k < 9; ++k)
    smax = fmax(smax, fabs(S[k] / J));
  for (size_t a = 0; a < sim->ps->n; ++a)
    for (int k = 0; k < 9; ++k)
      dev = fmax(dev,
                 fabs(sim->ps->field[SPH_FIELD_STRESS][9 * a + k] - S[k] / J));
  printf("homogeneous F, %s: largest stress deviation %.3g of %.3g\n",
         correction, dev, smax);
  ck_assert_msg(dev < 1e-11 * smax, "%s: %g of %g", correction, dev, smax);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
}

START_TEST(bond_gradient_reproduces_homogeneous_deformation) {
  homogeneous("first_order");
  homogeneous("zeroth_order");
}
END_TEST

/* a free block spinning and stretching: total linear momentum (zero) stays
 * zero to round-off with the symmetrised force and JST (eq. 22, 28) */
START_TEST(linear_momentum_to_round_off) {
  const char *sets[] = {
      "method={name: tl-bond}", "bodies.0.particles.count=[5,25,5]",
      "boundaries=[]", "time.end=0.02",
      "bodies.0.initial_velocity={expression: [\"20*y\", \"5*x\", \"-3*y\"]}"};
  sph_scene *s;
  sph_sim *sim = load("twisting_column", sets, 5, &s);
  sph_error err;
  ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
  double l0[3], a0[3], l1[3], a1[3];
  sph_momentum(sim->ps, l0, a0);
  run_to_end(sim);
  sph_momentum(sim->ps, l1, a1);
  /* scale: the largest momentum of one particle times the particle count */
  double mass = 0.0;
  for (size_t a = 0; a < sim->ps->n; ++a)
    mass += sim->ps->field[SPH_FIELD_MASS][a];
  double scale = mass * 20 * 6, d = 0.0;
  for (int c = 0; c < 3; ++c)
    d = fmax(d, fabs(l1[c] - l0[c]));
  printf("linear momentum change %.3g (scale %.3g) in %lu steps\n", d, scale,
         sim->steps);
  ck_assert_msg(d < 1e-13 * scale, "%g", d);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
}
END_TEST

/* the B6 plate, linear elastic (the exact solution's material), at CFL c:
 * positions at the end time */
static double *plate_positions(double cfl, const char *integrator, size_t *n) {
  char c[96], integ[96];
  snprintf(c, sizeof c, "method.cfl=%.17g", cfl);
  snprintf(integ, sizeof integ, "method.integrator=%s", integrator);
  const char *sets[] = {c,
                        integ,
                        "materials.rubber.model=linear-elastic",
                        "method.wave_speed=linear",
                        "time.end=0.01",
                        "output.every=0.01"};
  sph_scene *s;
  sph_sim *sim = load("swinging_plate_2d", sets, 6, &s);
  run_to_end(sim);
  *n = sim->ps->n;
  double *x = malloc(3 * *n * sizeof *x);
  memcpy(x, sim->ps->field[SPH_FIELD_POSITION], 3 * *n * sizeof *x);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
  return x;
}

static double max_diff(const double *a, const double *b, size_t n) {
  double d = 0.0;
  for (size_t i = 0; i < 3 * n; ++i)
    d = fmax(d, fabs(a[i] - b[i]));
  return d;
}

/* eq. 30: halving dt divides the error by 8 (against a run at 1/8 of the
 * smallest dt); TVD-RK2 by 4 */
static void time_order(const char *integrator, double expect) {
  const double cfl[3] = {0.8, 0.4, 0.2};
  size_t n;
  double *ref = plate_positions(0.025, integrator, &n), e[3];
  for (int i = 0; i < 3; ++i) {
    size_t m;
    double *x = plate_positions(cfl[i], integrator, &m);
    e[i] = max_diff(x, ref, n);
    free(x);
  }
  for (int i = 0; i < 2; ++i) {
    double order = log(e[i] / e[i + 1]) / log(2.0);
    printf("%s: CFL %.2g -> %.2g: error %.3g -> %.3g, order %.2f\n", integrator,
           cfl[i], cfl[i + 1], e[i], e[i + 1], order);
    ck_assert_msg(fabs(order - expect) < 0.3, "%s order %g", integrator, order);
  }
  free(ref);
}

START_TEST(ssp_rk3_is_third_order) {
  time_order("ssp-rk3", 3.0);
  time_order("tvd-rk2", 2.0);
}
END_TEST

/* B6 (seed 004 Fig. 9): displacement L2 and H1-seminorm errors at d = 0.2,
 * 0.1, 0.05 on the linear elastic plate (the exact solution's material) */
START_TEST(swinging_plate_converges) {
  const double d[3] = {0.2, 0.1, 0.05};
  double e2[3], e1[3];
  for (int i = 0; i < 3; ++i) {
    char sp[96];
    snprintf(sp, sizeof sp, "bodies.0.particles.spacing=%.17g", d[i]);
    const char *sets[] = {sp, "materials.rubber.model=linear-elastic"};
    sph_scene *s;
    sph_sim *sim = load("swinging_plate_2d", sets, 2, &s);
    run_to_end(sim);
    sph_reference_error e;
    sph_error err;
    ck_assert_msg(sph_reference_errors(sim->reference, sim, &e, &err) == SPH_OK,
                  "%s", err.message);
    e2[i] = e.l2_displacement;
    e1[i] = e.h1_displacement;
    printf("B6 d = %.3g: L2 %.4g H1 %.4g\n", d[i], e2[i], e1[i]);
    sph_sim_destroy(sim);
    sph_scene_destroy(s);
  }
  for (int i = 0; i < 2; ++i) {
    double o2 = log(e2[i] / e2[i + 1]) / log(2.0);
    double o1 = log(e1[i] / e1[i + 1]) / log(2.0);
    printf("B6 order d %.3g -> %.3g: L2 %.2f, H1 %.2f\n", d[i], d[i + 1], o2,
           o1);
    ck_assert_msg(o2 >= 1.8, "L2 order %g", o2);
    ck_assert_msg(o1 >= 0.8, "H1 order %g", o1);
  }
}
END_TEST

/* every option names its key; the CFL is refused above the SSP limit */
START_TEST(option_errors) {
  const char *bad[][2] = {
      {"method={name: tl-bond, cfl: 1.2}", "cfl"},
      {"method={name: tl-bond, deformation_gradient: nodal}",
       "deformation_gradient"},
      {"method={name: tl-bond, correction: second_order}", "correction"},
      {"method={name: tl-bond, integrator: euler}", "integrator"},
      {"method={name: tl-bond, wave_speed: current}", "wave_speed"},
      {"method={name: tl-bond, force: eq31}", "force"},
      {"method={name: tl-bond, jst: {eps4_p: -1}}", "eps4_p"},
      {"method={name: tl-bond, jst: {eps4_J: 1}}", "eps4_J"},
      {"method={name: tl-bond, jst: {outer: eq28}}", "outer"},
      {"method={name: tl-bond, fields: pFJ}", "fields"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof *bad; ++i) {
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/twisting_column.yaml",
             SPH_SOURCE_DIR);
    sph_scene *s;
    sph_sim *sim = NULL;
    sph_error err;
    const char *sets[] = {bad[i][0]};
    sph_status st = sph_scene_load(&s, path, sets, 1, &err);
    ck_assert_int_eq(st, SPH_OK);
    st = sph_sim_create(&sim, s, &err);
    ck_assert_msg(st != SPH_OK, "%s accepted", bad[i][0]);
    ck_assert_msg(strstr(err.message, bad[i][1]) || strstr(err.key, bad[i][1]),
                  "%s: %s (%s)", bad[i][0], err.message, err.key);
    sph_scene_destroy(s);
  }
}
END_TEST

int main(void) {
  Suite *s = suite_create("tl_bond");
  TCase *tc = tcase_create("tl_bond");
  tcase_set_timeout(tc, 600);
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, bond_gradient_reproduces_homogeneous_deformation);
  tcase_add_test(tc, linear_momentum_to_round_off);
  tcase_add_test(tc, ssp_rk3_is_third_order);
  tcase_add_test(tc, swinging_plate_converges);
  tcase_add_test(tc, option_errors);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
