/* Orientation invariance of the scene placement (body transform, oblique
 * normals, oblique mirror planes): the shipped spinning cube (B2, seed 000
 * sec. 8.3) and cable (B3, seed 000 sec. 8.1) run as they are and turned
 * by 37 degrees about [1, 2, 3] give the same energy, |linear momentum|,
 * |angular momentum| and wave arrival histories, as does the 2D tensile
 * plate (B11, ul-sph) turned by 30 degrees; a half cube with a
 * symmetry or skew-symmetry mirror plane (docs/benchmarks.md D.1) gives half
 * the energy of the full cube, with the plane along x and with the same plane
 * turned oblique.
 *
 * Tolerance: a rotation changes the order of the floating-point sums (cell
 * lists, neighbour order, R X instead of X), so the runs agree to round-off,
 * not bit for bit: about 1e-16 relative per operation, growing at most
 * linearly over the ~10^3 steps of a run, i.e. ~1e-13; the checks allow
 * 1e-10. Anything placed wrongly (a velocity not turned, a normal left
 * along its axis, a time step that depends on the orientation) differs by
 * 1e-6 or more. */
#include "test_scene_util.h"
#include "test_util.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"
#include "scene/scene.h"
#include "solver/run.h"
#include "solver/sim.h"

#define ROUNDOFF 1e-10
#define TURN "{rotate: {axis: [1, 2, 3], angle: 37}}"
#define NMAX 128

typedef struct history {
  int n;
  double t[NMAX], kinetic[NMAX], total[NMAX], lin[NMAX], ang[NMAX];
  double tip[NMAX]; /* velocity of particle `tip` along `dir` */
  double mass;
} history;

/* Runs the scene to n samples `every` apart, recording the invariants. */
static void record(sph_scene *s, int n, double every, size_t tip,
                   const double dir[3], history *h) {
  sph_sim *sim;
  sph_error err;
  ck_assert_msg(sph_sim_create(&sim, s, &err) == SPH_OK, "%s", err.message);
  ck_assert_int_le(n, NMAX);
  h->n = n;
  h->mass = 0.0;
  for (size_t a = 0; a < sim->ps->n; ++a)
    h->mass += sim->ps->field[SPH_FIELD_MASS][a];
  for (int k = 0; k < n; ++k) {
    double next = every * k;
    ck_assert_msg(sph_sim_advance(sim, next, ULONG_MAX, &err) == SPH_OK, "%s",
                  err.message);
    ck_assert(sim->method->derive(sim, &err) == SPH_OK);
    double kin, strain, l[3], a[3];
    sim->method->energy(sim, &kin, &strain);
    sph_momentum(sim->ps, l, a);
    h->t[k] = sim->t;
    h->kinetic[k] = kin;
    h->total[k] = kin + strain;
    h->lin[k] = sph_vec3_norm(l);
    h->ang[k] = sph_vec3_norm(a);
    const double *v = sim->ps->field[SPH_FIELD_VELOCITY] + 3 * tip;
    h->tip[k] = dir ? sph_vec3_dot(v, dir) : 0.0;
  }
  sph_sim_destroy(sim);
}

static sph_scene *load_file(const char *name, const char *const *sets,
                            size_t n) {
  char path[512];
  snprintf(path, sizeof path, "%s/scenes/%s.yaml", SPH_SOURCE_DIR, name);
  sph_scene *s;
  sph_error err;
  ck_assert_msg(sph_scene_load(&s, path, sets, n, &err) == SPH_OK, "%s",
                err.message);
  return s;
}

/* Largest differences of the histories: energies over the initial total,
 * momenta over the momentum scale P = sqrt(2 M K0) (times `size` for the
 * angular one); `scale` multiplies b's energies (2 for a half body). */
typedef struct diff {
  double energy, lin, ang;
} diff;

static diff compare(const history *a, const history *b, double scale,
                    double size) {
  diff d = {0, 0, 0};
  double P = sqrt(2.0 * a->mass * a->kinetic[0]);
  for (int k = 0; k < a->n; ++k) {
    d.energy =
        fmax(d.energy, fabs(a->total[k] - scale * b->total[k]) / a->total[0]);
    d.energy = fmax(d.energy,
                    fabs(a->kinetic[k] - scale * b->kinetic[k]) / a->total[0]);
    d.lin = fmax(d.lin, fabs(a->lin[k] - b->lin[k]) / P);
    d.ang = fmax(d.ang, fabs(a->ang[k] - b->ang[k]) / (P * size));
  }
  return d;
}

/* Runs the shipped scene `name` with sets[0..plain) and with all `turned`
 * sets, n samples `every` apart (a velocity along x of particle `tip`,
 * resp. along the turned x), and checks that energy, |p| and |L| (over
 * P `size`) agree to round-off. */
static void turned_pair(const char *name, const char *const *sets, size_t plain,
                        size_t turned, int n, double every, double size,
                        size_t tip, history *a, history *b) {
  sph_scene *s0 = load_file(name, sets, plain);
  sph_scene *s1 = load_file(name, sets, turned);
  ck_assert(s1->bodies[0].transform.given);
  const double *R = s1->bodies[0].transform.R;
  const double ex[3] = {1, 0, 0}, along[3] = {R[0], R[3], R[6]};
  record(s0, n, every, tip, ex, a);
  record(s1, n, every, tip, along, b);
  diff d = compare(a, b, 1.0, size);
  printf("%s turned, to %g s: energy %.3g, |p| %.3g, |L| %.3g (relative)\n",
         name, every * (n - 1), d.energy, d.lin, d.ang);
  ck_assert_msg(d.energy <= ROUNDOFF, "energy differs by %g", d.energy);
  ck_assert_msg(d.lin <= ROUNDOFF, "|p| differs by %g", d.lin);
  ck_assert_msg(d.ang <= ROUNDOFF, "|L| differs by %g", d.ang);
  sph_scene_destroy(s0);
  sph_scene_destroy(s1);
}

START_TEST(spinning_cube_turned) {
  /* turned about [1, 2, 3] and moved: |L| about the origin is unchanged
   * because the total momentum is zero */
  const char *sets[] = {"bodies.0.transform={rotate: {axis: [1, 2, 3], "
                        "angle: 37}, translate: [0.3, -0.2, 0.5]}"};
  static history a, b;
  turned_pair("spinning_cube", sets, 0, 1, 51, 0.002, 1.0, 0, &a, &b);
}
END_TEST

static double crossing(const history *h, double level, double after) {
  for (int i = 1; i < h->n; ++i)
    if (h->t[i] > after && h->tip[i - 1] > level && h->tip[i] <= level)
      return h->t[i - 1] + (h->t[i] - h->t[i - 1]) * (h->tip[i - 1] - level) /
                               (h->tip[i - 1] - h->tip[i]);
  return NAN;
}

START_TEST(cable_turned) {
  /* the boundaries' planes and roller normals in the rod's frame */
  const char *sets[] = {"output.probes=[]",
                        "time.end=0.004",
                        "boundaries.0.select.plane.body=rod",
                        "boundaries.1.select.plane.body=rod",
                        "boundaries.2.select.plane.body=rod",
                        "boundaries.3.select.plane.body=rod",
                        "boundaries.4.select.plane.body=rod",
                        "bodies.0.transform=" TURN};
  /* the tip particle (10, 0.1, 0.1): same index in both runs */
  sph_scene *s0 = load_file("cable", sets, 2);
  sph_particles *ps;
  sph_error err;
  ck_assert(sph_scene_build_particles(s0, &ps, &err) == SPH_OK);
  size_t tip = ps->n;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  for (size_t a = 0; a < ps->n; ++a)
    if (X[3 * a] == 10.0 && X[3 * a + 1] == 0.1 && X[3 * a + 2] == 0.1)
      tip = a;
  ck_assert(tip < ps->n);
  sph_particles_destroy(ps);
  sph_scene_destroy(s0);
  static history a, b;
  turned_pair("cable", sets, 2, 8, 81, 0.00005, 10.0, tip, &a, &b);
  double t0[2] = {crossing(&a, 2.5, 0.0), crossing(&b, 2.5, 0.0)};
  double t1[2] = {crossing(&a, -2.5, 0.001), crossing(&b, -2.5, 0.001)};
  printf("cable arrivals at the tip %.6g s and %.6g s, turned %+.3g and "
         "%+.3g (relative)\n",
         t0[0], t1[0], t0[1] / t0[0] - 1.0, t1[1] / t1[0] - 1.0);
  /* the fronts reach the tip (d'Alembert: 0.0005 s and 0.0035 s) */
  ck_assert(fabs(t0[0] - 0.0005) < 0.02 * 0.0005);
  ck_assert(fabs(t1[0] - 0.0035) < 0.02 * 0.0035);
  ck_assert_msg(fabs(t0[1] - t0[0]) <= ROUNDOFF * t0[0],
                "arrival %.17g vs %.17g", t0[1], t0[0]);
  ck_assert_msg(fabs(t1[1] - t1[0]) <= ROUNDOFF * t1[0],
                "arrival %.17g vs %.17g", t1[1], t1[0]);
}
END_TEST

START_TEST(plate_2d_turned) {
  /* ul-sph in 2D: the B11 tensile plate turned by 30 degrees about z */
  const char *sets[] = {"time.end=0.002",
                        "boundaries.0.select.plane.body=plate",
                        "bodies.0.transform={rotate: {angle: 30}}"};
  static history a, b;
  turned_pair("tensile_plate_2d", sets, 2, 3, 21, 0.0001, 1.0, 0, &a, &b);
}
END_TEST

/* A cube [-0.5, 0.5]^3, or its half x >= 0 with a mirror plane at x = 0 (in
 * the body frame), optionally turned; the velocity field is symmetric
 * (skew = 0) or skew-symmetric (skew = 1) about that plane. Skew images
 * carry the displacement -R u, a symmetry of the equations only when P is
 * odd in F - I: the skew case is linear-elastic (with neo-Hookean the half
 * body departs by 1e-2 in 0.02 s, as it does with a plane along x). */
static sph_scene *mirror_scene(int half, int skew, const char *transform) {
  static const char *const field[2] = {
      "\"40*x*(1+y)\", \"20*z + 10*x*x\", \"-10*y\"",
      "\"20 + 10*y\", \"15*x\", \"10*x*y\""};
  char text[2048];
  snprintf(text, sizeof text,
           "name: mirror\ndimension: 3\n"
           "method: {name: tl-jst, angular_momentum_projection: false, "
           "jst_projection: false}\n"
           "materials: {rubber: {model: %s, density: 1100, "
           "youngs_modulus: 17e6, poisson_ratio: 0.3}}\n"
           "bodies:\n  - name: cube\n    material: rubber\n"
           "    shape: {box: {min: [%s, -0.5, -0.5], max: [0.5, 0.5, 0.5]}}\n"
           "    particles: {spacing: 0.125}\n"
           "    initial_velocity: {expression: [%s]}\n"
           "%s%s%s"
           "%s"
           "time: {end: 0.02}\n",
           skew ? "linear-elastic" : "neo-hookean", half ? "0" : "-0.5",
           field[skew], transform ? "    transform: " : "",
           transform ? transform : "", transform ? "\n" : "",
           !half ? ""
           : skew
               ? "boundaries:\n  - {name: m, select: {plane: {axis: x, at: 0, "
                 "body: cube}}, skew_symmetry: {axis: x}}\n"
               : "boundaries:\n  - {name: m, select: {plane: {axis: x, at: 0, "
                 "body: cube}}, symmetry: {axis: x}}\n");
  return sph_test_scene_text(text);
}

static diff half_vs_full(int skew, const char *transform) {
  static history a, b;
  sph_scene *full = mirror_scene(0, skew, transform);
  sph_scene *half = mirror_scene(1, skew, transform);
  if (transform)
    ck_assert_int_lt(half->boundaries[0].select.axis, 0); /* oblique */
  else
    ck_assert_int_eq(half->boundaries[0].select.axis, 0);
  record(full, 21, 0.001, 0, NULL, &a);
  record(half, 21, 0.001, 0, NULL, &b);
  sph_scene_destroy(full);
  sph_scene_destroy(half);
  return compare(&a, &b, 2.0, 1.0);
}

START_TEST(half_body_with_mirror_plane) {
  for (int skew = 0; skew < 2; ++skew) {
    diff axis = half_vs_full(skew, NULL);
    diff turned = half_vs_full(
        skew, "{rotate: {axis: [1, 2, 3], angle: 37}, translate: [0.2, 0, 1]}");
    printf("%s plane, energy of the full cube vs twice the half: %.3g along "
           "x, %.3g oblique (relative)\n",
           skew ? "skew-symmetry" : "symmetry", axis.energy, turned.energy);
    ck_assert_msg(axis.energy <= ROUNDOFF, "along x: %g", axis.energy);
    ck_assert_msg(turned.energy <= ROUNDOFF, "oblique: %g", turned.energy);
  }
}
END_TEST

int main(void) {
  Suite *s = suite_create("orientation");
  TCase *tc = tcase_create("orientation");
  tcase_set_timeout(tc, 300);
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, spinning_cube_turned);
  tcase_add_test(tc, cable_turned);
  tcase_add_test(tc, plate_2d_turned);
  tcase_add_test(tc, half_body_with_mirror_plane);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
