/* The contact term (src/terms/contact.c): wall geometry, a block bouncing
 * off a rigid wall with every method that takes contact, two blocks
 * colliding (momentum to round-off), a wall being exactly the mirror image
 * of the body (seed 001 sec. 2.4.2's symmetry plane), and the step bound
 * of a stiff contact spring. */
#include "test_scene_util.h"
#include "test_util.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"
#include "solver/run.h"
#include "solver/sim.h"

#define BLOCK_MATERIAL                                                         \
  "materials: {rubber: {model: neo-hookean, density: 1000, "                   \
  "youngs_modulus: 1e6, poisson_ratio: 0.3}}\n"

/* a 0.1 x 0.05 block (spacing 5 mm) at 2 m/s towards x = 0 */
#define LEFT_BLOCK                                                             \
  "  - name: left\n    material: rubber\n"                                     \
  "    shape: {box: {min: [-0.105, -0.025], max: [-0.005, 0.025]}}\n"          \
  "    particles: {spacing: 0.005}\n"                                          \
  "    initial_velocity: {uniform: [2, 0, 0]}\n"
#define RIGHT_BLOCK                                                            \
  "  - name: right\n    material: rubber\n"                                    \
  "    shape: {box: {min: [0.005, -0.025], max: [0.105, 0.025]}}\n"            \
  "    particles: {spacing: 0.005}\n"                                          \
  "    initial_velocity: {uniform: [-2, 0, 0]}\n"
#define WALL                                                                   \
  "contact: {walls: [{name: w, plane: {point: [0, 0], normal: [-1, 0]}}]}\n"

static sph_status make(const char *method, const char *bodies,
                       const char *contact, sph_scene **s, sph_sim **sim,
                       sph_error *err) {
  char text[4096];
  /* tl-bond's support as in its scenes: at 1.3 dp it trips indicators on
   * A1, B8 and A3 (docs/results.md), and here leaves the wall with 3.3
   * times the energy it came with */
  snprintf(text, sizeof text,
           "name: contact\ndimension: 2\nmethod: {name: %s}\n"
           "kernel: {type: cubic, h_over_dp: %s}\n" BLOCK_MATERIAL
           "bodies:\n%s%stime: {end: 0.012}\n"
           "output: {fields: [velocity, displacement, stress]}\n",
           method, strcmp(method, "tl-bond") ? "1.3" : "1.1", bodies, contact);
  *sim = NULL;
  *s = sph_test_scene_text(text);
  sph_status st = sph_sim_create(sim, *s, err);
  if (st != SPH_OK)
    sph_scene_destroy(*s);
  return st;
}

static double body_momentum_x(const sph_sim *sim, int body) {
  const sph_particles *ps = sim->ps;
  double p = 0.0;
  for (size_t a = 0; a < ps->n; ++a)
    if (ps->body[a] == body)
      p += ps->field[SPH_FIELD_MASS][a] * ps->field[SPH_FIELD_VELOCITY][3 * a];
  return p;
}

static double energy(sph_sim *sim) {
  double k, e;
  sim->method->energy(sim, &k, &e);
  return k + e;
}

START_TEST(wall_distance) {
  sph_wall plane = {.kind = SPH_WALL_PLANE,
                    .point = {1, 0, 0},
                    .normal = {-1, 0, 0},
                    .velocity = {-2, 0, 0}};
  double n[3], x[3] = {0.5, 3, 0};
  ck_assert_double_eq_tol(sph_wall_distance(&plane, 0.0, 2, x, n), 0.5, 1e-15);
  ck_assert_double_eq(n[0], -1.0);
  /* moved by v t = 0.5: touching */
  ck_assert_double_eq_tol(sph_wall_distance(&plane, 0.25, 2, x, n), 0.0, 1e-15);
  sph_wall box = {.kind = SPH_WALL_BOX, .min = {0, 0, 0}, .max = {1, 2, 3}};
  double corner[3] = {-3, -4, 1}, inside[3] = {0.9, 1, 1.5};
  ck_assert_double_eq_tol(sph_wall_distance(&box, 0.0, 2, corner, n), 5.0,
                          1e-15);
  ck_assert_double_eq_tol(n[0], -0.6, 1e-15);
  ck_assert_double_eq_tol(n[1], -0.8, 1e-15);
  /* inside: the nearest face, x = 1, 0.1 away */
  ck_assert_double_eq_tol(sph_wall_distance(&box, 0.0, 3, inside, n), -0.1,
                          1e-15);
  ck_assert_double_eq(n[0], 1.0);
}
END_TEST

/* every method that takes contact bounces the block off the wall: the
 * momentum turns round, no particle passes the wall, no energy is made */
START_TEST(block_bounces_off_wall) {
  int tried = 0;
  for (const sph_method_ops *const *m = sph_method_list(); *m; ++m) {
    sph_scene *s;
    sph_sim *sim;
    sph_error err;
    sph_status st = make((*m)->name, LEFT_BLOCK, WALL, &s, &sim, &err);
    if (!strcmp((*m)->name, "ul-sph")) { /* refuses, naming the block */
      ck_assert_int_eq(st, SPH_ERR_ARG);
      ck_assert_ptr_nonnull(strstr(err.message, "contact"));
      continue;
    }
    ck_assert_msg(st == SPH_OK, "%s: %s", (*m)->name, err.message);
    ++tried;
    ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
    double p0 = body_momentum_x(sim, 0), e0 = energy(sim), gmin = INFINITY;
    while (sim->t < s->t_end * (1 - 1e-12)) {
      ck_assert_msg(sph_sim_advance(sim, s->t_end, 1, &err) == SPH_OK, "%s: %s",
                    (*m)->name, err.message);
      const double *x = sim->ps->field[SPH_FIELD_POSITION];
      double n[3];
      for (size_t a = 0; a < sim->ps->n; ++a)
        gmin = fmin(gmin, sph_wall_distance(&s->contact.walls[0], sim->t, 2,
                                            x + 3 * a, n));
    }
    ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
    double p1 = body_momentum_x(sim, 0), e1 = energy(sim);
    printf("%-8s momentum %.4g -> %.4g, energy %.5g -> %.5g, closest to "
           "the wall %.3g dp\n",
           (*m)->name, p0, p1, e0, e1, gmin / 0.005);
    /* rebounded at most as fast as it came (measured 0.70-0.80 of it) */
    ck_assert_msg(p1 < -0.5 * p0 && p1 > -p0, "%s: %g -> %g", (*m)->name, p0,
                  p1);
    /* the spring stops the centres short of the wall (measured >= 0.3 dp
     * at 5 m/s, c = 37 m/s) */
    ck_assert_double_gt(gmin, 0.0);
    /* no energy created: leap-frog methods keep it to 1 %, the JST ones
     * dissipate */
    ck_assert_msg(e1 <= 1.01 * e0, "%s: energy %g -> %g", (*m)->name, e0, e1);
    sph_sim_destroy(sim);
    sph_scene_destroy(s);
  }
  ck_assert_int_ge(tried, 4);
}
END_TEST

/* two blocks meet: the pair forces are equal and opposite (momentum to
 * round-off) and the blocks part */
START_TEST(bodies_collide) {
  for (const sph_method_ops *const *m = sph_method_list(); *m; ++m) {
    if (!strcmp((*m)->name, "ul-sph"))
      continue;
    sph_scene *s;
    sph_sim *sim;
    sph_error err;
    ck_assert_int_eq(make((*m)->name, LEFT_BLOCK RIGHT_BLOCK,
                          "contact: {between_bodies: true}\n", &s, &sim, &err),
                     SPH_OK);
    ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
    double l0 = body_momentum_x(sim, 0), r0 = body_momentum_x(sim, 1);
    ck_assert_int_eq(sph_sim_advance(sim, s->t_end, ULONG_MAX, &err), SPH_OK);
    ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
    double l1 = body_momentum_x(sim, 0), r1 = body_momentum_x(sim, 1);
    printf("%-8s left %.4g -> %.4g, right %.4g -> %.4g, total %.3g\n",
           (*m)->name, l0, l1, r0, r1, l1 + r1);
    ck_assert_double_lt(l1, 0.0);
    ck_assert_double_gt(r1, 0.0);
    ck_assert_double_le(fabs(l1 + r1), 1e-12 * fabs(l0));
    sph_sim_destroy(sim);
    sph_scene_destroy(s);
  }
}
END_TEST

/* a wall is the mirror image of the body: with aligned lattices only mirror
 * twins come closer than dp, and the pair force at distance 2 g is the
 * wall's at distance g, so the two runs agree to round-off */
START_TEST(wall_is_the_mirror_image) {
  sph_scene *s1, *s2;
  sph_sim *one, *two;
  sph_error err;
  ck_assert_int_eq(make("tl-csph", LEFT_BLOCK, WALL, &s1, &one, &err), SPH_OK);
  ck_assert_int_eq(make("tl-csph", LEFT_BLOCK RIGHT_BLOCK,
                        "contact: {between_bodies: true}\n", &s2, &two, &err),
                   SPH_OK);
  double worst = 0.0;
  while (one->t < s1->t_end * (1 - 1e-12)) {
    ck_assert_int_eq(sph_sim_advance(one, s1->t_end, 1, &err), SPH_OK);
    ck_assert_int_eq(sph_sim_advance(two, s1->t_end, 1, &err), SPH_OK);
    ck_assert_double_eq_tol(one->t, two->t, 1e-12 * one->t);
    const double *x1 = one->ps->field[SPH_FIELD_POSITION];
    const double *x2 = two->ps->field[SPH_FIELD_POSITION];
    for (size_t a = 0; a < 3 * one->ps->n; ++a)
      worst = fmax(worst, fabs(x1[a] - x2[a]));
  }
  printf("wall against mirror body: largest position difference %.3g m\n",
         worst);
  ck_assert_double_le(worst, 1e-12);
  sph_sim_destroy(one);
  sph_sim_destroy(two);
  sph_scene_destroy(s1);
  sph_scene_destroy(s2);
}
END_TEST

/* a stiff spring bounds the step below the method's CFL step */
START_TEST(stiff_contact_bounds_step) {
  sph_scene *s;
  sph_sim *sim;
  sph_error err;
  ck_assert_int_eq(
      make("tl-csph", LEFT_BLOCK,
           "contact: {stiffness: 100, walls: [{name: w, plane: {point: [0, "
           "0], normal: [-1, 0]}}]}\n",
           &s, &sim, &err),
      SPH_OK);
  double c = sqrt(1e6 * 0.7 / (1.3 * 0.4) / 1000.0); /* p-wave speed */
  double bound = 0.005 / (2.0 * sqrt(100.0) * c);
  ck_assert_double_le(sph_sim_stable_dt(sim), bound * (1 + 1e-12));
  ck_assert_double_lt(bound, sim->method->stable_dt(sim));
  ck_assert_int_eq(sph_sim_advance(sim, s->t_end, ULONG_MAX, &err), SPH_OK);
  ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
  ck_assert_double_lt(body_momentum_x(sim, 0), 0.0);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
}
END_TEST

int main(void) {
  Suite *s = suite_create("contact");
  TCase *tc = tcase_create("contact");
  tcase_set_timeout(tc, 600);
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, wall_distance);
  tcase_add_test(tc, block_bounces_off_wall);
  tcase_add_test(tc, bodies_collide);
  tcase_add_test(tc, wall_is_the_mirror_image);
  tcase_add_test(tc, stiff_contact_bounds_step);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
