/* The stability verdict's scalars as a checkpoint restores them
 * (src/io/checkpoint.c): a CRC-valid file may still hold any bytes, so
 * counts and flags are checked before the verdict uses them (issue 36
 * item 8: frames + 1 overflowed at the next observation). */
#include <limits.h>
#include <math.h>

#include "solver/stability.h"

sph_status sph_verdict_check_restored(const sph_verdict *v, sph_error *err) {
  int flags = (v->stable == 0 || v->stable == 1) &&
              (v->nan == 0 || v->nan == 1) &&
              (v->energy_tracked == 0 || v->energy_tracked == 1);
  if (!flags)
    return sph_error_set(err, SPH_ERR_IO,
                         "verdict flags %d, %d, %d are not 0 or 1", v->stable,
                         v->nan, v->energy_tracked);
  if (v->frames < 0 || v->frames > INT_MAX / 2)
    return sph_error_set(err, SPH_ERR_IO, "verdict of %d frames", v->frames);
  if (v->fracture_pairs_over < 0 || v->fracture_peak_over < 0 ||
      v->fracture_pairs_over > LONG_MAX / 2 ||
      v->fracture_peak_over > LONG_MAX / 2)
    return sph_error_set(err, SPH_ERR_IO, "verdict of %ld and %ld pairs",
                         v->fracture_pairs_over, v->fracture_peak_over);
  return SPH_OK;
}
