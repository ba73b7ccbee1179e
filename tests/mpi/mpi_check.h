/* Runs a Check suite under mpirun: one process a rank (no fork), rank 0
 * reporting; MPI finalised after. The exit status of the test program. */
#ifndef SPH_TEST_MPI_CHECK_H
#define SPH_TEST_MPI_CHECK_H

#include <check.h>
#include <stdlib.h>

#include "parallel/domain.h"

static inline int sph_mpi_check_run(Suite *s) {
  SRunner *sr = srunner_create(s);
  srunner_set_fork_status(sr, CK_NOFORK);
  srunner_run_all(sr, sph_domain_world_rank() == 0 ? CK_NORMAL : CK_SILENT);
  int failed = srunner_ntests_failed(sr);
  srunner_free(sr);
  sph_domain_finalize();
  return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}

#endif
