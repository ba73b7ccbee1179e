/* Domain decomposition over MPI ranks (issue 20): recursive coordinate
 * bisection of the reference positions balanced by count, ghost layers of
 * one kernel support found with the cell-list search, a fixed halo exchange
 * with MPI_Irecv/MPI_Isend, reductions in rank order and the gather of the
 * output fields to rank 0; the same partition, ghosts and halo from each
 * rank's share of the particles, without the whole set. This file: MPI's
 * start, the accessors and the partition; domain_fixed.c the ghosts and
 * halo from the whole set, domain_share.c the same from each rank's share,
 * domain_comm.c the exchanges, reductions and gathers, domain_dynamic.c
 * the updated-Lagrangian rebuild (every MPI call of sph is in these). */
#include "parallel/domain.h"
#include "parallel/domain_impl.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef SPH_HAVE_MPI
#include <mpi.h>
#endif

static int world_rank = 0, world_size = 1, node_ranks = 1;
#ifdef SPH_HAVE_MPI
static int mpi_started = 0;
#endif

/* started by a launcher: the environment OpenMPI, MPICH and PMIx set */
static int launched_size(void) {
  const char *names[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"};
  for (size_t i = 0; i < sizeof names / sizeof *names; ++i) {
    const char *v = getenv(names[i]);
    if (v && *v)
      return atoi(v);
  }
  return getenv("PMIX_RANK") ? 2 : 0;
}

/* OpenMPI busy-polls while a rank waits: beside other work on a shared
 * machine a waiting rank takes the core its partner needs (issue 36: 2 ranks
 * 7-10x slower than one). Unless the user chose (OMPI_MCA_mpi_yield_when_idle,
 * or mpirun --mca, which sets it), waits yield; OpenMPI reads it in MPI_Init.
 * Returns 1 when it set the default. */
int sph_domain_idle_defaults(void) {
  if (getenv("OMPI_MCA_mpi_yield_when_idle"))
    return 0;
  return setenv("OMPI_MCA_mpi_yield_when_idle", "1", 0) == 0;
}

sph_status sph_domain_init(int *argc, char ***argv, sph_error *err) {
  int launched = launched_size();
#ifdef SPH_HAVE_MPI
  if (launched <= 0)
    return SPH_OK; /* serial: MPI is never started */
  sph_domain_idle_defaults();
  int provided;
  if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) !=
      MPI_SUCCESS)
    return sph_error_set(err, SPH_ERR_IO, "MPI_Init failed");
  mpi_started = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &world_size);
  node_ranks = sph_domain_node_size();
  return SPH_OK;
#else
  (void)argc, (void)argv;
  if (launched > 1)
    return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                         "started by mpirun with %d ranks, but this sph was "
                         "built without MPI (cmake -DSPH_MPI=ON with "
                         "libopenmpi-dev installed)",
                         launched);
  return SPH_OK;
#endif
}

void sph_domain_finalize(void) {
#ifdef SPH_HAVE_MPI
  if (mpi_started)
    MPI_Finalize();
  mpi_started = 0;
#endif
}

int sph_domain_world_rank(void) { return world_rank; }
int sph_domain_world_size(void) { return world_size; }
int sph_domain_node_ranks(void) { return node_ranks; }

int sph_domain_rank(const sph_domain *d) { return d ? d->rank : 0; }
double sph_domain_seconds(const sph_domain *d) { return d ? d->seconds : 0.0; }
int sph_domain_size(const sph_domain *d) { return d ? d->size : 1; }
void sph_domain_traffic(const sph_domain *d, double *values, double *messages) {
  *values = d ? d->sent : 0.0;
  *messages = d ? d->messages : 0.0;
}
size_t sph_domain_ghosts(const sph_domain *d) { return d ? d->ng : 0; }
const double *sph_domain_ghost_X(const sph_domain *d) { return d->gX; }
const double *sph_domain_ghost_volume(const sph_domain *d) { return d->gV; }
const int32_t *sph_domain_ghost_body(const sph_domain *d) { return d->gbody; }
const int64_t *sph_domain_ghost_id(const sph_domain *d) { return d->gid; }
int sph_domain_migrates(const sph_domain *d) { return d && d->dyn; }
const int64_t *sph_domain_storage_index(const sph_domain *d) {
  return d ? d->gidx : NULL;
}
void sph_domain_set_ghost_base(sph_domain *d, size_t base) {
  if (d)
    d->base = base;
}
size_t sph_domain_particles(const sph_domain *d, const sph_particles *ps) {
  return d ? d->total : ps->n;
}

sph_halo sph_domain_halo(sph_domain *d) {
  sph_halo h = {0.0, 0.0, 0.0, 0.0};
  if (!d)
    return h;
  double v[2] = {(double)d->nsend, 0.0};
  for (int q = 0; q < d->size; ++q)
    v[1] += d->send_count[q] > 0;
  sph_domain_sum(d, v, 2);
  h.values = v[0];
  h.messages = v[1];
  h.max_ghosts = sph_domain_max(d, (double)d->ng);
  h.max_owned = sph_domain_max(d, (double)d->n);
  return h;
}

void sph_domain_destroy(sph_domain *d) {
  if (!d)
    return;
  free(d->gidx);
  free(d->gX);
  free(d->gV);
  free(d->gbody);
  free(d->gid);
  free(d->recv_count);
  free(d->recv_off);
  free(d->send_count);
  free(d->send_off);
  free(d->send_idx);
  free(d->buf);
  free(d->req);
  free(d->sums);
  free(d->pbuf);
  sph_domain_dyn_destroy(d->dyn);
  free(d);
}

/* ---- recursive coordinate bisection ----------------------------------- */

/* the longest side of a box */
static int axis_of(const double *lo, const double *hi, int dim) {
  int axis = 0;
  for (int c = 1; c < dim; ++c)
    if (hi[c] - lo[c] > hi[axis] - lo[axis])
      axis = c;
  return axis;
}

static int cmp_rcb(const void *pa, const void *pb) {
  const rcb_key *a = pa, *b = pb;
  if (a->x != b->x)
    return a->x < b->x ? -1 : 1;
  return (a->i > b->i) - (a->i < b->i);
}

/* owner of the n particles idx: halves of the ranks get shares of the
 * particles in proportion, cut across the longest side of their box
 * (ties by storage index, so every rank computes the same partition); the
 * cut between ranks below and from s = rank0 + nranks / 2 on is recorded as
 * axis[s], cut[s] (halfway between the two sides' nearest particles) when
 * axis is not NULL */
void sph_domain_rcb(const double *X, int dim, rcb_key *k, size_t n, int rank0,
                    int nranks, int *owner, int *axis, double *cutv) {
  if (nranks == 1) {
    for (size_t i = 0; i < n; ++i)
      owner[k[i].i] = rank0;
    return;
  }
  double lo[3] = {INFINITY, INFINITY, INFINITY},
         hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < dim; ++c) {
      lo[c] = fmin(lo[c], X[3 * k[i].i + c]);
      hi[c] = fmax(hi[c], X[3 * k[i].i + c]);
    }
  int ax = axis_of(lo, hi, dim);
  for (size_t i = 0; i < n; ++i)
    k[i].x = X[3 * k[i].i + ax];
  qsort(k, n, sizeof *k, cmp_rcb);
  int nlo = nranks / 2;
  size_t cut = n * (size_t)nlo / (size_t)nranks;
  if (axis) {
    axis[rank0 + nlo] = ax;
    cutv[rank0 + nlo] = n == 0     ? 0.0
                        : cut == 0 ? k[0].x
                        : cut == n ? k[n - 1].x
                                   : 0.5 * (k[cut - 1].x + k[cut].x);
  }
  sph_domain_rcb(X, dim, k, cut, rank0, nlo, owner, axis, cutv);
  sph_domain_rcb(X, dim, k + cut, n - cut, rank0 + nlo, nranks - nlo, owner,
                 axis, cutv);
}

#ifdef SPH_HAVE_MPI

/* ---- the same partition by counting bisection ------------------------- */

/* a coordinate as an unsigned key of the same order (-0 as +0) */
static uint64_t ordered_bits(double x) {
  uint64_t u;
  x = x == 0.0 ? 0.0 : x;
  memcpy(&u, &x, sizeof u);
  return u >> 63 ? ~u : u | 1ull << 63;
}

/* the coordinate of an ordered_bits key (-0 comes back as +0) */
static double ordered_value(uint64_t u) {
  double x;
  u = u >> 63 ? u & ~(1ull << 63) : ~u;
  memcpy(&x, &u, sizeof x);
  return x;
}

#define RADIX 256 /* buckets a round of the selection: 8 bits */

/* the k-th smallest (from 1) over all ranks of the keys u[idx[j]] (or,
 * with t, of the tie keys of the particles whose key is *kth, as
 * unsigned keys of the same order), all within range[0] .. range[1], by 8
 * bits a round: a histogram of the next byte of the keys that share the
 * bytes found so far (the range's common leading bytes to begin with),
 * summed with MPI_Allreduce; *below: the keys smaller than the one found,
 * *at: the keys equal to it */
static uint64_t radix_select(const uint64_t *u, const int64_t *t,
                             const uint64_t *idx, size_t m, int64_t k,
                             const uint64_t *kth, const uint64_t range[2],
                             int64_t *below, int64_t *at) {
  int64_t h[RADIX], sum[RADIX];
  int r0 = 0;
  while (r0 < 7 && (range[0] ^ range[1]) >> (56 - 8 * r0) == 0)
    ++r0;
  uint64_t prefix = r0 ? range[0] >> (64 - 8 * r0) : 0;
  *below = 0;
  for (int r = r0; r < 8; ++r) {
    int shift = 56 - 8 * r;
    memset(h, 0, sizeof h);
    for (size_t j = 0; j < m; ++j) {
      uint64_t i = idx[j];
      if (t && u[i] != *kth)
        continue;
      uint64_t v = t ? (uint64_t)t[i] ^ 1ull << 63 : u[i];
      if (r == r0 || v >> (shift + 8) == prefix)
        h[v >> shift & (RADIX - 1)] += 1;
    }
    MPI_Allreduce(h, sum, RADIX, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
    int q = 0;
    while (q < RADIX - 1 && *below + sum[q] < k)
      *below += sum[q++];
    prefix = prefix << 8 | (uint64_t)q;
    *at = sum[q];
  }
  return prefix;
}

/* sph_domain_rcb's recursion over the local particles idx (n over all
 * ranks) of ranks rank0 .. rank0 + nranks - 1: the box from a reduction,
 * the cut-th key (coordinate, tie key) by radix selection; the cut plane
 * as sph_domain_rcb records it when axis is not NULL */
static void rcb_counted(const double *X, const int64_t *t,
                        const uint64_t trange[2], uint64_t *u, uint64_t *idx,
                        size_t m, int64_t n, int dim, int rank0, int nranks,
                        int *owner, int *axis, double *cutv) {
  if (nranks == 1) {
    for (size_t j = 0; j < m; ++j)
      owner[idx[j]] = rank0;
    return;
  }
  double b[6] = {INFINITY, INFINITY, INFINITY, INFINITY, INFINITY, INFINITY};
  for (size_t j = 0; j < m; ++j)
    for (int c = 0; c < dim; ++c) {
      b[c] = fmin(b[c], X[3 * idx[j] + c]);
      b[3 + c] = fmin(b[3 + c], -X[3 * idx[j] + c]);
    }
  double box[6];
  MPI_Allreduce(b, box, 6, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  double hi[3] = {-box[3], -box[4], -box[5]};
  int ax = axis_of(box, hi, dim);
  int nlo = nranks / 2;
  int64_t cut = n * nlo / nranks;
  for (size_t j = 0; j < m; ++j)
    u[idx[j]] = ordered_bits(X[3 * idx[j] + ax]);
  /* the cut-th coordinate key, then the tie key among its particles that
   * completes the cut (all of them when they end exactly at the cut) */
  uint64_t lo = 0, range[2] = {ordered_bits(box[ax]), ordered_bits(hi[ax])};
  int64_t wlo = INT64_MAX, below = 0, at = 0, tb, ta;
  if (cut > 0)
    lo = radix_select(u, NULL, idx, m, cut, NULL, range, &below, &at);
  if (cut > 0 && below + at > cut)
    wlo = (int64_t)(radix_select(u, t, idx, m, cut - below, &lo, trange, &tb,
                                 &ta) ^
                    1ull << 63);
  /* the low ranks' particles first in idx */
  size_t nb = 0;
  uint64_t first = UINT64_MAX; /* the high side's smallest key */
  for (size_t j = 0; j < m; ++j) {
    uint64_t i = idx[j];
    if (cut > 0 && (u[i] < lo || (u[i] == lo && t[i] <= wlo))) {
      idx[j] = idx[nb];
      idx[nb++] = i;
    } else if (u[i] < first) {
      first = u[i];
    }
  }
  if (axis) { /* halfway between the two sides' nearest particles */
    uint64_t f = first;
    MPI_Allreduce(&f, &first, 1, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
    axis[rank0 + nlo] = ax;
    cutv[rank0 + nlo] = n == 0     ? 0.0
                        : cut == 0 ? ordered_value(first)
                        : cut == n
                            ? ordered_value(lo)
                            : 0.5 * (ordered_value(lo) + ordered_value(first));
  }
  rcb_counted(X, t, trange, u, idx, nb, cut, dim, rank0, nlo, owner, axis,
              cutv);
  rcb_counted(X, t, trange, u, idx + nb, m - nb, n - cut, dim, rank0 + nlo,
              nranks - nlo, owner, axis, cutv);
}

void sph_domain_rcb_counted(const double *X, const int64_t *t, size_t n,
                            int dim, int *owner, int *axis, double *cut,
                            uint64_t *work) {
  uint64_t *u = work ? work : malloc(2 * (n ? n : 1) * sizeof *u);
  uint64_t *idx = u ? u + n : NULL;
  for (size_t i = 0; idx && i < n; ++i)
    idx[i] = i;
  /* the particles and the range of the tie keys (as ordered unsigned) */
  int64_t v[2] = {u == NULL, (int64_t)n}, all[2];
  uint64_t tr[2] = {UINT64_MAX, UINT64_MAX}, trange[2];
  for (size_t i = 0; i < n; ++i) {
    uint64_t k = (uint64_t)t[i] ^ 1ull << 63;
    tr[0] = k < tr[0] ? k : tr[0];
    tr[1] = ~k < tr[1] ? ~k : tr[1];
  }
  MPI_Allreduce(v, all, 2, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  MPI_Allreduce(tr, trange, 2, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
  trange[1] = ~trange[1];
  if (!all[0])
    rcb_counted(X, t, trange, u, idx, n, all[1], dim, 0, world_size, owner,
                axis, cut);
  else
    for (size_t i = 0; i < n; ++i)
      owner[i] = -1;
  if (!work)
    free(u);
}

#endif
