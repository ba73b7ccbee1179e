/* The transport of a relaxation built per MPI rank (issue 20,
 * sph/relax_share.h): ghosts from the other ranks' boxes widened by the search
 * reach (MPI_Allgather of the boxes, MPI_Alltoallv of the points), their
 * positions refreshed along the same plan, min/max reductions, and every
 * rank's points broadcast in chunks in rank order. Without MPI (or a
 * launcher): one rank, no ghosts. */
#include "parallel/relax_share.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "parallel/domain.h"

#ifdef SPH_HAVE_MPI
#include <mpi.h>
#endif

/* points a broadcast carries at most */
#define STREAM_CHUNK 65536

struct sph_relax_share {
  size_t ng;    /* ghosts */
  double *gx;   /* their positions, grouped by owner rank */
  int64_t *gid; /* their creation indices */
  int *count;   /* 4 per rank: points sent, received, their offsets */
  int32_t *send;
  size_t nsend;
  double *buf; /* 3 per sent point */
};

sph_status sph_relax_share_create(sph_relax_share **out, sph_error *err) {
  *out = calloc(1, sizeof **out);
  int R = sph_domain_world_size();
  if (*out && !((*out)->count = calloc(4 * (size_t)R, sizeof(int)))) {
    free(*out);
    *out = NULL;
  }
  return sph_domain_world_agree(
      *out ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "relaxation halo"),
      err);
}

void sph_relax_share_destroy(sph_relax_share *h) {
  if (!h)
    return;
  free(h->gx);
  free(h->gid);
  free(h->count);
  free(h->send);
  free(h->buf);
  free(h);
}

size_t sph_relax_share_count(const sph_relax_share *h) { return h->ng; }
const double *sph_relax_share_x(const sph_relax_share *h) { return h->gx; }
const int64_t *sph_relax_share_id(const sph_relax_share *h) { return h->gid; }

#ifdef SPH_HAVE_MPI

void sph_relax_share_bounds(double lo[3], double hi[3], int dim) {
  if (sph_domain_world_size() < 2)
    return;
  MPI_Allreduce(MPI_IN_PLACE, lo, dim, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, hi, dim, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
}

double sph_relax_share_max(double v) {
  if (sph_domain_world_size() > 1)
    MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return v;
}

typedef struct ghost_rec {
  double x[3];
  int64_t id;
} ghost_rec;

/* whether X lies within w of the box (lo, hi) in the dim axes */
static int near_box(const double *X, const double *box, int dim, double w) {
  for (int c = 0; c < dim; ++c)
    if (!(X[c] >= box[c] - w && X[c] <= box[3 + c] + w))
      return 0;
  return 1;
}

sph_status sph_relax_share_ghosts(sph_relax_share *h, const double *x, size_t n,
                                  int64_t first, int dim, double reach,
                                  sph_error *err) {
  int R = sph_domain_world_size(), me = sph_domain_world_rank();
  if (R < 2)
    return SPH_OK;
  int *scount = h->count, *rcount = scount + R, *soff = scount + 2 * R,
      *roff = scount + 3 * R;
  /* this rank's box, then every rank's */
  double *box = malloc(6 * (size_t)R * sizeof *box);
  sph_status st = sph_domain_world_agree(
      box ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "relaxation halo"), err);
  if (st != SPH_OK) {
    free(box);
    return st;
  }
  double mine[6] = {0, 0, 0, 0, 0, 0};
  for (int c = 0; c < dim; ++c) {
    mine[c] = n ? x[c] : INFINITY;
    mine[3 + c] = n ? x[c] : -INFINITY; /* empty: a box nothing is near */
  }
  for (size_t i = 1; i < n; ++i)
    for (int c = 0; c < dim; ++c) {
      double v = x[3 * i + c];
      mine[c] = v < mine[c] ? v : mine[c];
      mine[3 + c] = v > mine[3 + c] ? v : mine[3 + c];
    }
  MPI_Allgather(mine, 6, MPI_DOUBLE, box, 6, MPI_DOUBLE, MPI_COMM_WORLD);
  /* the points near another rank's box, grouped by that rank; the margin
   * covers the rounding of a distance just below the reach */
  double w = reach * (1.0 + 1e-9);
  size_t total = 0;
  for (int q = 0; q < R; ++q) {
    scount[q] = 0;
    for (size_t i = 0; q != me && i < n; ++i)
      scount[q] += near_box(x + 3 * i, box + 6 * q, dim, w);
    total += (size_t)scount[q];
  }
  free(h->send);
  free(h->buf);
  h->send = malloc((total ? total : 1) * sizeof *h->send);
  h->buf = malloc(3 * (total ? total : 1) * sizeof *h->buf);
  ghost_rec *out = malloc((total ? total : 1) * sizeof *out);
  h->nsend = total;
  st = sph_domain_world_agree(
      h->send && h->buf && out
          ? SPH_OK
          : sph_error_set(err, SPH_ERR_NOMEM, "relaxation halo (%zu)", total),
      err);
  for (int q = 0, k = 0; st == SPH_OK && q < R; ++q) {
    soff[q] = k;
    for (size_t i = 0; q != me && i < n; ++i)
      if (near_box(x + 3 * i, box + 6 * q, dim, w)) {
        h->send[k] = (int32_t)i;
        memcpy(out[k].x, x + 3 * i, sizeof out->x);
        out[k++].id = first + (int64_t)i;
      }
  }
  free(box);
  if (st == SPH_OK)
    MPI_Alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, MPI_COMM_WORLD);
  size_t ng = 0;
  for (int q = 0; st == SPH_OK && q < R; ++q) {
    roff[q] = (int)ng;
    ng += (size_t)rcount[q];
  }
  ghost_rec *in = NULL;
  if (st == SPH_OK) {
    free(h->gx);
    free(h->gid);
    h->gx = malloc(3 * (ng ? ng : 1) * sizeof *h->gx);
    h->gid = malloc((ng ? ng : 1) * sizeof *h->gid);
    in = malloc((ng ? ng : 1) * sizeof *in);
    st = sph_domain_world_agree(
        h->gx && h->gid && in
            ? SPH_OK
            : sph_error_set(err, SPH_ERR_NOMEM, "relaxation ghosts (%zu)", ng),
        err);
  }
  if (st == SPH_OK) {
    MPI_Datatype type;
    MPI_Type_contiguous((int)sizeof(ghost_rec), MPI_BYTE, &type);
    MPI_Type_commit(&type);
    MPI_Alltoallv(out, scount, soff, type, in, rcount, roff, type,
                  MPI_COMM_WORLD);
    MPI_Type_free(&type);
    h->ng = ng;
    for (size_t j = 0; j < ng; ++j) {
      memcpy(h->gx + 3 * j, in[j].x, sizeof in->x);
      h->gid[j] = in[j].id;
    }
  }
  free(out);
  free(in);
  return st;
}

sph_status sph_relax_share_refresh(sph_relax_share *h, const double *x,
                                   sph_error *err) {
  int R = sph_domain_world_size();
  if (R < 2)
    return SPH_OK;
  for (size_t k = 0; k < h->nsend; ++k)
    memcpy(h->buf + 3 * k, x + 3 * (size_t)h->send[k], 3 * sizeof *x);
  /* three doubles a point */
  int *c3 = malloc(4 * (size_t)R * sizeof *c3);
  sph_status st = sph_domain_world_agree(
      c3 ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "relaxation halo"), err);
  if (st != SPH_OK) {
    free(c3);
    return st;
  }
  for (int i = 0; i < 4 * R; ++i)
    c3[i] = 3 * h->count[i];
  MPI_Alltoallv(h->buf, c3, c3 + 2 * R, MPI_DOUBLE, h->gx, c3 + R, c3 + 3 * R,
                MPI_DOUBLE, MPI_COMM_WORLD);
  free(c3);
  return SPH_OK;
}

sph_status sph_relax_share_stream(const double *x, size_t n,
                                  sph_relax_share_fn fn, void *ctx,
                                  sph_error *err) {
  int R = sph_domain_world_size(), me = sph_domain_world_rank();
  if (R < 2)
    return fn(ctx, x, n, err);
  uint64_t *counts = malloc((size_t)R * sizeof *counts);
  double *buf = malloc(3 * STREAM_CHUNK * sizeof *buf);
  sph_status st = sph_domain_world_agree(
      counts && buf ? SPH_OK
                    : sph_error_set(err, SPH_ERR_NOMEM, "relaxed points"),
      err);
  if (st == SPH_OK) {
    uint64_t mine = n;
    MPI_Allgather(&mine, 1, MPI_UINT64_T, counts, 1, MPI_UINT64_T,
                  MPI_COMM_WORLD);
  }
  sph_status bad = SPH_OK;
  for (int q = 0; st == SPH_OK && q < R; ++q)
    for (uint64_t at = 0; at < counts[q]; at += STREAM_CHUNK) {
      size_t len = (size_t)(counts[q] - at < STREAM_CHUNK ? counts[q] - at
                                                          : STREAM_CHUNK);
      if (q == me)
        memcpy(buf, x + 3 * at, 3 * len * sizeof *buf);
      MPI_Bcast(buf, (int)(3 * len), MPI_DOUBLE, q, MPI_COMM_WORLD);
      if (bad == SPH_OK)
        bad = fn(ctx, buf, len, err);
    }
  free(counts);
  free(buf);
  return st != SPH_OK ? st : bad;
}

#else /* without MPI: one rank */

void sph_relax_share_bounds(double lo[3], double hi[3], int dim) {
  (void)lo, (void)hi, (void)dim;
}

double sph_relax_share_max(double v) { return v; }

sph_status sph_relax_share_ghosts(sph_relax_share *h, const double *x, size_t n,
                                  int64_t first, int dim, double reach,
                                  sph_error *err) {
  (void)h, (void)x, (void)n, (void)first, (void)dim, (void)reach, (void)err;
  return SPH_OK;
}

sph_status sph_relax_share_refresh(sph_relax_share *h, const double *x,
                                   sph_error *err) {
  (void)h, (void)x, (void)err;
  return SPH_OK;
}

sph_status sph_relax_share_stream(const double *x, size_t n,
                                  sph_relax_share_fn fn, void *ctx,
                                  sph_error *err) {
  return fn(ctx, x, n, err);
}

#endif
