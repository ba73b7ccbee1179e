/* ul-csph against tl-csph on seed 001's cases: the 1D bar of sec. 3.3.1
 * (standard updated formulation breaks, the stabilised one stays close to
 * the total-Lagrangian run), the punch of sec. 2.4.3 / 4.3 (what is
 * measured, which is not the paper's clear-cut outcome: docs/results.md)
 * and the rubber rings of sec. 2.4.2 / 4.2 (through the contact term). */
#include "stability_run.h"

typedef struct tip {
  long a;      /* the particle at the free end B */
  double umax; /* its largest displacement along the bar */
} tip;

static void track_tip(sph_sim *sim, void *ctx) {
  tip *t = ctx;
  const sph_particles *ps = sim->ps;
  if (t->a < 0) { /* largest X, nearest the bar's axis */
    double best = -1e300;
    for (size_t a = 0; a < ps->n; ++a) {
      const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * a;
      double score = X[0] - fabs(X[1] - 0.375) - fabs(X[2] - 0.375);
      if (score > best)
        best = score, t->a = (long)a;
    }
  }
  t->umax = fmax(t->umax, ps->field[SPH_FIELD_DISPLACEMENT][3 * t->a]);
}

START_TEST(bar_standard_breaks_stabilised_follows_tl) {
  static const char *tl[] = {"method={name: tl-csph}"};
  static const char *plain[] = {"method.eta=0"};
  tip ttl = {-1, 0}, tst = {-1, 0};
  outcome otl = run_case("bar_ul_csph", tl, 1, 0.01, track_tip, &ttl);
  outcome o0 = run_case("bar_ul_csph", plain, 1, 0.01, NULL, NULL);
  outcome ost = run_case("bar_ul_csph", NULL, 0, 0.01, track_tip, &tst);
  show("bar tl-csph", &otl, "tip max %.4f", ttl.umax);
  show("bar ul-csph eta 0", &o0, "");
  show("bar ul-csph eta 0.3", &ost, "tip max %.4f", tst.umax);
  ck_assert_msg(otl.stable, "tl-csph: %s", otl.reason);
  /* the mechanism of sec. 3.2 excited by the updates (measured: fracture,
   * 2.13 dp at 0.23 s) */
  ck_assert_msg(!o0.stable && o0.first == SPH_INDICATOR_FRACTURE,
                "eta 0 was not flagged by fracture: %s", o0.reason);
  /* stabilised: stable, largest end displacement within 5 % of tl-csph
   * (measured 0.2549 against 0.2497, 2.1 %), energy kept to 2e-3
   * (leap-frog, no dissipation; measured +4.9e-4 at the end) */
  ck_assert_msg(ost.stable, "eta 0.3: %s", ost.reason);
  ck_assert_double_le(fabs(tst.umax - ttl.umax), 0.05 * ttl.umax);
  ck_assert_double_le(fabs(ost.e1 - ost.e0), 2e-3 * ost.e0);
}
END_TEST

START_TEST(punch_measured) {
  static const char *tl[] = {"method={name: tl-csph}"};
  static const char *tl_all[] = {"method={name: tl-csph}",
                                 "stability.zigzag_max=0",
                                 "stability.fracture_dp=0"};
  static const char *ul_all[] = {"stability.zigzag_max=0",
                                 "stability.fracture_dp=0"};
  outcome otl = run_case("punch_ul_csph", tl, 1, 1e-5, NULL, NULL);
  outcome oul = run_case("punch_ul_csph", NULL, 0, 1e-5, NULL, NULL);
  outcome atl = run_case("punch_ul_csph", tl_all, 3, 1e-5, NULL, NULL);
  outcome aul = run_case("punch_ul_csph", ul_all, 2, 1e-5, NULL, NULL);
  show("punch tl-csph", &otl, "");
  show("punch ul-csph", &oul, "");
  show("punch tl-csph, nan/J only", &atl, "");
  show("punch ul-csph, nan/J only", &aul, "");
  /* the tool edge's stress concentration flags both by zig-zag, tl-csph
   * first (measured 6e-5 s against 8e-5 s) */
  ck_assert(!otl.stable && otl.first == SPH_INDICATOR_ZIGZAG);
  ck_assert(!oul.stable && oul.first == SPH_INDICATOR_ZIGZAG);
  ck_assert_double_lt(otl.t_tripped, oul.t_tripped);
  /* judged on nan and J only both reach 54 % of the height; the updated
   * run keeps the smallest J higher (measured 0.400 against 0.120 with the
   * paper's frictionless tool; 0.162 against 0.107 with the top row's
   * velocity prescribed) */
  ck_assert_msg(atl.stable && aul.stable, "%s / %s", atl.reason, aul.reason);
  ck_assert_double_gt(aul.j_min, 1.3 * atl.j_min);
}
END_TEST

/* over the frames: the most any particle lies across the planes X = 0 and
 * Y = 0 or inside the tool (X < 0.01 above its bottom, 0.0105 - 10 t) */
typedef struct planes_watch {
  double across, in_tool;
  int frames;
} planes_watch;

static void watch_planes(sph_sim *sim, void *ctx) {
  planes_watch *w = ctx;
  const sph_particles *ps = sim->ps;
  const double *x = ps->field[SPH_FIELD_POSITION];
  double bottom = 0.0105 - 10.0 * sim->t;
  for (size_t a = 0; a < ps->n; ++a) {
    w->across = fmax(w->across, fmax(-x[3 * a], -x[3 * a + 1]));
    if (x[3 * a] < 0.01)
      w->in_tool =
          fmax(w->in_tool, fmin(x[3 * a + 1] - bottom, 0.01 - x[3 * a]));
  }
  w->frames++;
}

/* The symmetry planes hold every particle on its side: judged on the
 * particles, every 1e-5 s, to 0.0006 s (the scene ends at 0.00048). Before
 * the particles on a plane were held and a crossing particle traded places
 * with its image, they left the planes (1 dp across X = 0 by 0.00044 s,
 * then nan); the run judged on nan and J only. */
START_TEST(punch_planes_hold) {
  static const char *beyond[] = {"time.end=0.0006", "stability.zigzag_max=0",
                                 "stability.fracture_dp=0"};
  planes_watch w = {0};
  outcome o = run_case("punch_ul_csph", beyond, 3, 1e-5, watch_planes, &w);
  show("punch ul-csph to 0.0006 s", &o, "across %.3g m, in the tool %.3g m",
       w.across, w.in_tool);
  ck_assert_msg(o.stable, "%s", o.reason);
  ck_assert_int_eq(w.frames, 61);
  /* on its side to round-off of the 1 mm spacing (measured 0 exactly) */
  ck_assert_double_le(w.across, 1e-15);
  /* the tool is a penalty wall, a spring layer dp / 2 thick (contact.c):
   * no particle deeper (measured 1.8e-4 m under its middle at 0.00058 s) */
  ck_assert_double_lt(w.in_tool, 0.5e-3);
}
END_TEST

/* scenes/<name>.yaml with overrides to its end, frames every `every` s,
 * steps shortened to land on them or not (at_steps): the positions and
 * velocities at the end into xv (6 per particle), their count */
static size_t end_state(const char *name, const char *const *sets, size_t nsets,
                        double every, int at_steps, double *xv, size_t cap) {
  char path[512];
  snprintf(path, sizeof path, "%s/scenes/%s.yaml", SPH_SOURCE_DIR, name);
  sph_scene *s;
  sph_run *run;
  sph_error err;
  ck_assert_msg(sph_scene_load(&s, path, sets, nsets, &err) == SPH_OK, "%s",
                err.message);
  sph_run_options opt = {.no_files = 1};
  sph_run_hooks hooks = {.every = every, .at_steps = at_steps};
  ck_assert_msg(sph_run_create_hooked(&run, s, &opt, &hooks, &err) == SPH_OK,
                "%s", err.message);
  ck_assert_msg(sph_run_advance(run, sph_scene_end_time(s), &err) == SPH_OK,
                "%s", err.message);
  const sph_sim *sim = sph_run_sim(run);
  ck_assert_msg(sph_run_verdict(run)->stable, "%s",
                sph_run_verdict(run)->reason);
  ck_assert_double_eq(sim->t, sph_scene_end_time(s));
  const sph_particles *ps = sim->ps;
  ck_assert_uint_le(ps->n, cap);
  for (size_t a = 0; a < ps->n; ++a)
    for (int c = 0; c < 3; ++c) {
      xv[6 * a + c] = ps->field[SPH_FIELD_POSITION][3 * a + c];
      xv[6 * a + 3 + c] = ps->field[SPH_FIELD_VELOCITY][3 * a + c];
    }
  size_t n = ps->n;
  sph_run_destroy(run);
  sph_scene_destroy(s);
  return n;
}

static double largest_difference(const double *a, const double *b, size_t n,
                                 int part) {
  double d = 0.0;
  for (size_t k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c)
      d = fmax(d, fabs(a[6 * k + 3 * part + c] - b[6 * k + 3 * part + c]));
  return d;
}

/* Outputs must not change the solution: with the steps shortened to land
 * on the output times, frames every 1e-5 s and every 2.4e-4 s end the
 * punch 1.13 dp apart (measured; the step sequence, so the reference
 * update times, differ); with the steps independent of the outputs
 * (at_steps) the two end states are the same bits. */
START_TEST(outputs_do_not_change_the_solution) {
  static const char *sets[] = {"stability.zigzag_max=0",
                               "stability.fracture_dp=0"};
  enum { CAP = 400 };
  static double a[6 * CAP], b[6 * CAP], c[6 * CAP], d[6 * CAP];
  size_t n = end_state("punch_ul_csph", sets, 2, 1e-5, 1, a, CAP);
  ck_assert_uint_eq(end_state("punch_ul_csph", sets, 2, 2.4e-4, 1, b, CAP), n);
  ck_assert_uint_eq(end_state("punch_ul_csph", sets, 2, 1e-5, 0, c, CAP), n);
  ck_assert_uint_eq(end_state("punch_ul_csph", sets, 2, 2.4e-4, 0, d, CAP), n);
  printf("punch ul-csph end state, frames every 1e-5 s against 2.4e-4 s: "
         "landing on them %.3g m, %.3g m/s apart; at steps %.3g m, %.3g m/s\n",
         largest_difference(c, d, n, 0), largest_difference(c, d, n, 1),
         largest_difference(a, b, n, 0), largest_difference(a, b, n, 1));
  ck_assert_int_eq(memcmp(a, b, 6 * n * sizeof *a), 0);
}
END_TEST

/* the top of the left ring (Fig. 20's y displacement) and the bodies'
 * momentum along x, over the frames */
typedef struct ring_watch {
  long top;
  double uy_max;  /* largest |u_y| of the top */
  double uy[256]; /* per frame */
  int frames;
  double px_drift;     /* largest |sum m v_x| change over the frames */
  double px0, p_scale; /* sum m |v| at the start */
} ring_watch;

static void watch_ring(sph_sim *sim, void *ctx) {
  ring_watch *w = ctx;
  const sph_particles *ps = sim->ps;
  if (w->top < 0)
    w->top = (long)nearest_particle(ps, -0.045, 0.039, 0.0);
  double uy = ps->field[SPH_FIELD_DISPLACEMENT][3 * w->top + 1];
  w->uy_max = fmax(w->uy_max, fabs(uy));
  if (w->frames < 256)
    w->uy[w->frames] = uy;
  double px = 0.0, scale = 0.0;
  for (size_t a = 0; a < ps->n; ++a) {
    double m = ps->field[SPH_FIELD_MASS][a];
    px += m * ps->field[SPH_FIELD_VELOCITY][3 * a];
    scale += m * fabs(ps->field[SPH_FIELD_VELOCITY][3 * a]);
  }
  if (w->frames++ == 0) {
    w->px0 = px;
    w->p_scale = scale;
  }
  w->px_drift = fmax(w->px_drift, fabs(px - w->px0));
}

/* seed 001 sec. 2.4.2 / 4.2: one ring against its symmetry plane (a rigid
 * wall) and the two rings in contact, to twice the paper's 0.05 s: past
 * the rebound and into the free oscillation */
START_TEST(rubber_rings) {
  static const char *end[] = {"time.end=0.1"};
  static const char *tl[] = {"time.end=0.1", "method={name: tl-csph}"};
  static const char *paper[] = {"time.end=0.1", "method.eta=0.3"};
  ring_watch wul = {.top = -1}, wtl = {.top = -1}, w2ul = {.top = -1},
             w2tl = {.top = -1};
  const double every = 0.001;
  outcome oul =
      run_case("rubber_ring_symmetry", end, 1, every, watch_ring, &wul);
  outcome otl =
      run_case("rubber_ring_symmetry", tl, 2, every, watch_ring, &wtl);
  outcome o03 = run_case("rubber_ring_symmetry", paper, 2, every, NULL, NULL);
  outcome o2ul =
      run_case("rubber_rings_ul_csph", end, 1, every, watch_ring, &w2ul);
  outcome o2tl =
      run_case("rubber_rings_ul_csph", tl, 2, every, watch_ring, &w2tl);
  double d_tl = 0.0, d_ul = 0.0; /* one ring against two, per frame */
  for (int k = 0; k < wtl.frames && k < w2tl.frames && k < 256; ++k)
    d_tl = fmax(d_tl, fabs(wtl.uy[k] - w2tl.uy[k]));
  for (int k = 0; k < wul.frames && k < w2ul.frames && k < 256; ++k)
    d_ul = fmax(d_ul, fabs(wul.uy[k] - w2ul.uy[k]));
  show("ring + plane ul-csph eta 1.5", &oul, "top |u_y| max %.4g", wul.uy_max);
  show("ring + plane tl-csph", &otl, "top |u_y| max %.4g", wtl.uy_max);
  show("ring + plane ul-csph eta 0.3", &o03, "");
  show("two rings ul-csph eta 1.5", &o2ul,
       "top |u_y| max %.4g, against one ring %.3g; momentum x drift %.3g of "
       "%.3g",
       w2ul.uy_max, d_ul, w2ul.px_drift, w2ul.p_scale);
  show("two rings tl-csph", &o2tl,
       "top |u_y| max %.4g, against one ring %.3g; momentum x drift %.3g of "
       "%.3g",
       w2tl.uy_max, d_tl, w2tl.px_drift, w2tl.p_scale);
  ck_assert_msg(oul.stable && otl.stable, "%s / %s", oul.reason, otl.reason);
  ck_assert_msg(o2ul.stable && o2tl.stable, "%s / %s", o2ul.reason,
                o2tl.reason);
  /* no energy made by the contact (leap-frog, no dissipation: measured
   * within 1e-4 relative) */
  ck_assert_double_le(fabs(oul.e1 - oul.e0), 1e-3 * oul.e0);
  ck_assert_double_le(fabs(o2ul.e1 - o2ul.e0), 1e-3 * o2ul.e0);
  /* equal and opposite pair forces */
  ck_assert_double_le(w2ul.px_drift, 1e-12 * w2ul.p_scale);
  ck_assert_double_le(w2tl.px_drift, 1e-12 * w2tl.p_scale);
  /* Fig. 20: the stabilised updated run follows the total-Lagrangian one
   * against the plane (measured 0.00424 against 0.00405, 5 %) */
  ck_assert_double_le(fabs(wul.uy_max - wtl.uy_max), 0.1 * wtl.uy_max);
  /* tl-csph keeps the mirror symmetry and only mirror twins come closer
   * than dp, so the second ring acts exactly as the plane: the same history
   * to round-off (measured 2.6e-13 m). ul-csph does not keep the symmetry
   * (measured 4.9e-3 m apart): eq. 21 stabilises along h = (h, h, h) */
  ck_assert_double_le(d_tl, 1e-9);
  /* the paper's eta = 0.3 at five particles across: initially adjacent
   * particles at the bottom of the ring part (measured 2.05 dp at 0.025 s),
   * after the contact began at 8.5 ms */
  ck_assert_msg(!o03.stable && o03.first == SPH_INDICATOR_FRACTURE,
                "eta 0.3: %s", o03.reason);
  ck_assert_double_gt(o03.t_tripped, 0.0085);
}
END_TEST

int main(void) {
  Suite *s = suite_create("stability_ul_csph");
  TCase *tc = tcase_create("seed 001");
  tcase_set_timeout(tc, 900);
  tcase_add_test(tc, bar_standard_breaks_stabilised_follows_tl);
  tcase_add_test(tc, punch_measured);
  tcase_add_test(tc, punch_planes_hold);
  tcase_add_test(tc, outputs_do_not_change_the_solution);
  tcase_add_test(tc, rubber_rings);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
