/* Sort-last compositing and the frame-wide reductions of frames drawn per
 * rank (issue 20; sph/composite.h): a depth composite of the ranks' tagged
 * images onto rank 0 by a user reduction operator (MPI_Reduce), minimum and
 * maximum reductions, and the exact k-th smallest value over the ranks by
 * radix selection (one byte of the values' ordered keys a round, the
 * histogram summed over the ranks, as sph_domain_rcb_counted bisects
 * coordinates by counting). Without MPI, or without a domain, each call
 * works on this rank's values alone. */
#include "parallel/composite.h"

#include <math.h>
#include <string.h>

#include "parallel/domain_impl.h"

#ifdef SPH_HAVE_MPI
#include <mpi.h>

/* the reduction operator: inout[i] becomes the winner of in[i], inout[i] */
static void composite_op(void *in, void *inout, int *len, MPI_Datatype *t) {
  (void)t;
  const sph_composite_px *a = in;
  sph_composite_px *b = inout;
  for (int i = 0; i < *len; ++i)
    if (sph_composite_wins(&a[i], &b[i]))
      b[i] = a[i];
}
#endif

sph_status sph_composite_reduce(sph_domain *d, const sph_composite_px *px,
                                size_t npix, sph_composite_px *out,
                                sph_error *err) {
#ifdef SPH_HAVE_MPI
  if (d) {
    if (npix > (size_t)INT32_MAX)
      return sph_error_set(err, SPH_ERR_RANGE, "composite: %zu pixels", npix);
    double t0 = MPI_Wtime();
    MPI_Datatype type;
    MPI_Op op;
    MPI_Type_contiguous(4, MPI_UINT32_T, &type);
    MPI_Type_commit(&type);
    MPI_Op_create(composite_op, 1, &op);
    int rc = MPI_Reduce(px, d->rank == 0 ? out : NULL, (int)npix, type, op, 0,
                        MPI_COMM_WORLD);
    MPI_Op_free(&op);
    MPI_Type_free(&type);
    d->seconds += MPI_Wtime() - t0;
    if (rc != MPI_SUCCESS)
      return sph_error_set(err, SPH_ERR_IO, "composite: MPI_Reduce failed");
    return SPH_OK;
  }
#endif
  (void)d, (void)err;
  memcpy(out, px, npix * sizeof *px);
  return SPH_OK;
}

void sph_composite_sum_u64(sph_domain *d, uint64_t *v, int count) {
#ifdef SPH_HAVE_MPI
  if (d && count > 0) {
    double t0 = MPI_Wtime();
    MPI_Allreduce(MPI_IN_PLACE, v, count, MPI_UINT64_T, MPI_SUM,
                  MPI_COMM_WORLD);
    d->seconds += MPI_Wtime() - t0;
  }
#endif
  (void)d, (void)v, (void)count;
}

/* order-preserving key of a double (-0 as +0), and back */
static uint64_t value_key(double v) {
  uint64_t b;
  v = v == 0.0 ? 0.0 : v;
  memcpy(&b, &v, sizeof b);
  return b >> 63 ? ~b : b | (1ull << 63);
}

static double key_value(uint64_t k) {
  uint64_t b = k >> 63 ? k & ~(1ull << 63) : ~k;
  double v;
  memcpy(&v, &b, sizeof v);
  return v;
}

void sph_composite_select(sph_domain *d, const double *v, size_t n,
                          const uint64_t *k, int nk, double *out) {
  enum { RADIX = 256 };
  uint64_t prefix[4] = {0}, rank[4], h[4 * RADIX];
  nk = nk < 4 ? nk : 4;
  for (int t = 0; t < nk; ++t)
    rank[t] = k[t];
  /* one byte a round, from the most significant */
  for (int shift = 56; shift >= 0; shift -= 8) {
    memset(h, 0, sizeof h);
    for (size_t i = 0; i < n; ++i) {
      if (!isfinite(v[i]))
        continue;
      uint64_t key = value_key(v[i]);
      for (int t = 0; t < nk; ++t)
        if (shift == 56 || key >> (shift + 8) == prefix[t] >> (shift + 8))
          h[t * RADIX + (key >> shift & 0xff)]++;
    }
    sph_composite_sum_u64(d, h, nk * RADIX);
    /* the byte whose bin holds the wanted rank */
    for (int t = 0; t < nk; ++t) {
      const uint64_t *ht = h + t * RADIX;
      int b = 0;
      while (b < RADIX - 1 && rank[t] >= ht[b])
        rank[t] -= ht[b++];
      prefix[t] |= (uint64_t)b << shift;
    }
  }
  for (int t = 0; t < nk; ++t)
    out[t] = key_value(prefix[t]);
}
