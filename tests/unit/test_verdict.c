/* The verdict's fracture, zig-zag and energy indicators on frames built by
 * hand:
 * scenes loaded from YAML, their particles generated, positions and von
 * Mises stress filled in directly (no method runs), observed through the
 * same sph_verdict_observe the sph command uses. */
#include "test_scene_util.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene/scene.h"
#include "solver/sim.h"
#include "solver/stability.h"

/* one rubber box [0, lx] x [0, ly] (x [0, lz]) with spacing dp, plus `extra`
 * YAML lines (more bodies, a stability block) */
static sph_scene *load_box(int dim, double lx, double ly, double lz, double dp,
                           const char *particles, const char *extra) {
  char text[4096];
  char lo[64], hi[64];
  if (dim == 3) {
    snprintf(lo, sizeof lo, "[0, 0, 0]");
    snprintf(hi, sizeof hi, "[%g, %g, %g]", lx, ly, lz);
  } else {
    snprintf(lo, sizeof lo, "[0, 0]");
    snprintf(hi, sizeof hi, "[%g, %g]", lx, ly);
  }
  snprintf(text, sizeof text,
           "name: verdict\ndimension: %d\nmethod: {name: tl-jst}\n"
           "materials: {rubber: {model: neo-hookean, density: 1100, "
           "youngs_modulus: 17e6, poisson_ratio: 0.45}}\n"
           "bodies:\n  - name: box\n    material: rubber\n"
           "    shape: {box: {min: %s, max: %s}}\n"
           "    particles: {spacing: %g%s}\n%s"
           "time: {end: 1}\n",
           dim, lo, hi, dp, particles, extra);
  return sph_test_scene_text(text);
}

/* particles of the scene with POSITION = POSITION0 and a zero von Mises */
typedef struct fixture {
  sph_scene *s;
  sph_particles *ps;
  sph_sim sim; /* only scene and particles: what the verdict reads */
  sph_verdict *v;
} fixture;

static void fixture_make(fixture *f, sph_scene *s) {
  sph_error err;
  memset(f, 0, sizeof *f);
  f->s = s;
  ck_assert_msg(sph_scene_build_particles(s, &f->ps, &err) == SPH_OK, "%s",
                err.message);
  ck_assert(sph_particles_require(f->ps, SPH_FIELD_POSITION, &err) == SPH_OK);
  ck_assert(sph_particles_require(f->ps, SPH_FIELD_VON_MISES, &err) == SPH_OK);
  memcpy(f->ps->field[SPH_FIELD_POSITION], f->ps->field[SPH_FIELD_POSITION0],
         3 * f->ps->n * sizeof(double));
  /* the masses a method would set: rho0 V0 of the rubber */
  ck_assert(sph_particles_require(f->ps, SPH_FIELD_MASS, &err) == SPH_OK);
  for (size_t a = 0; a < f->ps->n; ++a)
    f->ps->field[SPH_FIELD_MASS][a] =
        1100.0 * f->ps->field[SPH_FIELD_VOLUME0][a];
  f->sim.scene = s;
  f->sim.ps = f->ps;
  ck_assert_msg(sph_verdict_create(&f->v, &f->sim, &err) == SPH_OK, "%s",
                err.message);
}

static void fixture_free(fixture *f) {
  sph_verdict_destroy(f->v);
  sph_particles_destroy(f->ps);
  sph_scene_destroy(f->s);
}

/* a frame with the given energies */
static void observe_energy(fixture *f, double t, double kinetic,
                           double strain) {
  sph_error err;
  sph_frame fr = {.time = t,
                  .sim = &f->sim,
                  .ps = f->ps,
                  .kinetic = kinetic,
                  .strain = strain};
  ck_assert_msg(sph_verdict_observe(f->v, &fr, &err) == SPH_OK, "%s",
                err.message);
}

static void observe(fixture *f, double t) { observe_energy(f, t, 0.0, 0.0); }

/* x <- X + (lambda - 1) X_c along the listed axes */
static void stretch(fixture *f, const double lambda[3]) {
  const double *X = f->ps->field[SPH_FIELD_POSITION0];
  double *x = f->ps->field[SPH_FIELD_POSITION];
  for (size_t i = 0; i < 3 * f->ps->n; ++i)
    x[i] = lambda[i % 3] * X[i];
}

/* ---- numerical fracture
 * ------------------------------------------------------ */

/* 10 x 5 x 5 cell-centred particles, dp = 0.1: within 1.5 dp a particle
 * has its 6 axial (1 dp) and 12 diagonal (sqrt 2 dp) neighbours; the
 * sqrt 3 dp corners are not adjacent */
static sph_scene *box3(const char *extra) {
  return load_box(3, 1.0, 0.5, 0.5, 0.1, "", extra);
}

START_TEST(adjacent_pairs_of_a_lattice) {
  fixture f;
  fixture_make(&f, box3(""));
  ck_assert_uint_eq(f.ps->n, 250);
  /* axial: 9*5*5 + 10*4*5 + 10*5*4; diagonal: 2 per face-diagonal square,
   * 2*(9*4*5 + 9*5*4 + 10*4*4) */
  size_t axial = 225 + 200 + 200, diagonal = 2 * (180 + 180 + 160);
  ck_assert_uint_eq(f.v->npairs, axial + diagonal);
  ck_assert(f.s->stability.fracture_dp == SPH_FRACTURE_DP);
  ck_assert(f.s->stability.zigzag_max == SPH_ZIGZAG_MAX);
  /* defaults are in the resolved tree (scene_used.yaml) */
  sph_node *st = sph_node_child(f.s->root, "stability");
  ck_assert_ptr_nonnull(st);
  ck_assert_ptr_nonnull(sph_node_child(st, "fracture_dp"));
  fixture_free(&f);
}
END_TEST

START_TEST(unmoved_does_not_trip) {
  fixture f;
  fixture_make(&f, box3(""));
  observe(&f, 0.0);
  ck_assert_msg(f.v->stable, "%s", f.v->reason);
  ck_assert(fabs(f.v->fracture_max_stretch - sqrt(2.0)) < 1e-12);
  ck_assert_int_eq(f.v->fracture_pairs_over, 0);
  ck_assert(isnan(f.v->zigzag)); /* von Mises zero everywhere */
  fixture_free(&f);
}
END_TEST

START_TEST(uniaxial_stretch_does_not_trip) {
  /* a tensile-test stretch of 1.5 along x: axial pairs 1.5 dp, the
   * diagonals in the xy and xz planes sqrt(1.5^2 + 1) = 1.80 dp < 2 */
  fixture f;
  fixture_make(&f, box3(""));
  stretch(&f, (double[3]){1.5, 1.0, 1.0});
  observe(&f, 0.1);
  ck_assert_msg(f.v->stable, "%s", f.v->reason);
  ck_assert(fabs(f.v->fracture_max_stretch - sqrt(3.25)) < 1e-12);
  fixture_free(&f);
}
END_TEST

START_TEST(isotropic_stretch_trips_unless_raised) {
  /* 1.5 in every direction takes the sqrt 2 dp diagonals to 2.12 dp: a
   * smooth deformation the default calls fracture, which is why the
   * threshold is a scene setting */
  fixture f;
  fixture_make(&f, box3(""));
  stretch(&f, (double[3]){1.5, 1.5, 1.5});
  observe(&f, 0.1);
  ck_assert(!f.v->stable);
  ck_assert_int_eq(f.v->fracture_pairs_over, 2 * (180 + 180 + 160));
  ck_assert_msg(strstr(f.v->reason, "numerical fracture"), "%s", f.v->reason);
  fixture_free(&f);
  fixture_make(&f, box3("stability: {fracture_dp: 2.2}\n"));
  stretch(&f, (double[3]){1.5, 1.5, 1.5});
  observe(&f, 0.1);
  ck_assert_msg(f.v->stable, "%s", f.v->reason);
  ck_assert(fabs(f.v->fracture_max_stretch - 1.5 * sqrt(2.0)) < 1e-12);
  fixture_free(&f);
  /* 0 turns the indicator off; the stretch is still measured */
  fixture_make(&f, box3("stability: {fracture_dp: 0}\n"));
  stretch(&f, (double[3]){3.0, 3.0, 3.0});
  observe(&f, 0.1);
  ck_assert_msg(f.v->stable, "%s", f.v->reason);
  ck_assert(fabs(f.v->fracture_peak_stretch - 3.0 * sqrt(2.0)) < 1e-12);
  ck_assert_int_eq(f.v->fracture_peak_over, 0);
  fixture_free(&f);
}
END_TEST

START_TEST(crack_trips_with_its_pair_count) {
  /* the half x > 0.5 moved 3 dp along x: every pair across the plane
   * x = 0.5 opens, axial ones to 4 dp, diagonal ones to sqrt(17) dp;
   * across it run 5*5 axial, 2*4*5 xy-diagonal and 2*5*4 xz-diagonal pairs */
  fixture f;
  fixture_make(&f, box3(""));
  observe(&f, 0.0);
  double *x = f.ps->field[SPH_FIELD_POSITION];
  for (size_t a = 0; a < f.ps->n; ++a)
    if (x[3 * a] > 0.5)
      x[3 * a] += 0.3;
  observe(&f, 0.25);
  ck_assert(!f.v->stable);
  ck_assert(f.v->t_tripped == 0.25);
  ck_assert_int_eq(f.v->fracture_pairs_over, 25 + 40 + 40);
  ck_assert(fabs(f.v->fracture_max_stretch - sqrt(17.0)) < 1e-9);
  ck_assert_msg(strstr(f.v->reason, "numerical fracture: 105 initially "
                                    "adjacent pairs more than 2 dp apart "
                                    "(largest 4.12 dp)"),
                "%s", f.v->reason);
  fixture_free(&f);
}
END_TEST

START_TEST(bodies_parting_is_not_fracture) {
  /* a second box touching the first (particles dp apart across the
   * interface) moves 5 dp away: pairs of different bodies are not listed */
  fixture f;
  fixture_make(&f,
               box3("  - name: other\n    material: rubber\n"
                    "    shape: {box: {min: [1, 0, 0], max: [1.5, 0.5, 0.5]}}\n"
                    "    particles: {spacing: 0.1}\n"));
  ck_assert_uint_eq(f.ps->n, 375);
  double *x = f.ps->field[SPH_FIELD_POSITION];
  for (size_t a = 0; a < f.ps->n; ++a)
    if (f.ps->body[a] == 1)
      x[3 * a] += 0.5;
  observe(&f, 0.1);
  ck_assert_msg(f.v->stable, "%s", f.v->reason);
  ck_assert(fabs(f.v->fracture_max_stretch - sqrt(2.0)) < 1e-12);
  fixture_free(&f);
}
END_TEST

/* ---- energy growth
 * ----------------------------------------------------------- */

START_TEST(energy_growth_above_round_off) {
  /* the rubber's p-wave speed: c0^2 = E (1 - nu) / ((1 + nu)(1 - 2 nu)) /
   * rho */
  double c2 = 17e6 * 0.55 / (1.45 * 0.1) / 1100.0, mc2 = 0.0;
  fixture f;
  fixture_make(&f, box3(""));
  const double *m = f.ps->field[SPH_FIELD_MASS];
  for (size_t a = 0; a < f.ps->n; ++a)
    mc2 += m[a] * c2;
  ck_assert(fabs(f.v->energy_floor - SPH_ENERGY_FLOOR * mc2) <
            1e-12 * f.v->energy_floor);
  /* a body at rest with round-off energies (1e-30 m c0^2) growing tenfold
   * is not judged */
  observe_energy(&f, 0.0, 1e-30 * mc2, 0.0);
  observe_energy(&f, 0.1, 5e-30 * mc2, 5e-30 * mc2);
  ck_assert_msg(f.v->stable, "%s", f.v->reason);
  fixture_free(&f);
  /* a physical state (strain about 1e-3) growing 6 % trips, at its time */
  fixture_make(&f, box3(""));
  observe_energy(&f, 0.0, 0.0, 1e-6 * mc2);
  observe_energy(&f, 0.1, 0.5e-6 * mc2, 0.54e-6 * mc2);
  ck_assert_msg(f.v->stable, "4 %% growth tripped: %s", f.v->reason);
  observe_energy(&f, 0.2, 0.5e-6 * mc2, 0.56e-6 * mc2);
  ck_assert(!f.v->stable);
  ck_assert_int_eq(f.v->first, SPH_INDICATOR_ENERGY_GROWTH);
  ck_assert(f.v->tripped_at[SPH_INDICATOR_ENERGY_GROWTH] == 0.2);
  ck_assert(f.v->t_tripped == 0.2);
  for (int i = 0; i < SPH_INDICATOR_COUNT; ++i)
    ck_assert(i == SPH_INDICATOR_ENERGY_GROWTH || isnan(f.v->tripped_at[i]));
  fixture_free(&f);
}
END_TEST

START_TEST(indicator_keys) {
  ck_assert_str_eq(sph_indicator_key(SPH_INDICATOR_NAN), "nan");
  ck_assert_str_eq(sph_indicator_key(SPH_INDICATOR_ZIGZAG), "zigzag");
  ck_assert_str_eq(sph_indicator_key(SPH_INDICATOR_STEP), "step");
  ck_assert_str_eq(sph_indicator_key(SPH_INDICATOR_NONE), "none");
  ck_assert_str_eq(sph_indicator_key(SPH_INDICATOR_COUNT), "none");
}
END_TEST

/* ---- zig-zag
 * ----------------------------------------------------------------- */

/* s = smooth(X) + amp * range(smooth) * parity on a jittered lattice;
 * returns R (also observed through the verdict) */
static double roughness(fixture *f, int quadratic, double amp) {
  const sph_particles *ps = f->ps;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  double *s = ps->field[SPH_FIELD_VON_MISES];
  signed char *parity = malloc(ps->n);
  sph_lattice_parity(f->s, ps, parity);
  double lo = INFINITY, hi = -INFINITY;
  for (size_t a = 0; a < ps->n; ++a) {
    const double *p = X + 3 * a;
    /* a stress of about 1 MPa varying over the body */
    s[a] = quadratic ? 1e6 * (1.0 + p[0] * p[0] + 2.0 * p[1] * p[1] -
                              p[0] * p[1] + 0.5 * p[2])
                     : 1e6 * (1.0 + p[0] + 0.5 * p[1] - 0.3 * p[2]);
    lo = fmin(lo, s[a]);
    hi = fmax(hi, s[a]);
  }
  for (size_t a = 0; a < ps->n; ++a) {
    ck_assert(parity[a] != 0);
    s[a] += amp * (hi - lo) * parity[a];
  }
  free(parity);
  observe(f, 0.1);
  return f->v->zigzag;
}

static sph_scene *jittered(int dim) {
  const char *p = ", distribution: jitter, jitter: 0.25, seed: 7";
  /* 12 and 20 particles across: interiors of 6^3 and 14^2 particles */
  return dim == 3 ? load_box(3, 1.0, 1.0, 1.0, 1.0 / 12.0, p, "")
                  : load_box(2, 1.0, 1.0, 0.0, 0.05, p, "");
}

START_TEST(smooth_fields_are_not_zigzag) {
  for (int dim = 2; dim <= 3; ++dim)
    for (int q = 0; q < 2; ++q) {
      fixture f;
      fixture_make(&f, jittered(dim));
      double R = roughness(&f, q, 0.0);
      printf("zig-zag R, %dD jittered lattice (%zu particles), %s field: "
             "%.3f\n",
             dim, f.ps->n, q ? "quadratic" : "linear", R);
      ck_assert_msg(R < 0.5 * SPH_ZIGZAG_MAX, "%dD %s: R = %g", dim,
                    q ? "quadratic" : "linear", R);
      /* the local linear fit reproduces a linear field, at the boundary
       * too */
      ck_assert_msg(q || R < 1e-9, "%dD linear: R = %g", dim, R);
      ck_assert_msg(f.v->stable, "%s", f.v->reason);
      fixture_free(&f);
    }
}
END_TEST

START_TEST(alternation_is_zigzag) {
  for (int dim = 2; dim <= 3; ++dim)
    for (int q = 0; q < 2; ++q) {
      fixture f;
      fixture_make(&f, jittered(dim));
      double R = roughness(&f, q, 0.2);
      printf("zig-zag R, %dD jittered lattice, %s field + 20 %% "
             "alternation: %.3f\n",
             dim, q ? "quadratic" : "linear", R);
      ck_assert_msg(R > 1.25 * SPH_ZIGZAG_MAX, "%dD %s: R = %g", dim,
                    q ? "quadratic" : "linear", R);
      ck_assert(!f.v->stable);
      ck_assert_int_eq(f.v->first, SPH_INDICATOR_ZIGZAG);
      ck_assert(f.v->tripped_at[SPH_INDICATOR_ZIGZAG] == 0.1);
      ck_assert_msg(strstr(f.v->reason, "zig-zag pattern"), "%s", f.v->reason);
      ck_assert(f.v->zigzag_max == R);
      fixture_free(&f);
    }
}
END_TEST

START_TEST(zigzag_is_scale_free_and_can_be_off) {
  /* R of s and of a s + b agree; a uniform field has none; zigzag_max: 0
   * measures without judging */
  fixture f;
  fixture_make(&f, jittered(2));
  double R1 = roughness(&f, 1, 0.1);
  double *s = f.ps->field[SPH_FIELD_VON_MISES];
  for (size_t a = 0; a < f.ps->n; ++a)
    s[a] = 3.0 * s[a] + 5e6;
  observe(&f, 0.2);
  ck_assert(fabs(f.v->zigzag - R1) < 1e-9 * R1);
  for (size_t a = 0; a < f.ps->n; ++a)
    s[a] = 2e6;
  observe(&f, 0.3);
  ck_assert(isnan(f.v->zigzag));
  ck_assert(f.v->zigzag_max == R1); /* NaN frames leave the maximum */
  fixture_free(&f);
  fixture_make(&f, load_box(2, 1.0, 1.0, 0.0, 0.05,
                            ", distribution: jitter, jitter: 0.25, seed: 7",
                            "stability: {zigzag_max: 0}\n"));
  double R = roughness(&f, 1, 0.5);
  ck_assert(R > SPH_ZIGZAG_MAX);
  ck_assert_msg(f.v->stable, "%s", f.v->reason);
  fixture_free(&f);
}
END_TEST

/* Bodies whose interior is smaller than one support (a 3D support holds
 * 74 lattice particles, a 2D one 21) are not judged, whatever their field:
 * 6 and 8 particles across in 3D (no interior, 2^3), 5 across a long 2D
 * strip (no interior); 9 across in 3D (3^3 = 27 interior) neither, 12
 * across (6^3 = 216) is. The limit: a genuine zig-zag in so coarse a body
 * goes unseen by this indicator (the pressure checkerboard still sees a
 * red-black mode). */
START_TEST(coarse_bodies_are_not_judged) {
  const char *p = ", distribution: jitter, jitter: 0.25, seed: 7";
  const struct {
    int dim, across;
    double lx, ly;
    int judged;
  } cases[] = {{3, 6, 1, 1, 0},  {3, 8, 1, 1, 0},   {3, 9, 1, 1, 0},
               {3, 12, 1, 1, 1}, {2, 5, 0.5, 4, 0}, {2, 10, 1, 4, 1}};
  for (size_t i = 0; i < sizeof cases / sizeof *cases; ++i) {
    double dp = cases[i].lx / cases[i].across;
    fixture f;
    fixture_make(&f, load_box(cases[i].dim, cases[i].lx, cases[i].ly,
                              cases[i].dim == 3 ? 1.0 : 0.0, dp, p, ""));
    double R = roughness(&f, 1, 0.5); /* a strong alternation */
    printf("zig-zag, %dD, %d across: %zu of %zu particles judged, R %.3f\n",
           cases[i].dim, cases[i].across, f.v->zigzag_count, f.ps->n, R);
    if (cases[i].judged) {
      ck_assert_uint_eq(f.v->zigzag_count, f.ps->n);
      ck_assert(R > SPH_ZIGZAG_MAX && !f.v->stable);
    } else {
      ck_assert_uint_eq(f.v->zigzag_count, 0);
      ck_assert(isnan(R) && isnan(f.v->zigzag_max));
      ck_assert_msg(f.v->stable, "%s", f.v->reason);
    }
    fixture_free(&f);
  }
}
END_TEST

int main(void) {
  Suite *s = suite_create("verdict");
  TCase *tc = tcase_create("fracture and zig-zag");
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, adjacent_pairs_of_a_lattice);
  tcase_add_test(tc, unmoved_does_not_trip);
  tcase_add_test(tc, uniaxial_stretch_does_not_trip);
  tcase_add_test(tc, isotropic_stretch_trips_unless_raised);
  tcase_add_test(tc, crack_trips_with_its_pair_count);
  tcase_add_test(tc, bodies_parting_is_not_fracture);
  tcase_add_test(tc, smooth_fields_are_not_zigzag);
  tcase_add_test(tc, alternation_is_zigzag);
  tcase_add_test(tc, zigzag_is_scale_free_and_can_be_off);
  tcase_add_test(tc, coarse_bodies_are_not_judged);
  tcase_add_test(tc, energy_growth_above_round_off);
  tcase_add_test(tc, indicator_keys);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
