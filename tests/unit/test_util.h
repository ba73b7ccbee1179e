/* Shared helpers for the Check suites: floating-point traps and a runner. */
#ifndef SPH_TEST_UTIL_H
#define SPH_TEST_UTIL_H

#include <check.h>
#include <fenv.h>
#include <stdlib.h>

/* Traps division by zero, invalid operations and overflow in numerical
 * tests, so a NaN or Inf produced anywhere stops the test where it appears. */
static inline void sph_test_enable_fp_traps(void) {
  feenableexcept(FE_DIVBYZERO | FE_INVALID | FE_OVERFLOW);
}

/* Runs one suite and returns the process exit status. */
static inline int sph_test_run(Suite *s) {
  SRunner *sr = srunner_create(s);
  srunner_run_all(sr, CK_NORMAL);
  int failed = srunner_ntests_failed(sr);
  srunner_free(sr);
  return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}

#endif
