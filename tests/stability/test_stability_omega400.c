/* The peer's extreme twist (docs/benchmarks.md A3, issue 14 item 4a): the A1
 * column at Omega = 400 rad/s on SPHinXsys' lattice (10 x 61 x 10) with
 * seed 004's method (scenes/twisting_column_bond.yaml), to the peer's end
 * time 0.5 s: stable, no inversion, the energy never above its start.
 * Coarser lattices fail (docs/results.md: 7 x 37 x 7 at 0.108 s, 9 x 49 x 9
 * at 0.0797 s), so this is the smallest case that means something; about
 * 4.5 minutes on one thread. It runs tl-bond as seed 004 prints it (eq. 22's
 * force, eq. 28's JST): the defaults that hold a body at rest (issue 35,
 * docs/results.md) trip the zig-zag indicator here at 0.4325 s (roughness
 * 0.541, J min 0.269), an open defect, not a tolerance to move. */
#include "stability_run.h"

START_TEST(twisting_column_omega_400) {
  const char *sets[] = {"bodies.0.initial_velocity.rotation.omega=400",
                        "bodies.0.particles.count=[10,61,10]", "time.end=0.5",
                        "method.force=symmetric", "method.jst.outer=symmetric"};
  outcome o = run_case("twisting_column_bond", sets, 5, 0.0025, NULL, NULL);
  show("A3 tl-bond Omega 400 10x61x10", &o, NULL);
  ck_assert_msg(o.stable, "%s", o.reason);
  ck_assert_msg(o.t >= 0.5 * (1 - 1e-12), "reached %g s", o.t);
  ck_assert_msg(o.j_min > 0.3, "J min %g", o.j_min);
  ck_assert_msg(o.e_max <= o.e0 * 1.0001, "energy %g above %g", o.e_max, o.e0);
}
END_TEST

int main(void) {
  Suite *s = suite_create("stability_omega400");
  TCase *tc = tcase_create("omega 400");
  tcase_set_timeout(tc, 1800);
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, twisting_column_omega_400);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
