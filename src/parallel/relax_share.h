/* The transport of a relaxation built per MPI rank (issue 20): each rank
 * holds a contiguous slice of a body's points (creation indices), finds
 * the other ranks' points within a reach of its own (ghosts, with their
 * creation indices), refreshes their positions, reduces bounds and maxima,
 * and streams every rank's points to every rank in rank order (creation
 * order) without any rank storing them all. geometry.c's relaxation drives
 * it; with one rank (no MPI, or no launcher) there are no ghosts and the
 * reductions return their input. */
#ifndef SPH_RELAX_SHARE_H
#define SPH_RELAX_SHARE_H

#include <stddef.h>
#include <stdint.h>

#include "sph/status.h"

typedef struct sph_relax_share sph_relax_share;

sph_status sph_relax_share_create(sph_relax_share **out, sph_error *err);
void sph_relax_share_destroy(sph_relax_share *h);

/* lo[c] and hi[c] (c < dim): the smallest and largest over the ranks
 * (collective) */
void sph_relax_share_bounds(double lo[3], double hi[3], int dim);
/* the largest v over the ranks (collective) */
double sph_relax_share_max(double v);

/* The points of the other ranks within `reach` of this rank's n points x
 * (3 per point, creation indices first .. first + n - 1) in each of the dim
 * axes (a superset of those closer than reach), with the send plan that
 * sph_relax_share_refresh follows (collective). */
sph_status sph_relax_share_ghosts(sph_relax_share *h, const double *x, size_t n,
                                  int64_t first, int dim, double reach,
                                  sph_error *err);
/* the ghosts' positions again from the owners' x (collective) */
sph_status sph_relax_share_refresh(sph_relax_share *h, const double *x,
                                   sph_error *err);
size_t sph_relax_share_count(const sph_relax_share *h);
const double *sph_relax_share_x(const sph_relax_share *h);
const int64_t *sph_relax_share_id(const sph_relax_share *h);

/* fn over every rank's points in rank order, a chunk at a time (x, 3 per
 * point, count of them), on every rank (collective: after fn's first
 * error the rank goes on receiving, without calling fn, and returns it) */
typedef sph_status (*sph_relax_share_fn)(void *ctx, const double *x,
                                         size_t count, sph_error *err);
sph_status sph_relax_share_stream(const double *x, size_t n,
                                  sph_relax_share_fn fn, void *ctx,
                                  sph_error *err);

#endif
