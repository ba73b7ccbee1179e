/* The domain's communication (issue 20): the fixed halo exchange with
 * MPI_Irecv/MPI_Isend, reductions in rank order, agreement on a status,
 * the gathers of rows by storage index and the lists' serial order. */
#include "parallel/domain.h"
#include "parallel/domain_impl.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifdef SPH_HAVE_MPI
#include <mpi.h>
#endif

/* rows of w doubles placed at their storage index less lo */
static void place_rows(double *out, const int64_t *key, const double *rows,
                       size_t n, int w, int64_t lo) {
  for (size_t i = 0; i < n; ++i)
    memcpy(out + (size_t)w * (size_t)(key[i] - lo), rows + (size_t)w * i,
           (size_t)w * sizeof *out);
}

#ifdef SPH_HAVE_MPI

/* OpenMPI's blocking calls poll: on a shared machine a waiting rank takes
 * the core its partner (or other work) needs, and 2 ranks ran 7-10x slower
 * than one (issue 36). The per-step waits poll for about 50 us, then sleep
 * 50 us between polls: a sleeping rank leaves its core. */
int sph_domain_wait(int n, void *req) {
  static int spin = -1;
  if (spin < 0) {
    const char *w = getenv("SPH_MPI_WAIT");
    spin = w && strcmp(w, "spin") == 0;
  }
  const struct timespec nap = {0, 50000};
  double t0 = -1.0;
  for (;;) {
    int done = 0,
        rc = MPI_Testall(n, (MPI_Request *)req, &done, MPI_STATUSES_IGNORE);
    if (rc != MPI_SUCCESS || done)
      return rc;
    if (spin)
      continue;
    double t = MPI_Wtime();
    if (t0 < 0.0)
      t0 = t;
    else if (t - t0 > 50e-6)
      nanosleep(&nap, NULL);
  }
}

/* MPI_Allreduce and MPI_Allgather with that wait (for MIN, MAX and
 * gathers: the same values as the blocking calls) */
static void allreduce(const void *in, void *out, int n, MPI_Datatype type,
                      MPI_Op op) {
  MPI_Request r;
  MPI_Iallreduce(in, out, n, type, op, MPI_COMM_WORLD, &r);
  sph_domain_wait(1, &r);
}

static void allgather(const void *in, int n, MPI_Datatype type, void *out) {
  MPI_Request r;
  MPI_Iallgather(in, n, type, out, n, type, MPI_COMM_WORLD, &r);
  sph_domain_wait(1, &r);
}

sph_status sph_domain_world_agree(sph_status st, sph_error *err) {
  return sph_domain_world_first(st, INT64_MAX, err);
}

sph_status sph_domain_world_first(sph_status st, int64_t key, sph_error *err) {
  if (sph_domain_world_size() < 2)
    return st;
  /* the failing rank of the lowest key, then of the lowest rank */
  int64_t mine[2] = {st != SPH_OK ? key : INT64_MAX,
                     st != SPH_OK ? sph_domain_world_rank()
                                  : sph_domain_world_size()},
          low[2];
  allreduce(mine, low, 1, MPI_INT64_T, MPI_MIN);
  if (mine[0] != low[0])
    mine[1] = sph_domain_world_size();
  allreduce(mine + 1, low + 1, 1, MPI_INT64_T, MPI_MIN);
  if (low[1] == sph_domain_world_size())
    return SPH_OK;
  sph_error e;
  if (low[1] == sph_domain_world_rank())
    e = *err;
  MPI_Bcast(&e, (int)sizeof e, MPI_BYTE, (int)low[1], MPI_COMM_WORLD);
  *err = e;
  return e.code != SPH_OK ? e.code : SPH_ERR_IO;
}

int sph_domain_node_size(void) {
  if (sph_domain_world_size() < 2)
    return 1;
  MPI_Comm node;
  int n = 1;
  if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED,
                          sph_domain_world_rank(), MPI_INFO_NULL,
                          &node) != MPI_SUCCESS)
    return sph_domain_world_size();
  MPI_Comm_size(node, &n);
  MPI_Comm_free(&node);
  return n;
}

sph_status sph_domain_exchange(sph_domain *d, double *field, int ncomp,
                               sph_error *err) {
  if (!d)
    return SPH_OK;
  double t0 = MPI_Wtime();
  MPI_Request *req = d->req;
  int nr = 0;
  size_t nc = (size_t)ncomp, base = d->base ? d->base : d->n;
  for (int q = 0; q < d->size; ++q)
    if (d->recv_count[q])
      MPI_Irecv(field + nc * (base + (size_t)d->recv_off[q]),
                ncomp * d->recv_count[q], MPI_DOUBLE, q, 7, MPI_COMM_WORLD,
                &req[nr++]);
  long ns = (long)d->nsend;
#pragma omp parallel for schedule(static)
  for (long k = 0; k < ns; ++k)
    memcpy(d->buf + nc * (size_t)k, field + nc * (size_t)d->send_idx[k],
           nc * sizeof(double));
  for (int q = 0; q < d->size; ++q)
    if (d->send_count[q]) {
      MPI_Isend(d->buf + nc * (size_t)d->send_off[q], ncomp * d->send_count[q],
                MPI_DOUBLE, q, 7, MPI_COMM_WORLD, &req[nr++]);
      d->sent += (double)(ncomp * d->send_count[q]);
      d->messages += 1.0;
    }
  int rc = sph_domain_wait(nr, req);
  d->seconds += MPI_Wtime() - t0;
  if (rc != MPI_SUCCESS)
    return sph_error_set(err, SPH_ERR_IO, "halo exchange failed");
  return SPH_OK;
}

double sph_domain_min(sph_domain *d, double v) {
  double out = v;
  if (!d)
    return out;
  double t0 = MPI_Wtime();
  allreduce(&v, &out, 1, MPI_DOUBLE, MPI_MIN);
  d->seconds += MPI_Wtime() - t0;
  return out;
}

double sph_domain_max(sph_domain *d, double v) {
  double out = v;
  if (d)
    allreduce(&v, &out, 1, MPI_DOUBLE, MPI_MAX);
  return out;
}

void sph_domain_minmax(sph_domain *d, double *lo, double *hi, int n) {
  if (!d)
    return;
  double t0 = MPI_Wtime();
  for (int at = 0; at < n; at += 16) { /* 16 pairs a reduction */
    int m = n - at < 16 ? n - at : 16;
    double v[32], r[32];
    for (int i = 0; i < m; ++i) {
      v[i] = lo[at + i];
      v[m + i] = -hi[at + i]; /* negation is exact: one MPI_MIN for both */
    }
    allreduce(v, r, 2 * m, MPI_DOUBLE, MPI_MIN);
    for (int i = 0; i < m; ++i) {
      lo[at + i] = r[i];
      hi[at + i] = -r[m + i];
    }
  }
  d->seconds += MPI_Wtime() - t0;
}

void sph_domain_sum(sph_domain *d, double *v, int count) {
  if (!d || count <= 0 || count > 16)
    return;
  double mine[16], *all = d->sums;
  memcpy(mine, v, (size_t)count * sizeof *v);
  allgather(mine, count, MPI_DOUBLE, all);
  for (int c = 0; c < count; ++c) {
    double s = 0.0;
    for (int q = 0; q < d->size; ++q)
      s += all[q * count + c];
    v[c] = s;
  }
}

void sph_domain_sum_long(sph_domain *d, double *v, size_t count, double *work,
                         size_t chunk) {
  if (!d || chunk == 0)
    return;
  double t0 = MPI_Wtime();
  for (size_t off = 0; off < count; off += chunk) {
    size_t m = count - off < chunk ? count - off : chunk;
    allgather(v + off, (int)m, MPI_DOUBLE, work);
    for (size_t c = 0; c < m; ++c) {
      double s = 0.0;
      for (int q = 0; q < d->size; ++q)
        s += work[(size_t)q * m + c];
      v[off + c] = s;
    }
  }
  d->seconds += MPI_Wtime() - t0;
}

int sph_domain_bcast_int(sph_domain *d, int v) {
  MPI_Request r;
  if (d && MPI_Ibcast(&v, 1, MPI_INT, 0, MPI_COMM_WORLD, &r) == MPI_SUCCESS)
    sph_domain_wait(1, &r);
  return v;
}

void sph_domain_gather_u64(sph_domain *d, const uint64_t *v, int count,
                           uint64_t *out) {
  MPI_Request r;
  if (d && MPI_Igather(v, count, MPI_UINT64_T, out, count, MPI_UINT64_T, 0,
                       MPI_COMM_WORLD, &r) == MPI_SUCCESS)
    sph_domain_wait(1, &r);
}

sph_status sph_domain_agree(sph_domain *d, sph_status st, sph_error *err) {
  if (!d)
    return st;
  int mine = st != SPH_OK ? d->rank : d->size, first = d->size;
  double t0 = MPI_Wtime();
  allreduce(&mine, &first, 1, MPI_INT, MPI_MIN);
  d->seconds += MPI_Wtime() - t0;
  if (first == d->size)
    return SPH_OK;
  sph_error e;
  if (first == d->rank && err)
    e = *err;
  else if (first == d->rank)
    sph_error_set(&e, st, "rank %d failed", d->rank);
  MPI_Bcast(&e, (int)sizeof e, MPI_BYTE, first, MPI_COMM_WORLD);
  if (err)
    *err = e;
  return e.code != SPH_OK ? e.code : SPH_ERR_IO;
}

sph_status sph_domain_box_points(sph_domain *d, const double *pts, size_t n,
                                 int ncomp, double radius, double **out,
                                 size_t *cap, size_t *m, sph_error *err) {
  *m = 0;
  if (!d)
    return SPH_OK;
  double t0 = MPI_Wtime();
  int R = d->size, dim = d->dim;
  size_t nc = (size_t)ncomp;
  /* this rank's box of points widened by the radius */
  double box[6] = {INFINITY,  INFINITY,  INFINITY,
                   -INFINITY, -INFINITY, -INFINITY};
  for (size_t a = 0; a < n; ++a)
    for (int c = 0; c < dim; ++c) {
      box[c] = fmin(box[c], pts[nc * a + (size_t)c] - radius);
      box[3 + c] = fmax(box[3 + c], pts[nc * a + (size_t)c] + radius);
    }
  double *boxes = malloc(6 * (size_t)R * sizeof *boxes);
  int *cnt = calloc(4 * (size_t)R + 2, sizeof *cnt);
  int fail = !boxes || !cnt;
  if (!fail)
    MPI_Allgather(box, 6, MPI_DOUBLE, boxes, 6, MPI_DOUBLE, MPI_COMM_WORLD);
  int *sc = cnt, *so = cnt + R, *rc = cnt + 2 * R, *ro = cnt + 3 * R + 1;
  /* the points inside each other rank's box, counted then packed */
  for (int pass = 0; !fail && pass < 2; ++pass) {
    for (int q = 0; q < R; ++q)
      sc[q] = 0;
    for (int q = 0; q < R; ++q) {
      const double *b = boxes + 6 * q;
      for (size_t a = 0; q != d->rank && a < n; ++a) {
        const double *x = pts + nc * a;
        int in = 1;
        for (int c = 0; c < dim && in; ++c)
          in = x[c] >= b[c] && x[c] <= b[3 + c];
        if (in && pass == 1)
          memcpy(d->pbuf + nc * (size_t)(so[q] + sc[q]), x,
                 nc * sizeof(double));
        sc[q] += in;
      }
    }
    if (pass == 0) {
      so[0] = 0;
      for (int q = 0; q < R; ++q)
        so[q + 1] = so[q] + sc[q];
      size_t need = nc * (size_t)so[R] + 1;
      if (need > d->pbuf_cap) {
        free(d->pbuf);
        d->pbuf = malloc(need * sizeof *d->pbuf);
        d->pbuf_cap = d->pbuf ? need : 0;
        fail = !d->pbuf;
      }
    }
  }
  long f = fail, anyfail = 0;
  MPI_Allreduce(&f, &anyfail, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
  if (!anyfail) {
    MPI_Alltoall(sc, 1, MPI_INT, rc, 1, MPI_INT, MPI_COMM_WORLD);
    ro[0] = 0;
    for (int q = 0; q < R; ++q)
      ro[q + 1] = ro[q] + rc[q];
    size_t need = nc * (size_t)ro[R] + 1;
    if (need > *cap) {
      free(*out);
      *out = malloc(need * sizeof **out);
      *cap = *out ? need : 0;
    }
    f = !*out;
    MPI_Allreduce(&f, &anyfail, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
  }
  if (!anyfail) {
    for (int q = 0; q <= R; ++q) { /* in doubles */
      sc[q] *= q < R ? ncomp : 1;
      so[q] *= ncomp;
      rc[q] *= q < R ? ncomp : 1;
      ro[q] *= ncomp;
    }
    MPI_Alltoallv(d->pbuf, sc, so, MPI_DOUBLE, *out, rc, ro, MPI_DOUBLE,
                  MPI_COMM_WORLD);
    *m = (size_t)ro[R] / nc;
  }
  free(boxes);
  free(cnt);
  d->seconds += MPI_Wtime() - t0;
  return anyfail ? sph_error_set(err, SPH_ERR_NOMEM, "points near a rank")
                 : SPH_OK;
}

static int cmp_i64(const void *pa, const void *pb) {
  int64_t a = *(const int64_t *)pa, b = *(const int64_t *)pb;
  return (a > b) - (a < b);
}

sph_status sph_domain_fetch(sph_domain *d, const int64_t *want, size_t nwant,
                            const int64_t *key, const double *val, size_t n,
                            int ncomp, double *out, sph_error *err) {
  if (!d)
    return SPH_OK;
  double t0 = MPI_Wtime();
  size_t nc = (size_t)ncomp, total = 0, at = 0;
  int64_t *all = NULL;
  double *ans = NULL;
  sph_status st =
      sph_domain_allgather_i64(d, want, nwant, &all, &total, &at, err);
  if (st == SPH_OK && total) {
    ans = calloc(total * nc, sizeof *ans);
    st = sph_domain_agree(
        d, ans ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "fetch"), err);
  }
  if (st == SPH_OK && total) {
    /* the owner answers, the others add zeros: the sum is exact */
    for (size_t i = 0; i < total; ++i) {
      const int64_t *k =
          n ? bsearch(all + i, key, n, sizeof *key, cmp_i64) : NULL;
      if (k)
        memcpy(ans + nc * i, val + nc * (size_t)(k - key), nc * sizeof *ans);
    }
    MPI_Allreduce(MPI_IN_PLACE, ans, (int)(total * nc), MPI_DOUBLE, MPI_SUM,
                  MPI_COMM_WORLD);
    memcpy(out, ans + nc * at, nc * nwant * sizeof *out);
  }
  free(all);
  free(ans);
  d->seconds += MPI_Wtime() - t0;
  return st;
}

sph_status sph_domain_pick(sph_domain *d, const double *rows, size_t m, int w,
                           double *out, sph_error *err) {
  if (!d)
    return SPH_OK;
  double t0 = MPI_Wtime();
  size_t block = m * (size_t)w;
  double *all =
      d->rank == 0 ? malloc(((size_t)d->size * block + 1) * sizeof *all) : NULL;
  sph_status st = d->rank == 0 && !all
                      ? sph_error_set(err, SPH_ERR_NOMEM, "probe values")
                      : SPH_OK;
  SPH_TRY(sph_domain_agree(d, st, err));
  MPI_Gather(rows, (int)block, MPI_DOUBLE, all, (int)block, MPI_DOUBLE, 0,
             MPI_COMM_WORLD);
  for (size_t k = 0; d->rank == 0 && k < m; ++k)
    for (int q = 0; q < d->size; ++q) {
      const double *r = all + (size_t)q * block + k * (size_t)w;
      if (r[0] != 0.0) {
        memcpy(out + k * (size_t)w, r, (size_t)w * sizeof *out);
        break;
      }
    }
  free(all);
  d->seconds += MPI_Wtime() - t0;
  return SPH_OK;
}

sph_status sph_domain_gather_range(sph_domain *d, const int64_t *key,
                                   const double *rows, size_t n, int w,
                                   int64_t lo, size_t m, double *out,
                                   sph_error *err) {
  size_t nw = (size_t)w;
  if (!d) {
    place_rows(out, key, rows, n, w, lo);
    return SPH_OK;
  }
  double t0 = MPI_Wtime();
  int R = d->size, mine = (int)n, *cnt = NULL, *off = NULL, *vcnt = NULL,
      *voff = NULL;
  int64_t *keys = NULL;
  double *vals = NULL;
  int fail = 0;
  if (d->rank == 0) {
    cnt = malloc((size_t)R * sizeof *cnt);
    off = malloc((size_t)R * sizeof *off);
    vcnt = malloc((size_t)R * sizeof *vcnt);
    voff = malloc((size_t)R * sizeof *voff);
    keys = malloc((m ? m : 1) * sizeof *keys);
    vals = malloc((m ? m : 1) * nw * sizeof *vals);
    fail = !cnt || !off || !vcnt || !voff || !keys || !vals;
  }
  sph_status st = sph_domain_agree(
      d, fail ? sph_error_set(err, SPH_ERR_NOMEM, "gather of a range") : SPH_OK,
      err);
  if (st == SPH_OK) {
    MPI_Gather(&mine, 1, MPI_INT, cnt, 1, MPI_INT, 0, MPI_COMM_WORLD);
    for (int q = 0, at = 0; d->rank == 0 && q < R; at += cnt[q++]) {
      off[q] = at;
      vcnt[q] = w * cnt[q];
      voff[q] = w * at;
    }
    MPI_Gatherv(key, mine, MPI_INT64_T, keys, cnt, off, MPI_INT64_T, 0,
                MPI_COMM_WORLD);
    MPI_Gatherv(rows, w * mine, MPI_DOUBLE, vals, vcnt, voff, MPI_DOUBLE, 0,
                MPI_COMM_WORLD);
    if (d->rank == 0)
      place_rows(out, keys, vals, (size_t)off[R - 1] + (size_t)cnt[R - 1], w,
                 lo);
  }
  free(cnt);
  free(off);
  free(vcnt);
  free(voff);
  free(keys);
  free(vals);
  d->seconds += MPI_Wtime() - t0;
  return st;
}

#else /* without MPI: one rank, no domain is ever made */

sph_status sph_domain_world_agree(sph_status st, sph_error *err) {
  (void)err;
  return st;
}

sph_status sph_domain_world_first(sph_status st, int64_t key, sph_error *err) {
  (void)key, (void)err;
  return st;
}

int sph_domain_node_size(void) { return 1; }

sph_status sph_domain_exchange(sph_domain *d, double *field, int ncomp,
                               sph_error *err) {
  (void)d, (void)field, (void)ncomp, (void)err;
  return SPH_OK;
}

double sph_domain_min(sph_domain *d, double v) { return (void)d, v; }
double sph_domain_max(sph_domain *d, double v) { return (void)d, v; }
void sph_domain_minmax(sph_domain *d, double *lo, double *hi, int n) {
  (void)d, (void)lo, (void)hi, (void)n;
}
void sph_domain_sum(sph_domain *d, double *v, int count) {
  (void)d, (void)v, (void)count;
}
void sph_domain_sum_long(sph_domain *d, double *v, size_t count, double *work,
                         size_t chunk) {
  (void)d, (void)v, (void)count, (void)work, (void)chunk;
}
int sph_domain_bcast_int(sph_domain *d, int v) { return (void)d, v; }
void sph_domain_gather_u64(sph_domain *d, const uint64_t *v, int count,
                           uint64_t *out) {
  (void)d, (void)v, (void)count, (void)out;
}
sph_status sph_domain_agree(sph_domain *d, sph_status st, sph_error *err) {
  (void)d, (void)err;
  return st;
}
sph_status sph_domain_box_points(sph_domain *d, const double *pts, size_t n,
                                 int ncomp, double radius, double **out,
                                 size_t *cap, size_t *m, sph_error *err) {
  (void)d, (void)pts, (void)n, (void)ncomp, (void)radius, (void)out;
  (void)cap, (void)err;
  *m = 0;
  return SPH_OK;
}
sph_status sph_domain_pick(sph_domain *d, const double *rows, size_t m, int w,
                           double *out, sph_error *err) {
  (void)d, (void)rows, (void)m, (void)w, (void)out, (void)err;
  return SPH_OK;
}
sph_status sph_domain_fetch(sph_domain *d, const int64_t *want, size_t nwant,
                            const int64_t *key, const double *val, size_t n,
                            int ncomp, double *out, sph_error *err) {
  (void)d, (void)want, (void)nwant, (void)key, (void)val, (void)n;
  (void)ncomp, (void)out, (void)err;
  return SPH_OK;
}

sph_status sph_domain_gather_range(sph_domain *d, const int64_t *key,
                                   const double *rows, size_t n, int w,
                                   int64_t lo, size_t m, double *out,
                                   sph_error *err) {
  (void)d, (void)m, (void)err;
  place_rows(out, key, rows, n, w, lo);
  return SPH_OK;
}
#endif

/* ascending storage index within each list: insertion sort of the usual
 * few tens of entries */
void sph_domain_sort_lists(const sph_domain *d, sph_neighbors *nl, size_t n) {
  if (d)
    sph_domain_sort_lists_by(nl, n, d->gidx);
}

void sph_domain_sort_lists_by(sph_neighbors *nl, size_t n, const int64_t *key) {
  long m = (long)n;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < m; ++a) {
    int32_t *v = nl->index + nl->offset[a];
    size_t k = nl->offset[a + 1] - nl->offset[a];
    for (size_t i = 1; i < k; ++i) {
      int32_t x = v[i];
      size_t j = i;
      for (; j > 0 && key[v[j - 1]] > key[x]; --j)
        v[j] = v[j - 1];
      v[j] = x;
    }
  }
}

/* (with or without MPI: one rank copies its values) */
sph_status sph_domain_allgather_i64(sph_domain *d, const int64_t *v,
                                    size_t count, int64_t **out, size_t *total,
                                    size_t *first, sph_error *err) {
  *out = NULL;
  *total = 0;
  int R = d ? d->size : 1, mine = (int)count;
  int *cnt = malloc((size_t)R * sizeof *cnt);
  int *off = malloc(((size_t)R + 1) * sizeof *off);
  int64_t *all = NULL;
  sph_status st =
      cnt && off && count <= (size_t)INT_MAX
          ? SPH_OK
          : sph_error_set(err, SPH_ERR_NOMEM, "gather of %zu", count);
  if ((st = sph_domain_agree(d, st, err)) != SPH_OK)
    goto done;
  cnt[0] = mine;
#ifdef SPH_HAVE_MPI
  if (d)
    MPI_Allgather(&mine, 1, MPI_INT, cnt, 1, MPI_INT, MPI_COMM_WORLD);
#endif
  off[0] = 0;
  for (int q = 0; q < R; ++q)
    off[q + 1] = off[q] + cnt[q];
  all = malloc(((size_t)off[R] + 1) * sizeof *all);
  st = all ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "gather of %d", off[R]);
  if ((st = sph_domain_agree(d, st, err)) != SPH_OK)
    goto done;
  if (!d)
    memcpy(all, v, count * sizeof *v);
#ifdef SPH_HAVE_MPI
  if (d)
    MPI_Allgatherv(v, mine, MPI_INT64_T, all, cnt, off, MPI_INT64_T,
                   MPI_COMM_WORLD);
#endif
  *out = all;
  *total = (size_t)off[R];
  if (first)
    *first = (size_t)off[d ? d->rank : 0];
  all = NULL;
done:
  free(all);
  free(cnt);
  free(off);
  return st;
}
