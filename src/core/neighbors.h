/* Neighbour search with cell lists into compact CSR lists.
 *
 * Cells have the size of the search radius; the list of particle a is
 * index[offset[a] .. offset[a+1]) and holds every b != a with
 * |x_a - x_b| < radius (strictly), in ascending index order, so a build is
 * deterministic for any thread count. Total-Lagrangian methods build once in
 * the reference configuration; updated methods rebuild into the same object,
 * which grows its buffers only when a rebuild needs more room. */
#ifndef SPH_NEIGHBORS_H
#define SPH_NEIGHBORS_H

#include <stddef.h>
#include <stdint.h>

#include "sph/status.h"

typedef struct sph_neighbors {
  size_t n;          /* particles listed */
  size_t count;      /* total pairs (directed: a->b and b->a both listed) */
  size_t *offset;    /* n + 1 entries */
  int32_t *index;    /* count entries */
  size_t capacity_n; /* allocated offset entries - 1 */
  size_t capacity;   /* allocated index entries */
  /* cell-list work space, reused between builds */
  size_t ncell_alloc;
  size_t *cell_start;
  int32_t *cell_particles;
  int32_t *particle_cell;
  size_t np_alloc;
} sph_neighbors;

/* Which pairs are kept. */
typedef enum sph_pair_filter {
  SPH_PAIRS_ALL = 0,       /* every pair within the radius */
  SPH_PAIRS_SAME_BODY = 1, /* only pairs with body[a] == body[b] */
  SPH_PAIRS_OTHER_BODY = 2 /* only pairs with body[a] != body[b] (contact) */
} sph_pair_filter;

sph_status sph_neighbors_create(sph_neighbors **out, sph_error *err);
void sph_neighbors_destroy(sph_neighbors *nl);

/* Builds the lists for n points x[3*i + c] in `dim` dimensions (components
 * beyond dim are ignored). `body` may be NULL when filter is ALL. */
sph_status sph_neighbors_build(sph_neighbors *nl, const double *x, size_t n,
                               int dim, double radius, const int32_t *body,
                               sph_pair_filter filter, sph_error *err);

/* The cell grid sph_neighbors_build lays over n points whose coordinates
 * c < dim span [lo[c], hi[c]]: cells of at least `radius` (grown while
 * there would be more than 8 a point and 64), nc[c] of them along axis c
 * from lo; returns the cell size. */
double sph_neighbors_grid(const double lo[3], const double hi[3], size_t n,
                          int dim, double radius, long nc[3]);

/* Whether nl keeps the contract above for points x (dim, radius): every
 * index in [0, n) and not the particle's own, each list strictly ascending,
 * every neighbour closer than radius, and the lists symmetric (b in a's
 * list exactly when a is in b's). SPH_ERR_INTERNAL naming the first
 * particle and pair that break it. O(N k log k) for k neighbours; run after
 * every build with SPH_DEBUG_CHECKS (core/check.h). */
sph_status sph_neighbors_check(const sph_neighbors *nl, const double *x,
                               int dim, double radius, sph_error *err);

/* Reference O(N^2) search with the same contract (tests, debug checks). */
sph_status sph_neighbors_build_brute(sph_neighbors *nl, const double *x,
                                     size_t n, int dim, double radius,
                                     const int32_t *body,
                                     sph_pair_filter filter, sph_error *err);

#endif
