/* Prints the sizes and field offsets of the public API's structures as
 * JSON, for tests/python/test_layout.py to compare with the ctypes mirror
 * in python/sph/_capi.py. */
#include <stddef.h>
#include <stdio.h>

#include "sph/sph.h"

#define FIELD(type, f) printf(", \"%s\": %zu", #f, offsetof(type, f))

int main(void) {
  printf("{\"sph_error\": {\"size\": %zu", sizeof(sph_error));
  FIELD(sph_error, code);
  FIELD(sph_error, file);
  FIELD(sph_error, line);
  FIELD(sph_error, col);
  FIELD(sph_error, key);
  FIELD(sph_error, message);
  printf("},\n \"sph_run_options\": {\"size\": %zu", sizeof(sph_run_options));
  FIELD(sph_run_options, out_dir);
  FIELD(sph_run_options, overwrite);
  FIELD(sph_run_options, resume);
  FIELD(sph_run_options, threads);
  FIELD(sph_run_options, quiet);
  FIELD(sph_run_options, stop);
  FIELD(sph_run_options, no_files);
  printf("},\n \"sph_summary\": {\"size\": %zu", sizeof(sph_summary));
  FIELD(sph_summary, state);
  FIELD(sph_summary, t);
  FIELD(sph_summary, steps);
  FIELD(sph_summary, wall);
  FIELD(sph_summary, particle_steps);
  FIELD(sph_summary, verdict);
  FIELD(sph_summary, method);
  FIELD(sph_summary, reference);
  FIELD(sph_summary, out_dir);
  printf("},\n \"enum\": %zu, \"state_count\": %d}\n", sizeof(sph_run_state),
         (int)SPH_RUN_FAILED + 1);
  return 0;
}
