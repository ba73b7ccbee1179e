/* Assertions on the library's own invariants (two tiers; issue 37).
 *
 * SPH_CHECK(cond, err, fmt, ...): always compiled, for cheap checks (O(1),
 *   or once per set-up or neighbour build). A false cond fills err with
 *   SPH_ERR_INTERNAL, "file:line:" of the check and the message, and returns
 *   SPH_ERR_INTERNAL from the calling function (sph exits 3).
 * SPH_DEBUG_CHECK(cond, ...), SPH_DEBUG_TRY(expr): the same and SPH_TRY,
 *   compiled only with SPH_DEBUG_CHECKS (cmake -DSPH_DEBUG_CHECKS=ON), for
 *   scans of O(N) or O(N neighbours) per call; else nothing is evaluated.
 * A check only reads: it never changes a number. The library never aborts
 * or prints; a failed check is an error record like any other. */
#ifndef SPH_CHECK_H
#define SPH_CHECK_H

#include "sph/status.h"

/* Fills err with `code`, the message prefixed by "file:line: " (file from
 * its src/ folder on) and returns code. */
sph_status sph_check_failed(sph_error *err, sph_status code, const char *file,
                            int line, const char *fmt, ...)
    __attribute__((format(printf, 5, 6), cold));

/* As SPH_CHECK with another status (a non-finite value: SPH_ERR_NUMERIC). */
#define SPH_CHECK_AS(code, cond, err, ...)                                     \
  do {                                                                         \
    if (__builtin_expect(!(cond), 0))                                          \
      return sph_check_failed((err), (code), __FILE__, __LINE__, __VA_ARGS__); \
  } while (0)

#define SPH_CHECK(cond, err, ...)                                              \
  SPH_CHECK_AS(SPH_ERR_INTERNAL, cond, err, __VA_ARGS__)

#if defined(SPH_DEBUG_CHECKS) && SPH_DEBUG_CHECKS
#define SPH_DEBUG_CHECKS_ON 1
#else
#define SPH_DEBUG_CHECKS_ON 0
#endif

/* compiled (so type-checked) in every build, dead code without the option */
#define SPH_DEBUG_CHECK(cond, err, ...)                                        \
  do {                                                                         \
    if (SPH_DEBUG_CHECKS_ON)                                                   \
      SPH_CHECK(cond, err, __VA_ARGS__);                                       \
  } while (0)
#define SPH_DEBUG_TRY(expr)                                                    \
  do {                                                                         \
    if (SPH_DEBUG_CHECKS_ON)                                                   \
      SPH_TRY(expr);                                                           \
  } while (0)

#endif
