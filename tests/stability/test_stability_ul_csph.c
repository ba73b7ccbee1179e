/* ul-csph against tl-csph on seed 001's cases: the 1D bar of sec. 3.3.1
 * (standard updated formulation breaks, the stabilised one stays close to
 * the total-Lagrangian run) and the punch of sec. 2.4.3 / 4.3 (what is
 * measured, which is not the paper's clear-cut outcome: docs/results.md). */
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
   * first (measured 5e-5 s against 9e-5 s) */
  ck_assert(!otl.stable && otl.first == SPH_INDICATOR_ZIGZAG);
  ck_assert(!oul.stable && oul.first == SPH_INDICATOR_ZIGZAG);
  ck_assert_double_lt(otl.t_tripped, oul.t_tripped);
  /* judged on nan and J only both reach 54 % of the height; the updated
   * run keeps the smallest J higher (measured 0.162 against 0.107) */
  ck_assert_msg(atl.stable && aul.stable, "%s / %s", atl.reason, aul.reason);
  ck_assert_double_gt(aul.j_min, 1.3 * atl.j_min);
}
END_TEST

int main(void) {
  Suite *s = suite_create("stability_ul_csph");
  TCase *tc = tcase_create("seed 001");
  tcase_set_timeout(tc, 900);
  tcase_add_test(tc, bar_standard_breaks_stabilised_follows_tl);
  tcase_add_test(tc, punch_measured);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
