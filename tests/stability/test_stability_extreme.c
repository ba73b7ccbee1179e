/* The extreme hard cases at CI size (docs/benchmarks.md A3, B10, B4 long time,
 * A8 at 0.08 c0): each run's verdict and the indicator of its failure mode,
 * through the same verdict the sph command uses (stability_run.h). */
#include "stability_run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- A3: twisting column at Omega = 300 rad/s --------------------------- */

typedef struct tip_track {
  size_t tip;
  double max_disp; /* largest tip displacement seen, m */
} tip_track;

static void track_tip(sph_sim *sim, void *ctx) {
  tip_track *tt = ctx;
  const sph_particles *ps = sim->ps;
  if (!tt->tip)
    tt->tip = nearest_particle(ps, 0.5, 6.0, 0.5);
  const double *x = ps->field[SPH_FIELD_POSITION] + 3 * tt->tip;
  const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * tt->tip;
  double d =
      sqrt(pow(x[0] - X[0], 2) + pow(x[1] - X[1], 2) + pow(x[2] - X[2], 2));
  tt->max_disp = fmax(tt->max_disp, d);
}

START_TEST(twisting_column_omega_300) {
  /* scenes/twisting_column_extreme.yaml: {p,F} JST at 5 x 25 x 5, nu 0.49.
   * The twist at the clamp peaks near 0.045 s with pairs at most 4 dp apart
   * (energy bound 5 dp, threshold 6); the measured failure is a numerical
   * fracture near the free end after that peak, without NaN or inversion.
   * Seed 004 (bond-based F, SSP-RK3, 11 x 11 x 66) is stable to 92.1 ms. */
  tip_track tt = {0, 0.0};
  outcome o =
      run_case("twisting_column_extreme", NULL, 0, 0.0025, track_tip, &tt);
  show("A3 twisting column Omega 300", &o,
       "tripped at %.4g s, tip moved %.3g m", o.t_tripped, tt.max_disp);
  ck_assert_msg(!o.stable && o.first == SPH_INDICATOR_FRACTURE,
                "expected the numerical fracture of tl-jst: %s",
                o.stable ? "stable" : o.reason);
  ck_assert_msg(o.t_tripped > 0.045 && o.t_tripped < 0.1,
                "tripped at %g s, not after the twist peak", o.t_tripped);
  ck_assert(!o.nan);
  ck_assert_msg(o.j_min > 0.0, "J min %g", o.j_min);
  ck_assert_msg(o.stretch_max > 6.0 && o.pairs_over > 0, "stretch %g dp",
                o.stretch_max);
}
END_TEST

/* scenes/twisting_column_bond.yaml: the same column with seed 004's method
 * (tl-bond, bond F, SSP-RK3 at CFL 0.5) as shipped (7 x 37 x 7) to its end
 * time, the paper's 92.1 ms: stable through the twist peak and back; then
 * on past it to 0.3 s, where the run must end with a verdict (it measures a
 * time-step collapse at 0.138 s: two particles closing onto each other),
 * never hang or NaN unnoticed. */
START_TEST(twisting_column_bond_omega_300) {
  tip_track tt = {0, 0.0};
  outcome o = run_case("twisting_column_bond", NULL, 0, 0.0025, track_tip, &tt);
  show("A3 tl-bond Omega 300 to 92.1 ms", &o, "tip moved %.3g m", tt.max_disp);
  ck_assert_msg(o.stable, "%s", o.reason);
  ck_assert_msg(o.j_min > 0.3, "J min %g", o.j_min);
  ck_assert_msg(o.e_max <= o.e0 * 1.0001, "energy %g above the initial %g",
                o.e_max, o.e0);
  ck_assert_msg(tt.max_disp > 0.3, "tip moved only %g m", tt.max_disp);
  const char *past[] = {"time.end=0.3"};
  outcome p = run_case("twisting_column_bond", past, 1, 0.0025, NULL, NULL);
  show("A3 tl-bond Omega 300 to 0.3 s", &p, "tripped at %.4g s", p.t_tripped);
  ck_assert_msg(p.stable || p.t_tripped > 0.0921,
                "tripped at %g s, before the paper's 92.1 ms", p.t_tripped);
}
END_TEST

/* seed 004 sec. 5.3/5.5: SSP-RK3 with the bond F runs the shipped A1 column
 * (7 x 37 x 7, to its end time 0.3 s) at CFL 0.9, where tl-jst's TVD-RK2
 * at the same CFL is stopped; both at h = 1.1 dp (tl-bond's kernel) */
START_TEST(twisting_column_cfl_09) {
  const char *bond[] = {"method={name: tl-bond, cfl: 0.9}",
                        "kernel.h_over_dp=1.1"};
  outcome b = run_case("twisting_column", bond, 2, 0.005, NULL, NULL);
  show("A1 tl-bond SSP-RK3 CFL 0.9", &b, NULL);
  ck_assert_msg(b.stable, "%s", b.reason);
  ck_assert_msg(b.e_max <= b.e0 * 1.0001, "energy %g above %g", b.e_max, b.e0);
  const char *jst[] = {"method.cfl=0.9", "kernel.h_over_dp=1.1"};
  outcome j = run_case("twisting_column", jst, 2, 0.005, NULL, NULL);
  show("A1 tl-jst TVD-RK2 CFL 0.9", &j, "tripped at %.4g s", j.t_tripped);
  ck_assert_msg(!j.stable, "tl-jst at CFL 0.9 was not flagged");
}
END_TEST

/* ---- B10: pulling column --------------------------------------------------
 */

typedef struct pull_track {
  size_t *top; /* particles of the pulled face */
  size_t ntop;
  double stretch_pct; /* (L' - L) / L x 100 at the latest frame */
  double prev_pct;    /* at the frame before */
} pull_track;

static void track_pull(sph_sim *sim, void *ctx) {
  pull_track *pt = ctx;
  const sph_particles *ps = sim->ps;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  const double *x = ps->field[SPH_FIELD_POSITION];
  if (!pt->top) {
    pt->top = malloc(ps->n * sizeof *pt->top);
    ck_assert_ptr_nonnull(pt->top);
    for (size_t a = 0; a < ps->n; ++a)
      if (fabs(X[3 * a + 1] - 6.0) < 1e-9)
        pt->top[pt->ntop++] = a;
    ck_assert(pt->ntop > 0);
  }
  double y = 0.0;
  for (size_t k = 0; k < pt->ntop; ++k)
    y += x[3 * pt->top[k] + 1];
  pt->prev_pct = pt->stretch_pct;
  pt->stretch_pct = (y / (double)pt->ntop - 6.0) / 6.0 * 100.0;
}

START_TEST(pulling_column) {
  /* scenes/pulling_column.yaml, {p,F} JST at 5 x 25 x 5, to 300 % stretch
   * (t = 1.8 s). Seed 004's JST-SPH (12 x 12 x 72) reaches 421.9 % before
   * its NaN; this tl-jst does not reach 300 %: an odd-even (hourglass)
   * mode of the axial spacing grows from the clamped and the pulled faces
   * until particles pass each other, which the fracture indicator sees.
   * Measured (scene comment): the largest initially adjacent distance stays
   * within 1.31 lambda dp (a uniform stretch lambda puts axial neighbours
   * lambda dp apart) up to 150 % and trips the threshold at 161.7 %; the
   * variants tried fail between 117 and 183 %. The test asserts that
   * documented failure mode: stable beyond 100 % (lambda = 2), tripped by
   * the fracture indicator before 300 %, no NaN and J > 0 throughout. */
  pull_track pt = {0};
  outcome o = run_case("pulling_column", NULL, 0, 0.01, track_pull, &pt);
  show("B10 pulling column", &o,
       "stretch %.1f %% at the trip (%.1f %% at the frame before)",
       pt.stretch_pct, pt.prev_pct);
  free(pt.top);
  /* the odd-even mode is what either indicator reports */
  ck_assert_msg(!o.stable && (o.first == SPH_INDICATOR_FRACTURE ||
                              o.first == SPH_INDICATOR_ZIGZAG),
                "expected the numerical fracture or zig-zag of tl-jst: %s",
                o.stable ? "stable to 300 %" : o.reason);
  ck_assert_msg(pt.prev_pct > 100.0 && pt.stretch_pct < 300.0,
                "tripped at %g %% stretch", pt.stretch_pct);
  ck_assert(!o.nan);
  ck_assert_msg(o.j_min > 0.0, "J min %g", o.j_min);
}
END_TEST

/* ---- B4: oscillating plate over 30 periods --------------------------------
 */

typedef struct plate_track {
  int init;
  size_t tip;
  double y_prev, t_prev;
  int periods;             /* upward zero crossings of the tip deflection */
  double lo, hi;           /* extremes in the current period */
  double amp_first;        /* half the peak-to-peak of the first period */
  double amp_last;         /* the same for the latest complete period */
  double t_cross;          /* time of the latest upward crossing */
  double period_first;     /* length of the first period */
  double period_last;      /* and of the latest */
  double xsum, xn, x_last; /* mean axial tip displacement per period */
} plate_track;

static void track_plate(sph_sim *sim, void *ctx) {
  plate_track *pt = ctx;
  const sph_particles *ps = sim->ps;
  if (!pt->init) {
    pt->init = 1;
    pt->tip = nearest_particle(ps, 0.2, 0.0, 0.0);
    pt->lo = INFINITY;
    pt->hi = -INFINITY;
  }
  const double *x = ps->field[SPH_FIELD_POSITION] + 3 * pt->tip;
  const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * pt->tip;
  double y = x[1] - X[1], t = sim->t;
  if (t > 0.01 && pt->y_prev < 0.0 && y >= 0.0) {
    double tc = pt->t_prev + (t - pt->t_prev) * -pt->y_prev / (y - pt->y_prev);
    double amp = 0.5 * (pt->hi - pt->lo);
    if (++pt->periods == 1) {
      pt->amp_first = amp;
      pt->period_first = tc;
    }
    pt->amp_last = amp;
    pt->period_last = tc - pt->t_cross;
    pt->t_cross = tc;
    pt->x_last = pt->xsum / pt->xn;
    pt->lo = INFINITY;
    pt->hi = -INFINITY;
    pt->xsum = pt->xn = 0.0;
  }
  pt->lo = fmin(pt->lo, y);
  pt->hi = fmax(pt->hi, y);
  pt->xsum += x[0] - X[0];
  pt->xn += 1.0;
  pt->y_prev = y;
  pt->t_prev = t;
}

START_TEST(oscillating_plate_30_periods) {
  /* B4 with ENOG at H/dp = 5 (spacing 0.004, the 0.016 m root of 4
   * layers), v_f 0.01, for 9 s: more than 30 periods (seed 002 Fig. 7 runs
   * 30+ at H/dp 10). The Riemann dissipation only removes energy: the
   * energy may not rise; measured -0.61 % by 9 s, bound 2 %. The amplitude
   * of the mode goes as the square root of its energy; the stated fraction,
   * 0.95 of the first period's amplitude, is a loss of 10 % of the energy
   * (16 times the measured loss; OAS "exhibits rapid energy decay").
   * Measured: the last period's amplitude is 1.03 times the first's, since
   * the plate also creeps: the tip's mean axial displacement grows by about
   * 1 mm/s (9.7 mm by 9 s; half the rate at H/dp 10), which lengthens the
   * period from 0.271 to 0.300 s and the tip's lever. */
  const char *sets[] = {"bodies.0.particles.spacing=0.004",
                        "bodies.0.shape.box.min=[-0.016,-0.01]", "time.end=9"};
  plate_track pt = {0};
  outcome o =
      run_case("oscillating_plate_2d", sets, 3, 0.005, track_plate, &pt);
  show("B4 plate H/dp 5, 9 s", &o,
       "%d periods (first %.4f s, last %.4f s), amplitude first %.5f last "
       "%.5f (ratio %.4f), energy change %.2e, mean axial tip displacement "
       "over the last period %.2e m",
       pt.periods, pt.period_first, pt.period_last, pt.amp_first, pt.amp_last,
       pt.amp_last / pt.amp_first, (o.e1 - o.e0) / o.e0, pt.x_last);
  ck_assert_msg(o.stable, "%s", o.reason);
  ck_assert_int_ge(pt.periods, 30);
  ck_assert_msg(o.e_max <= o.e0 && o.e1 > 0.98 * o.e0,
                "energy %g -> %g (max %g)", o.e0, o.e1, o.e_max);
  ck_assert_msg(pt.amp_last > 0.95 * pt.amp_first, "amplitude %g -> %g",
                pt.amp_first, pt.amp_last);
}
END_TEST

START_TEST(oscillating_plate_large_amplitude) {
  /* B4 at seed 002 Table 1's largest amplitude, v_f 0.05, H/dp 5, to 1 s
   * (about 3 periods): stable with the full Riemann dissipation, the
   * energy never above its initial value (measured 4.064 -> 3.795 J/m,
   * period 0.309 at this resolution, 0.2817 at H/dp 10). The twin with eq.
   * 16's limiter gains kinetic energy: measured, energy growth at 0.145 s. */
  const char *sets[] = {"bodies.0.particles.spacing=0.004",
                        "bodies.0.shape.box.min=[-0.016,-0.01]", "time.end=1",
                        "method.dissipation=full"};
  outcome o = run("oscillating_plate_2d_large", sets, 4, 0.005);
  ck_assert_msg(o.stable && o.t >= 1.0 - 1e-12, "%s", o.reason);
  ck_assert_msg(o.e_max <= o.e0, "energy %g -> max %g", o.e0, o.e_max);
  ck_assert(o.stretch_max < SPH_FRACTURE_DP && o.pairs_over == 0);
  sets[3] = "method.dissipation=limited";
  outcome l = run("oscillating_plate_2d_large", sets, 4, 0.005);
  ck_assert_msg(!l.stable && l.first == SPH_INDICATOR_ENERGY_GROWTH,
                "limited: %s", l.stable ? "stable" : l.reason);
  ck_assert_msg(l.t_tripped > 0.1 && l.t_tripped < 0.2, "tripped at %g",
                l.t_tripped);
}
END_TEST

/* ---- A8: colliding rings through and after the rebound ---------------------
 */

typedef struct rings_track {
  int frames;
  double ke0;    /* kinetic energy at t = 0 */
  double ke_max; /* largest kinetic energy over the frames */
  double e_max;  /* largest booked total (kinetic + stored) after t = 0 */
  double vx_end; /* mean x velocity of the left ring at the latest frame */
  double gap;    /* min x of the right ring - max x of the left, latest */
} rings_track;

static void track_rings(sph_sim *sim, void *ctx) {
  rings_track *rt = ctx;
  const sph_particles *ps = sim->ps;
  const double *m = ps->field[SPH_FIELD_MASS];
  const double *v = ps->field[SPH_FIELD_VELOCITY];
  const double *x = ps->field[SPH_FIELD_POSITION];
  double k, st;
  sim->method->energy(sim, &k, &st);
  if (rt->frames++ == 0) {
    rt->ke0 = k;
    rt->e_max = k + st;
  }
  rt->ke_max = fmax(rt->ke_max, k);
  rt->e_max = fmax(rt->e_max, k + st);
  double mv = 0.0, mass = 0.0, left = -INFINITY, right = INFINITY;
  for (size_t a = 0; a < ps->n; ++a)
    if (ps->body[a] == 0) {
      mv += m[a] * v[3 * a];
      mass += m[a];
      left = fmax(left, x[3 * a]);
    } else {
      right = fmin(right, x[3 * a]);
    }
  rt->vx_end = mv / mass;
  rt->gap = right - left;
}

static outcome rings_to(double v0, const char *dissipation, double t_end,
                        rings_track *rt) {
  char vl[96], vr[96], end[64], diss[64];
  snprintf(vl, sizeof vl, "bodies.0.initial_velocity.uniform=[%.17g,0,0]", v0);
  snprintf(vr, sizeof vr, "bodies.1.initial_velocity.uniform=[%.17g,0,0]", -v0);
  snprintf(end, sizeof end, "time.end=%g", t_end);
  snprintf(diss, sizeof diss, "method.dissipation=%s", dissipation);
  const char *sets[] = {"method.shear=laplacian",
                        end,
                        diss,
                        "bodies.0.particles.spacing=0.002",
                        "bodies.1.particles.spacing=0.002",
                        vl,
                        vr};
  *rt = (rings_track){0};
  return run_case("colliding_rings", sets, 7, 0.0005, track_rings, rt);
}

START_TEST(rings_enog_past_the_rebound) {
  /* A8 at v0 = 0.06, 0.07, 0.08 c0 (c0 = 117.85 m/s), dp = 0.002, ENOG, to
   * 0.03 s: the rings meet at about 0.003 s, part at about 0.012 s and then
   * oscillate freely (seed 002 Fig. 16-18: no fracture, no zig-zag). The
   * verdict keeps its defaults (fracture beyond 2 dp, zig-zag above 0.5,
   * energy growth). The booked total (kinetic + volumetric + work against
   * the shear force) never exceeds its initial value and the kinetic energy
   * stays below it. */
  const double c0 = 117.85113019775793, frac[] = {0.06, 0.07, 0.08};
  for (int i = 0; i < 3; ++i) {
    double v0 = frac[i] * c0, area = M_PI * (0.04 * 0.04 - 0.03 * 0.03);
    double ke = 0.5 * 1200 * area * v0 * v0;
    rings_track rt;
    outcome o = rings_to(v0, "full", 0.03, &rt);
    char label[64];
    snprintf(label, sizeof label, "A8 rings %.2f c0 ENOG", frac[i]);
    show(label, &o,
         "kinetic per ring %.3f (1/2 rho A v0^2 = %.3f), max %.3f; total "
         "max %.4g; left ring v_x at 0.03: %.3f m/s, gap %.4f m",
         0.5 * rt.ke0, ke, 0.5 * rt.ke_max, rt.e_max, rt.vx_end, rt.gap);
    ck_assert_msg(o.stable && o.t >= 0.03 - 1e-12, "%g c0: %s", frac[i],
                  o.reason);
    ck_assert_msg(fabs(0.5 * rt.ke0 - ke) < 0.01 * ke, "kinetic %g vs %g",
                  0.5 * rt.ke0, ke);
    ck_assert_msg(rt.e_max <= rt.ke0 * (1.0 + 1e-12),
                  "%g c0: total %g above its initial %g", frac[i], rt.e_max,
                  rt.ke0);
    ck_assert_msg(rt.ke_max <= rt.ke0, "%g c0: kinetic %g above initial %g",
                  frac[i], rt.ke_max, rt.ke0);
    ck_assert_msg(o.stretch_max < SPH_FRACTURE_DP && o.pairs_over == 0,
                  "stretch %g dp", o.stretch_max);
    /* (NaN: rings 5 particles thick are too coarse to be judged) */
    ck_assert_msg(!isgreaterequal(o.zigzag_max, SPH_ZIGZAG_MAX), "zig-zag %g",
                  o.zigzag_max);
    ck_assert_msg(rt.vx_end < 0.0 && rt.gap > 0.0,
                  "%g c0: the rings did not part (v_x %g, gap %g)", frac[i],
                  rt.vx_end, rt.gap);
  }
}
END_TEST

START_TEST(rings_limited_dissipation_gain_energy) {
  /* the twin: with eq. 16's limiter the Riemann dissipation acts only on
   * approaching pairs, and ENOG's shear force (no potential) creates kinetic
   * energy after the rebound. Measured: energy growth trips at 0.0125 s. */
  rings_track rt;
  outcome o = rings_to(0.08 * 117.85113019775793, "limited", 0.03, &rt);
  show("A8 rings 0.08 c0 limited", &o, "kinetic max %.4g of %.4g", rt.ke_max,
       rt.ke0);
  ck_assert_msg(!o.stable && o.first == SPH_INDICATOR_ENERGY_GROWTH,
                "limited dissipation: %s", o.stable ? "stable" : o.reason);
  ck_assert_msg(o.t_tripped > 0.010 && o.t_tripped < 0.016, "tripped at %g",
                o.t_tripped);
}
END_TEST

START_TEST(rings_unequal_gain_energy) {
  /* issue 35 item 3: a thin ring (inner radius 0.03) against a thick one
   * (0.025) at 0.07 c0, dp 0.002: the thin ring folds at the impact and
   * stays folded. With `energy: state` (the isochoric neo-Hookean energy of
   * F from the reference positions) the total jumps from 201.5 to 262.5 J/m
   * of an initial 214.9 as the fold forms and trips at 0.005 s; the booked
   * work against ENOG's shear force (the default) hid it until the kinetic
   * energy alone passed the initial total at 0.027 s (booked strain then
   * falling to -83 J/m). */
  const char *sets[] = {"bodies.0.particles.spacing=0.002",
                        "bodies.1.particles.spacing=0.002",
                        "bodies.0.initial_velocity.uniform=[8.2496,0,0]",
                        "bodies.1.initial_velocity.uniform=[-8.2496,0,0]",
                        "bodies.1.shape.ring.inner_radius=0.025",
                        "time.end=0.03",
                        "method.energy=state"};
  rings_track rt = {0};
  outcome o = run_case("colliding_rings", sets, 7, 0.0005, track_rings, &rt);
  show("A8 rings thin against thick 0.07 c0", &o, "total max %.4g of %.4g",
       rt.e_max, rt.ke0);
  ck_assert_msg(!o.stable && o.first == SPH_INDICATOR_ENERGY_GROWTH,
                "unequal rings: %s", o.stable ? "stable" : o.reason);
  ck_assert_msg(o.t_tripped < 0.008, "tripped at %g", o.t_tripped);
  /* the booked total (the default) trips only when the kinetic energy alone
   * passes the initial total, long after the fold (0.027 s measured): shown,
   * not asserted, so that a fix of ENOG's shear force does not fail here */
  sets[6] = "method.energy=booked";
  outcome b = run_case("colliding_rings", sets, 7, 0.0005, track_rings, &rt);
  show("A8 rings thin against thick, booked", &b, NULL);
}
END_TEST

int main(void) {
  Suite *s = suite_create("stability_extreme");
  TCase *tc = tcase_create("extreme cases");
  tcase_set_timeout(tc, 900);
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, twisting_column_omega_300);
  tcase_add_test(tc, twisting_column_bond_omega_300);
  tcase_add_test(tc, twisting_column_cfl_09);
  tcase_add_test(tc, pulling_column);
  tcase_add_test(tc, oscillating_plate_30_periods);
  tcase_add_test(tc, oscillating_plate_large_amplitude);
  tcase_add_test(tc, rings_enog_past_the_rebound);
  tcase_add_test(tc, rings_limited_dissipation_gain_energy);
  tcase_add_test(tc, rings_unequal_gain_energy);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
