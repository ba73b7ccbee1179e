/* What the whole particle set (build.c) and one rank's share (share.c)
 * share: the checks made particle by particle and their errors, a
 * particle's state from its body, the overlap check. */
#ifndef SPH_BUILD_IMPL_H
#define SPH_BUILD_IMPL_H

#include <stddef.h>
#include <stdint.h>

#include "scene/scene.h"
#include "sph/status.h"

/* What the set-up checks particle by particle, in creation order: the first
 * particle with a non-finite initial velocity, the first beyond where
 * doubles resolve the spacing, the selections and probes each reaches, the
 * first wall with a particle behind it. Shared by the whole set and the
 * per-rank share (which sees every particle once in its first pass). */
typedef struct build_checks {
  int velocity, resolvable; /* found (the error in *_err) */
  sph_error velocity_err, resolvable_err;
  char *hit;    /* per boundary: selects a particle */
  char *inside; /* per probe: within a spacing of a particle */
  size_t wall;  /* lowest wall with a particle behind it (nwalls: none) */
  sph_error wall_err;
} build_checks;

sph_status sph_build_checks_create(const sph_scene *s, build_checks *c,
                                   sph_error *err);
void sph_build_checks_destroy(build_checks *c);

/* The particle of body b at Xb (body frame): its world position X, initial
 * velocity v (world frame) and flags, the checks updated when c is given. */
void sph_build_particle_state(const sph_scene *s, size_t b, const double Xb[3],
                              double X[3], double v[3], uint32_t *flags,
                              build_checks *c);

/* The checks' first failure in the serial order: velocities, positions. */
sph_status sph_build_checks_first(const build_checks *c, sph_error *err);

/* Then selections, probes and walls. */
sph_status sph_build_checks_rest(const sph_scene *s, const build_checks *c,
                                 sph_error *err);

/* A body's generation error at its key. */
sph_status sph_build_body_error(const sph_scene *s, size_t b, sph_status st,
                                sph_error *err);

/* The first of the n points X (bodies, in creation order) that `check`
 * marks with a point of another body closer than dp / 2, and the first
 * such point: as an error, *first its index (n: none). */
sph_status sph_build_find_overlap(const sph_scene *s, const double *X,
                                  const int32_t *body, const char *check,
                                  size_t n, size_t *first, sph_error *err);

#endif
