/* Frames of a run over MPI ranks drawn by sort-last rendering (issue 20):
 * every rank draws its own particles with the frame's camera into colour
 * and tag images (the layer, window depth and serial draw index of the
 * fragment that won each pixel), and the images are composited by depth
 * onto rank 0, as ParaView/IceT do; the frame-wide numbers (bounding boxes,
 * counts, the colour range's percentiles) are reductions over the ranks
 * that give the serial values. No rank holds the whole particle set.
 *
 * Without a domain (NULL: a serial run) every call works on this rank's
 * values alone. */
#ifndef SPH_COMPOSITE_H
#define SPH_COMPOSITE_H

#include <stddef.h>
#include <stdint.h>

#include "parallel/domain.h"
#include "sph/status.h"

/* One composited pixel: the layer (1-based, 0: no fragment), the window
 * depth's float bits, the serial draw index and the colour (RGBA, bytes in
 * memory order) of the fragment that won it. */
typedef struct sph_composite_px {
  uint32_t layer, depth, key, rgba;
} sph_composite_px;

/* Whether fragment a wins over b: a later layer, then the smaller depth,
 * then the lower draw index (the first drawn wins a depth tie, as GL's
 * strict depth test). */
static inline int sph_composite_wins(const sph_composite_px *a,
                                     const sph_composite_px *b) {
  if (a->layer != b->layer)
    return a->layer > b->layer;
  if (a->depth != b->depth)
    return a->depth < b->depth;
  return a->key < b->key;
}

/* Rank 0 receives into out, per pixel of npix, the winner over every
 * rank's px (collective; out is unused elsewhere; a copy for NULL). */
sph_status sph_composite_reduce(sph_domain *d, const sph_composite_px *px,
                                size_t npix, sph_composite_px *out,
                                sph_error *err);

/* Sums of count unsigned integers over the ranks (collective, exact). */
void sph_composite_sum_u64(sph_domain *d, uint64_t *v, int count);

/* The k[i]-th smallest (0-based) of the finite values of v[0 .. n) over
 * every rank, i < nk (nk <= 4), into out[i] (collective): radix selection
 * over the values' order-preserving 64-bit keys, one byte a round and one
 * histogram reduction a round, so the result is the serial selection's
 * (-0 counts as +0). k[i] must be below the number of finite values. */
void sph_composite_select(sph_domain *d, const double *v, size_t n,
                          const uint64_t *k, int nk, double *out);

#endif
