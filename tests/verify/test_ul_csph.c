/* ul-csph (seed 001 sec. 3-4): the linear patch test after several
 * reference updates (eq. 12-14; the Hessian difference of eq. 17-21
 * vanishes on linear fields), the internal force as the exact gradient of
 * the discrete strain energy with the stabilised gradient (eq. 21 and its
 * adjoint), and the 1D bar and punch of sec. 3.3.1 and 4.3. */
#include "test_scene_util.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"
#include "scene/scene.h"
#include "solver/sim.h"

static sph_sim *make_sim(const char *method, int count, sph_scene **scene) {
  char text[2048];
  snprintf(text, sizeof text,
           "name: ulcsph\ndimension: 3\nmethod: {name: ul-csph, %s}\n"
           "materials: {rubber: {model: neo-hookean, density: 1100, "
           "youngs_modulus: 17e6, poisson_ratio: 0.3}}\n"
           "bodies:\n  - name: cube\n    material: rubber\n"
           "    shape: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
           "    particles: {count: [%d, %d, %d]}\n"
           "time: {end: 1}\n"
           "output: {fields: [acceleration]}\n",
           method, count, count, count);
  *scene = sph_test_scene_text(text);
  sph_sim *sim = NULL;
  sph_error err;
  sph_status st = sph_sim_create(&sim, *scene, &err);
  ck_assert_msg(st == SPH_OK, "%s", err.message);
  return sim;
}

static double *state_x(sph_sim *sim) {
  sph_state_array a[SPH_MAX_STATE];
  int n = sim->method->state(sim, a);
  for (int i = 0; i < n; ++i)
    if (!strcmp(a[i].name, "x"))
      return a[i].data;
  ck_abort_msg("no state x");
  return NULL;
}

/* x = A X + c for every particle */
static void set_affine(sph_sim *sim, const double A[9], const double c[3]) {
  const sph_particles *ps = sim->ps;
  double *x = state_x(sim);
  for (size_t a = 0; a < ps->n; ++a) {
    sph_mat3_vec(A, ps->field[SPH_FIELD_POSITION0] + 3 * a, x + 3 * a);
    for (int k = 0; k < 3; ++k)
      x[3 * a + k] += c[k];
  }
}

/* a step too short to move anything: with update_every 1 it makes the
 * current positions the reference */
static void update_here(sph_sim *sim) {
  sph_error err;
  ck_assert_int_eq(sim->method->step(sim, 1e-300, &err), SPH_OK);
}

START_TEST(patch_test_after_updates) {
  static const char *const opts[] = {"update_every: 1, eta: 0",
                                     "update_every: 1, eta: 0.3",
                                     "update_every: 1, eta: 1.5"};
  /* stretch, shear, rotation: the reference moves through each */
  static const double A[4][9] = {{1.2, 0, 0, 0, 0.9, 0, 0, 0, 1.05},
                                 {1.2, 0.3, 0, 0, 0.9, 0.1, 0, 0, 1.05},
                                 {0.8, 0.3, -0.2, 0.1, 1.3, 0.1, 0, -0.2, 0.95},
                                 {0, -1.1, 0.2, 1.25, 0.1, 0, 0.1, 0, 0.9}};
  double c[3] = {0.3, -0.1, 2.0};
  for (size_t o = 0; o < sizeof opts / sizeof *opts; ++o) {
    sph_scene *s;
    sph_sim *sim = make_sim(opts[o], 6, &s);
    update_here(sim); /* the first step never updates */
    for (int u = 0; u < 3; ++u) {
      set_affine(sim, A[u], c);
      update_here(sim);
    }
    set_affine(sim, A[3], c);
    sph_error err;
    ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
    const sph_particles *ps = sim->ps;
    double worst = 0.0;
    for (size_t a = 0; a < ps->n; ++a)
      for (int k = 0; k < 9; ++k)
        worst = fmax(worst,
                     fabs(ps->field[SPH_FIELD_DEFGRAD][9 * a + k] - A[3][k]));
    /* four references, each reproducing a linear map to round-off */
    ck_assert_msg(worst < 1e-12, "%s: F off the affine map by %g", opts[o],
                  worst);
    sph_sim_destroy(sim);
    sph_scene_destroy(s);
  }
}
END_TEST

static double strain_energy(sph_sim *sim) {
  sph_error err;
  double ek, es;
  ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
  sim->method->energy(sim, &ek, &es);
  return es;
}

/* the force is minus the gradient of sum_a V0_a W(F_a) with F from the
 * (stabilised) gradient: checked by central differences in a jittered,
 * updated reference */
START_TEST(force_is_energy_gradient) {
  static const char *const opts[] = {"update_every: 1, eta: 0",
                                     "update_every: 1, eta: 0.3",
                                     "update_every: 1, eta: 1.5"};
  for (size_t o = 0; o < sizeof opts / sizeof *opts; ++o) {
    sph_scene *s;
    sph_sim *sim = make_sim(opts[o], 5, &s);
    const sph_particles *ps = sim->ps;
    double *x = state_x(sim);
    unsigned seed = 11;
    update_here(sim);
    for (int pass = 0; pass < 2; ++pass) {
      double A[9] = {1.1, 0.1, 0, 0, 0.95, 0.05, 0.02, 0, 1.0}, c[3] = {0};
      set_affine(sim, A, c);
      for (size_t i = 0; i < 3 * ps->n; ++i) {
        seed = seed * 1103515245u + 12345u;
        x[i] += 0.03 * (((seed >> 8) % 1000) / 1000.0 - 0.5) * 0.25;
      }
      if (pass == 0)
        update_here(sim); /* a jittered reference */
    }
    sph_error err;
    ck_assert_int_eq(sim->method->restore(sim, &err), SPH_OK);
    ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
    double rho0 = s->materials[0].density, fmax_ = 0.0, worst = 0.0;
    size_t n3 = 3 * ps->n;
    double *force = malloc(n3 * sizeof *force);
    for (size_t i = 0; i < n3; ++i) {
      force[i] = ps->field[SPH_FIELD_ACCELERATION][i] * rho0 *
                 ps->field[SPH_FIELD_VOLUME0][i / 3];
      fmax_ = fmax(fmax_, fabs(force[i]));
    }
    for (size_t i = 0; i < n3; i += 7) {
      double eps = 1e-6 * 0.25, keep = x[i];
      x[i] = keep + eps;
      double ep = strain_energy(sim);
      x[i] = keep - eps;
      double em = strain_energy(sim);
      x[i] = keep;
      worst = fmax(worst, fabs(-(ep - em) / (2 * eps) - force[i]));
    }
    ck_assert_msg(fmax_ > 0.0, "no force");
    ck_assert_msg(worst < 1e-6 * fmax_,
                  "%s: force differs from -dE/dx by %g of %g", opts[o], worst,
                  fmax_);
    free(force);
    sph_sim_destroy(sim);
    sph_scene_destroy(s);
  }
}
END_TEST

/* update_distance: a reference update whenever a particle has moved that
 * many spacings from x^r; on a rigid translation at 100 m/s that is every
 * ceil(0.5 dp / (v dt)) steps, and F stays I */
START_TEST(displacement_criterion) {
  sph_scene *s;
  sph_sim *sim = make_sim("update_distance: 0.5", 5, &s);
  const sph_particles *ps = sim->ps;
  sph_state_array arr[SPH_MAX_STATE];
  int na = sim->method->state(sim, arr);
  double *p = NULL;
  for (int i = 0; i < na; ++i)
    if (!strcmp(arr[i].name, "p"))
      p = arr[i].data;
  ck_assert_ptr_nonnull(p);
  for (size_t a = 0; a < ps->n; ++a)
    p[3 * a] = 100.0 * s->materials[0].density;
  sph_error err;
  double dt = sim->method->stable_dt(sim);
  int steps = 30;
  for (int i = 0; i < steps; ++i)
    ck_assert_int_eq(sim->method->step(sim, dt, &err), SPH_OK);
  unsigned long updates = 0;
  for (int i = 0; i < sim->ntimers; ++i)
    if (!strcmp(sim->timers[i].name, "reference_update"))
      updates = sim->timers[i].calls;
  int every = (int)ceil(0.5 * sim->dp / (100.0 * dt) + 1e-12);
  /* the first update comes once the criterion holds, then one each `every`
   * steps */
  fprintf(stderr, "%lu updates in %d steps, every %d\n", updates, steps, every);
  ck_assert_msg(updates > 1 &&
                    labs((long)updates - (long)((steps - 1) / every)) <= 1,
                "%lu updates in %d steps of %d each", updates, steps, every);
  ck_assert_int_eq(sim->method->derive(sim, &err), SPH_OK);
  for (size_t a = 0; a < ps->n; ++a)
    for (int k = 0; k < 9; ++k)
      ck_assert_double_eq_tol(ps->field[SPH_FIELD_DEFGRAD][9 * a + k],
                              k % 4 == 0, 1e-12);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
}
END_TEST

int main(void) {
  Suite *s = suite_create("ul_csph");
  TCase *tc = tcase_create("ul_csph");
  tcase_set_timeout(tc, 600);
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, patch_test_after_updates);
  tcase_add_test(tc, force_is_energy_gradient);
  tcase_add_test(tc, displacement_criterion);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
