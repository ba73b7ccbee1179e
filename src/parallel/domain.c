/* Domain decomposition over MPI ranks (issue 20): recursive coordinate
 * bisection of the reference positions balanced by count, ghost layers of
 * one kernel support found with the cell-list search, a fixed halo exchange
 * with MPI_Irecv/MPI_Isend, reductions in rank order and the gather of the
 * output fields to rank 0; the same partition, ghosts and halo from each
 * rank's share of the particles, without the whole set. Every MPI call of
 * sph is in this file and domain_dynamic.c (the updated-Lagrangian
 * rebuild). */
#include "parallel/domain.h"
#include "parallel/domain_impl.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef SPH_HAVE_MPI
#include <mpi.h>
#endif

static int world_rank = 0, world_size = 1, mpi_started = 0;

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

sph_status sph_domain_init(int *argc, char ***argv, sph_error *err) {
  int launched = launched_size();
#ifdef SPH_HAVE_MPI
  if (launched <= 0)
    return SPH_OK; /* serial: MPI is never started */
  int provided;
  if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) !=
      MPI_SUCCESS)
    return sph_error_set(err, SPH_ERR_IO, "MPI_Init failed");
  mpi_started = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &world_size);
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

/* rows of w doubles placed at their storage index less lo */
static void place_rows(double *out, const int64_t *key, const double *rows,
                       size_t n, int w, int64_t lo) {
  for (size_t i = 0; i < n; ++i)
    memcpy(out + (size_t)w * (size_t)(key[i] - lo), rows + (size_t)w * i,
           (size_t)w * sizeof *out);
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

/* the ghosts of rank r: particles of the same body within `support` of an
 * owned one, from a cell-list search over the owned particles and those in
 * their box widened by `support`; flags ghost[i] = 1 in the whole set */
static sph_status find_ghosts(const sph_particles *ps, const int *owner, int r,
                              double support, char *ghost, sph_error *err) {
  size_t N = ps->n;
  int dim = ps->dim;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  double lo[3] = {INFINITY, INFINITY, INFINITY},
         hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < N; ++i)
    for (int c = 0; owner[i] == r && c < dim; ++c) {
      lo[c] = fmin(lo[c], X[3 * i + c]);
      hi[c] = fmax(hi[c], X[3 * i + c]);
    }
  size_t nc = 0;
  int64_t *cand = malloc((N ? N : 1) * sizeof *cand);
  for (size_t i = 0; cand && i < N; ++i) {
    int in = 1;
    for (int c = 0; c < dim; ++c)
      in &= X[3 * i + c] >= lo[c] - support && X[3 * i + c] <= hi[c] + support;
    if (in)
      cand[nc++] = (int64_t)i;
  }
  double *cx = malloc(3 * (nc ? nc : 1) * sizeof *cx);
  int32_t *cb = malloc((nc ? nc : 1) * sizeof *cb);
  sph_neighbors *nl = NULL;
  sph_status st = cand && cx && cb
                      ? sph_neighbors_create(&nl, err)
                      : sph_error_set(err, SPH_ERR_NOMEM, "ghost search");
  for (size_t j = 0; st == SPH_OK && j < nc; ++j) {
    memcpy(cx + 3 * j, X + 3 * cand[j], 3 * sizeof *cx);
    cb[j] = ps->body[cand[j]];
  }
  if (st == SPH_OK)
    st = sph_neighbors_build(nl, cx, nc, dim, support, cb, SPH_PAIRS_SAME_BODY,
                             err);
  for (size_t j = 0; st == SPH_OK && j < nc; ++j) {
    if (owner[cand[j]] != r)
      continue;
    for (size_t k = nl->offset[j]; k < nl->offset[j + 1]; ++k) {
      int64_t b = cand[nl->index[k]];
      if (owner[b] != r)
        ghost[b] = 1;
    }
  }
  sph_neighbors_destroy(nl);
  free(cand);
  free(cx);
  free(cb);
  return st;
}

/* corner k (bit c: hi along c) of the box lo, hi into X; its signed
 * distance from the plane */
static double box_corner(const sph_domain_plane *p, const double *lo,
                         const double *hi, int k, double X[3]) {
  for (int c = 0; c < 3; ++c)
    X[c] = k >> c & 1 ? hi[c] : lo[c];
  return sph_plane_distance(p, X);
}

/* reflection of the box lo, hi (bounding the reflected corners) */
static void reflect_box(const sph_domain_plane *p, const double *lo,
                        const double *hi, double *out) {
  double *olo = out, *ohi = out + 3;
  for (int c = 0; c < 3; ++c)
    olo[c] = INFINITY, ohi[c] = -INFINITY;
  for (int k = 0; k < 8; ++k) {
    double X[3], dist = box_corner(p, lo, hi, k, X), y[3];
    sph_plane_reflect(p, X, dist, y);
    for (int c = 0; c < 3; ++c) {
      olo[c] = fmin(olo[c], y[c]);
      ohi[c] = fmax(ohi[c], y[c]);
    }
  }
}

/* whether some point of the box lies within `layer` of the plane */
static int box_near(const sph_domain_plane *p, const double *lo,
                    const double *hi, double layer) {
  double dmin = INFINITY, dmax = -INFINITY;
  for (int k = 0; k < 8; ++k) {
    double X[3], dist = box_corner(p, lo, hi, k, X);
    dmin = fmin(dmin, dist);
    dmax = fmax(dmax, dist);
  }
  return dmin < layer && dmax > -layer;
}

size_t sph_domain_mirror_boxes(const sph_domain_plane *planes, int np,
                               double near, double tol, int passes, double *box,
                               size_t max) {
  size_t nb = 1;
  int grew = 1;
  for (int pass = 0; grew && pass < passes; ++pass) {
    grew = 0;
    for (int k = 0; k < np; ++k)
      for (size_t b = 0, count = nb; b < count; ++b) {
        double img[6];
        if (!box_near(&planes[k], box + 6 * b, box + 6 * b + 3, near))
          continue;
        reflect_box(&planes[k], box + 6 * b, box + 6 * b + 3, img);
        int seen = 0;
        for (size_t e = 0; e < nb && !seen; ++e) {
          seen = 1;
          for (int c = 0; c < 6; ++c)
            seen &= fabs(box[6 * e + c] - img[c]) <= tol;
        }
        if (seen)
          continue;
        if (nb == max)
          return 0;
        memcpy(box + 6 * nb++, img, sizeof img);
        grew = 1;
      }
  }
  return nb;
}

/* the ghosts mirror images need (sph_domain_create_mirrored): the box of
 * the owned particles and its reflections across every plane it comes
 * within four supports of, chained until no new box appears; ghost[i] = 1
 * for every other rank's particle within two supports of one of the boxes
 * (all of them when the boxes do not settle) */
static sph_status find_mirror_ghosts(const sph_particles *ps, const int *owner,
                                     int r, double support,
                                     const sph_domain_plane *planes, int np,
                                     char *ghost, sph_error *err) {
  size_t N = ps->n;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  double *box = malloc(6 * SPH_DOMAIN_MIRROR_BOXES * sizeof *box);
  if (!box)
    return sph_error_set(err, SPH_ERR_NOMEM, "ghost search");
  for (int c = 0; c < 3; ++c)
    box[c] = INFINITY, box[3 + c] = -INFINITY;
  for (size_t i = 0; i < N; ++i)
    for (int c = 0; owner[i] == r && c < ps->dim; ++c) {
      box[c] = fmin(box[c], X[3 * i + c]);
      box[3 + c] = fmax(box[3 + c], X[3 * i + c]);
    }
  for (int c = ps->dim; c < 3; ++c)
    box[c] = box[3 + c] = 0.0;
  size_t nb = sph_domain_mirror_boxes(planes, np, 4.0 * support, 1e-9 * support,
                                      16, box, SPH_DOMAIN_MIRROR_BOXES);
  int full = nb == 0;
  double w = 2.0 * support;
  for (size_t i = 0; i < N; ++i) {
    if (owner[i] == r || ghost[i])
      continue;
    int in = full;
    for (size_t b = 0; b < nb && !in; ++b) {
      in = 1;
      for (int c = 0; c < ps->dim; ++c)
        in &= X[3 * i + c] >= box[6 * b + c] - w &&
              X[3 * i + c] <= box[6 * b + 3 + c] + w;
    }
    ghost[i] = (char)in;
  }
  free(box);
  return SPH_OK;
}

/* this rank's owned particles as a set of their own, in storage order */
static sph_status owned_set(const sph_particles *ps, const sph_domain *d,
                            size_t capacity, sph_particles **out,
                            sph_error *err) {
  SPH_TRY(sph_particles_create(out, capacity, ps->dim, err));
  sph_particles *o = *out;
  for (int f = 0; f < SPH_FIELD_COUNT; ++f) {
    if (!ps->field[f])
      continue;
    SPH_TRY(sph_particles_require(o, (sph_field)f, err));
    size_t nc = (size_t)sph_field_components((sph_field)f);
    for (size_t a = 0; a < d->n; ++a)
      memcpy(o->field[f] + nc * a, ps->field[f] + nc * d->gidx[a],
             nc * sizeof(double));
  }
  for (size_t a = 0; a < d->n; ++a) {
    o->id[a] = ps->id[d->gidx[a]];
    o->body[a] = ps->body[d->gidx[a]];
    o->flags[a] = ps->flags[d->gidx[a]];
  }
  o->n = d->n;
  return SPH_OK;
}

/* who needs what: ghost storage indices to their owners, answered with the
 * owned indices to send */
static sph_status exchange_plan(sph_domain *d, const int *gowner,
                                sph_error *err) {
  int R = d->size;
  d->recv_count = calloc((size_t)R, sizeof(int));
  d->recv_off = calloc((size_t)R + 1, sizeof(int));
  d->send_count = calloc((size_t)R, sizeof(int));
  d->send_off = calloc((size_t)R + 1, sizeof(int));
  d->req = malloc(2 * (size_t)R * sizeof(MPI_Request));
  if (!d->recv_count || !d->recv_off || !d->send_count || !d->send_off ||
      !d->req)
    return sph_error_set(err, SPH_ERR_NOMEM, "halo plan");
  for (size_t g = 0; g < d->ng; ++g)
    d->recv_count[gowner[g]]++;
  for (int q = 0; q < R; ++q)
    d->recv_off[q + 1] = d->recv_off[q] + d->recv_count[q];
  MPI_Alltoall(d->recv_count, 1, MPI_INT, d->send_count, 1, MPI_INT,
               MPI_COMM_WORLD);
  for (int q = 0; q < R; ++q)
    d->send_off[q + 1] = d->send_off[q] + d->send_count[q];
  d->nsend = (size_t)d->send_off[R];
  int64_t *want = malloc((d->nsend ? d->nsend : 1) * sizeof *want);
  d->send_idx = malloc((d->nsend ? d->nsend : 1) * sizeof *d->send_idx);
  d->buf = malloc(9 * (d->nsend ? d->nsend : 1) * sizeof *d->buf);
  if (!want || !d->send_idx || !d->buf) {
    free(want);
    return sph_error_set(err, SPH_ERR_NOMEM, "halo plan");
  }
  MPI_Alltoallv(d->gidx + d->n, d->recv_count, d->recv_off, MPI_INT64_T, want,
                d->send_count, d->send_off, MPI_INT64_T, MPI_COMM_WORLD);
  /* owned storage indices ascend: binary search */
  for (size_t k = 0; k < d->nsend; ++k) {
    size_t lo = 0, hi = d->n;
    while (lo < hi) {
      size_t mid = (lo + hi) / 2;
      if (d->gidx[mid] < want[k])
        lo = mid + 1;
      else
        hi = mid;
    }
    d->send_idx[k] = (int32_t)lo;
  }
  free(want);
  return SPH_OK;
}

/* a halo larger than the domain (ng_support ghosts within one support):
 * more ranks than useful; then the exchange's plan from the ghosts'
 * owners (collective, agreed) */
static sph_status halo_plan(sph_domain *d, sph_status st, size_t ng_support,
                            size_t N, const int *gowner, sph_error *err) {
  long worst = -1;
  if (st == SPH_OK && (ng_support > d->n || d->n == 0))
    worst = world_rank;
  st = sph_domain_agree(d, st, err);
  long any = -1;
  if (st == SPH_OK) {
    MPI_Allreduce(&worst, &any, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
    if (any >= 0)
      st = sph_error_set(err, SPH_ERR_RANGE,
                         "%d ranks are more than useful for %zu particles: "
                         "rank %ld would own no particle or hold more ghost "
                         "particles (one kernel support around its own) than "
                         "particles it owns; run on fewer ranks",
                         world_size, N, any);
  }
  if (st == SPH_OK)
    st = exchange_plan(d, gowner, err);
  return sph_domain_agree(d, st, err);
}

/* the partition; a dynamic domain (updated Lagrangian) finds no ghosts
 * here (sph_domain_rebuild does) and holds its particles with room */
static sph_status domain_create(sph_domain **out, sph_particles **ps,
                                double support, int dynamic,
                                const sph_domain_plane *planes, int np,
                                sph_error *err) {
  *out = NULL;
  sph_particles *all = *ps;
  size_t N = all->n;
  sph_domain *d = calloc(1, sizeof *d);
  int *owner = malloc((N ? N : 1) * sizeof *owner);
  char *ghost = calloc(N ? N : 1, 1);
  rcb_key *k = malloc((N ? N : 1) * sizeof *k);
  int *axis = malloc(((size_t)world_size + 1) * sizeof *axis);
  double *cut = malloc(((size_t)world_size + 1) * sizeof *cut);
  size_t cap = dynamic ? sph_domain_dyn_capacity(N, world_size) : 0;
  sph_status st = d && owner && ghost && k && axis && cut
                      ? SPH_OK
                      : sph_error_set(err, SPH_ERR_NOMEM, "decomposition");
  if (d) {
    d->rank = world_rank;
    d->size = world_size;
    d->dim = all->dim;
    d->sums = malloc((size_t)world_size * 16 * sizeof *d->sums);
    if (!d->sums)
      st = sph_error_set(err, SPH_ERR_NOMEM, "decomposition");
  }
  if (st == SPH_OK) {
    for (size_t i = 0; i < N; ++i)
      k[i] = (rcb_key){0.0, (int64_t)i};
    sph_domain_rcb(all->field[SPH_FIELD_POSITION0], all->dim, k, N, 0,
                   world_size, owner, axis, cut);
    if (!dynamic)
      st = find_ghosts(all, owner, world_rank, support, ghost, err);
  }
  /* owned in storage order, then ghosts by owner and storage order */
  for (size_t i = 0; st == SPH_OK && i < N; ++i) {
    d->n += owner[i] == world_rank;
    d->ng += ghost[i] != 0;
  }
  /* the usefulness check below counts the ghosts within one support */
  size_t ng_support = d ? d->ng : 0;
  if (st == SPH_OK && np > 0 && !dynamic) {
    st = find_mirror_ghosts(all, owner, world_rank, support, planes, np, ghost,
                            err);
    d->ng = 0;
    for (size_t i = 0; st == SPH_OK && i < N; ++i)
      d->ng += ghost[i] != 0;
  }
  if (st == SPH_OK) {
    size_t m = d->n + d->ng ? d->n + d->ng : 1;
    m = cap > m ? cap : m;
    d->gidx = malloc(m * sizeof *d->gidx);
    d->gX = malloc(3 * (d->ng + 1) * sizeof *d->gX);
    d->gV = malloc((d->ng + 1) * sizeof *d->gV);
    d->gbody = malloc((d->ng + 1) * sizeof *d->gbody);
    d->gid = malloc((d->ng + 1) * sizeof *d->gid);
    if (!d->gidx || !d->gX || !d->gV || !d->gbody || !d->gid)
      st = sph_error_set(err, SPH_ERR_NOMEM, "ghosts");
  }
  if (st == SPH_OK) {
    size_t a = 0;
    for (size_t i = 0; i < N; ++i)
      if (owner[i] == world_rank)
        d->gidx[a++] = (int64_t)i;
    /* ghosts by owner (a counting sort), each owner's in storage order */
    size_t *at = calloc((size_t)world_size + 1, sizeof *at);
    if (!at)
      st = sph_error_set(err, SPH_ERR_NOMEM, "ghosts");
    for (size_t i = 0; at && i < N; ++i)
      at[owner[i] + 1] += ghost[i] != 0;
    for (int q = 0; at && q < world_size; ++q)
      at[q + 1] += at[q];
    for (size_t i = 0; at && i < N; ++i)
      if (ghost[i])
        d->gidx[d->n + at[owner[i]]++] = (int64_t)i;
    free(at);
    for (size_t j = 0; st == SPH_OK && j < d->ng; ++j) {
      size_t i = (size_t)d->gidx[d->n + j];
      memcpy(d->gX + 3 * j, all->field[SPH_FIELD_POSITION0] + 3 * i,
             3 * sizeof *d->gX);
      d->gV[j] = all->field[SPH_FIELD_VOLUME0][i];
      d->gbody[j] = all->body[i];
      d->gid[j] = all->id[i];
    }
  }
  int *gowner = NULL;
  if (st == SPH_OK && !(gowner = malloc((d->ng + 1) * sizeof *gowner)))
    st = sph_error_set(err, SPH_ERR_NOMEM, "ghosts");
  for (size_t g = 0; st == SPH_OK && g < d->ng; ++g)
    gowner[g] = owner[d->gidx[d->n + g]];
  st = halo_plan(d, st, ng_support, N, gowner, err);
  free(gowner);
  sph_particles *mine = NULL;
  if (st == SPH_OK)
    st = owned_set(all, d, cap > d->n ? cap : d->n, &mine, err);
  st = sph_domain_agree(d, st, err);
  if (st == SPH_OK)
    d->total = N;
  if (st == SPH_OK && dynamic)
    st = sph_domain_dyn_create(d, N, axis, cut, err);
  st = sph_domain_agree(d, st, err);
  free(owner);
  free(ghost);
  free(k);
  free(axis);
  free(cut);
  if (st != SPH_OK) {
    sph_particles_destroy(mine);
    sph_domain_destroy(d);
    return st;
  }
  sph_particles_destroy(all);
  *ps = mine;
  *out = d;
  return SPH_OK;
}

sph_status sph_domain_create(sph_domain **out, sph_particles **ps,
                             double support, sph_error *err) {
  return domain_create(out, ps, support, 0, NULL, 0, err);
}

sph_status sph_domain_create_mirrored(sph_domain **out, sph_particles **ps,
                                      double support,
                                      const sph_domain_plane *planes,
                                      int nplanes, sph_error *err) {
  return domain_create(out, ps, support, 0, planes, nplanes, err);
}

sph_status sph_domain_create_dynamic(sph_domain **out, sph_particles **ps,
                                     double support, sph_error *err) {
  return domain_create(out, ps, support, 1, NULL, 0, err);
}

/* ---- the partition from each rank's share (no whole set) -------------- */

/* a particle as sent between ranks */
typedef struct share_rec {
  double X[3], V, v[3];
  int64_t id, g; /* particle id, storage index */
  int32_t body, owner;
  uint32_t flags;
  int32_t edge; /* an owned one within another rank's widened box */
} share_rec;

static int cmp_rec_storage(const void *pa, const void *pb) {
  const share_rec *a = pa, *b = pb;
  return (a->g > b->g) - (a->g < b->g);
}

static int cmp_rec_owner(const void *pa, const void *pb) {
  const share_rec *a = pa, *b = pb;
  if (a->owner != b->owner)
    return a->owner < b->owner ? -1 : 1;
  return (a->g > b->g) - (a->g < b->g);
}

/* the records send (grouped by destination, count[q] to rank q) to their
 * ranks: *recv (malloc'd, each record's owner its sender), *nrecv of them
 * (collective) */
static sph_status send_recs(const share_rec *send, const int *count,
                            MPI_Datatype type, share_rec **recv, size_t *nrecv,
                            sph_error *err) {
  int R = world_size;
  int *rcount = malloc(4 * (size_t)R * sizeof *rcount);
  int *soff = rcount + R, *roff = rcount + 2 * R, *scount = rcount + 3 * R;
  int ok = rcount != NULL, all = 0;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (!all) {
    free(rcount);
    return sph_error_set(err, SPH_ERR_NOMEM, "decomposition");
  }
  memcpy(scount, count, (size_t)R * sizeof *scount);
  MPI_Alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, MPI_COMM_WORLD);
  size_t n = 0;
  for (int q = 0; q < R; ++q) {
    soff[q] = q ? soff[q - 1] + scount[q - 1] : 0;
    roff[q] = (int)n;
    n += (size_t)rcount[q];
  }
  *recv = malloc((n ? n : 1) * sizeof **recv);
  ok = *recv != NULL;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (all)
    MPI_Alltoallv(send, scount, soff, type, *recv, rcount, roff, type,
                  MPI_COMM_WORLD);
  for (int q = 0; all && q < R; ++q)
    for (int k = 0; k < rcount[q]; ++k)
      (*recv)[roff[q] + k].owner = q;
  free(rcount);
  *nrecv = n;
  if (!all) {
    free(*recv);
    *recv = NULL;
    return sph_error_set(err, SPH_ERR_NOMEM, "decomposition");
  }
  return SPH_OK;
}

/* the ghosts among the owned records own (storage order) and the
 * candidates cand (others' particles in the owned box widened by
 * `support`): as find_ghosts, whose pairs of an owned particle and another
 * rank's are those among the candidates and the owned particles within
 * their ranks' widened boxes (edge); *ghost (malloc'd) by owner and
 * storage index */
static sph_status share_ghosts(const share_rec *own, size_t n, share_rec *cand,
                               size_t nc, int dim, double support,
                               share_rec **ghost, size_t *ng, sph_error *err) {
  size_t m = nc;
  for (size_t a = 0; a < n; ++a)
    m += own[a].edge != 0;
  share_rec *all = malloc((m ? m : 1) * sizeof *all);
  double *cx = malloc(3 * (m ? m : 1) * sizeof *cx);
  int32_t *cb = malloc((m ? m : 1) * sizeof *cb);
  char *is_ghost = calloc(m ? m : 1, 1);
  sph_neighbors *nl = NULL;
  sph_status st = all && cx && cb && is_ghost
                      ? sph_neighbors_create(&nl, err)
                      : sph_error_set(err, SPH_ERR_NOMEM, "ghost search");
  if (st == SPH_OK) {
    memcpy(all, cand, nc * sizeof *all);
    for (size_t a = 0, j = nc; a < n; ++a)
      if (own[a].edge)
        all[j++] = own[a];
    qsort(all, m, sizeof *all, cmp_rec_storage);
    for (size_t j = 0; j < m; ++j) {
      memcpy(cx + 3 * j, all[j].X, 3 * sizeof *cx);
      cb[j] = all[j].body;
    }
    st = sph_neighbors_build(nl, cx, m, dim, support, cb, SPH_PAIRS_SAME_BODY,
                             err);
  }
  for (size_t j = 0; st == SPH_OK && j < m; ++j) {
    if (all[j].owner != world_rank)
      continue;
    for (size_t k = nl->offset[j]; k < nl->offset[j + 1]; ++k)
      if (all[nl->index[k]].owner != world_rank)
        is_ghost[nl->index[k]] = 1;
  }
  *ng = 0;
  for (size_t j = 0; st == SPH_OK && j < m; ++j)
    if (is_ghost[j])
      all[(*ng)++] = all[j];
  if (st == SPH_OK)
    qsort(all, *ng, sizeof *all, cmp_rec_owner);
  sph_neighbors_destroy(nl);
  free(cx);
  free(cb);
  free(is_ghost);
  if (st != SPH_OK) {
    free(all);
    all = NULL;
  }
  *ghost = all;
  return st;
}

/* the owned set from the owned records, in storage order */
static sph_status share_owned_set(const share_rec *own, size_t n,
                                  size_t capacity, int dim, sph_particles **out,
                                  sph_error *err) {
  SPH_TRY(sph_particles_create(out, capacity, dim, err));
  sph_particles *o = *out;
  SPH_TRY(sph_particles_require(o, SPH_FIELD_VELOCITY, err));
  for (size_t a = 0; a < n; ++a) {
    memcpy(o->field[SPH_FIELD_POSITION0] + 3 * a, own[a].X, 3 * sizeof(double));
    o->field[SPH_FIELD_VOLUME0][a] = own[a].V;
    memcpy(o->field[SPH_FIELD_VELOCITY] + 3 * a, own[a].v, 3 * sizeof(double));
    o->id[a] = own[a].id;
    o->body[a] = own[a].body;
    o->flags[a] = own[a].flags;
  }
  o->n = n;
  return SPH_OK;
}

/* find_ghosts' test: X in the box lo, hi (6 values) widened by w */
static int in_box(const double *box, const double X[3], int dim, double w) {
  int in = 1;
  for (int c = 0; c < dim; ++c)
    in &= X[c] >= box[c] - w && X[c] <= box[3 + c] + w;
  return in;
}

/* whether X lies in one of the nb boxes b widened by w (all: every X) */
static int in_boxes(const double *b, size_t nb, int all, const double X[3],
                    int dim, double w) {
  for (size_t k = 0; !all && k < nb; ++k)
    all = in_box(b + 6 * k, X, dim, w);
  return all;
}

/* each rank's owned records to the ranks whose owned box, widened by
 * `support`, holds them; with planes, to those whose box or one of its
 * reflections (find_mirror_ghosts' boxes), widened by two supports, holds
 * them (collective) */
static sph_status share_candidates(share_rec *own, size_t n, int dim,
                                   double support,
                                   const sph_domain_plane *planes, int np,
                                   MPI_Datatype type, share_rec **cand,
                                   size_t *nc, sph_error *err) {
  int R = world_size;
  size_t max = np ? SPH_DOMAIN_MIRROR_BOXES : 1;
  double *box = malloc(6 * max * sizeof *box);
  int *nbox = malloc((4 * (size_t)R + 1) * sizeof *nbox);
  int *count = calloc((size_t)R, sizeof *count);
  int ok = box && nbox && count, all = 0;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (!all) {
    free(box);
    free(nbox);
    free(count);
    return sph_error_set(err, SPH_ERR_NOMEM, "ghost search");
  }
  for (int c = 0; c < 3; ++c)
    box[c] = INFINITY, box[3 + c] = -INFINITY;
  for (size_t a = 0; a < n; ++a)
    for (int c = 0; c < dim; ++c) {
      box[c] = fmin(box[c], own[a].X[c]);
      box[3 + c] = fmax(box[3 + c], own[a].X[c]);
    }
  for (int c = dim; np && c < 3; ++c)
    box[c] = box[3 + c] = 0.0;
  /* the boxes' count and whether they settled (else: every particle) */
  int mine[2] = {1, 0};
  if (np) {
    size_t nb = sph_domain_mirror_boxes(planes, np, 4.0 * support,
                                        1e-9 * support, 16, box, max);
    mine[0] = nb ? (int)nb : 1;
    mine[1] = nb == 0;
  }
  int *cnt = nbox + 2 * R, *off = cnt + R; /* 2 R, R, R + 1 */
  MPI_Allgather(mine, 2, MPI_INT, nbox, 2, MPI_INT, MPI_COMM_WORLD);
  off[0] = 0;
  for (int q = 0; q < R; ++q) {
    cnt[q] = 6 * nbox[2 * q];
    off[q + 1] = off[q] + cnt[q];
  }
  double *boxes = malloc(((size_t)off[R] + 1) * sizeof *boxes);
  ok = boxes != NULL;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (all)
    MPI_Allgatherv(box, 6 * mine[0], MPI_DOUBLE, boxes, cnt, off, MPI_DOUBLE,
                   MPI_COMM_WORLD);
  free(box);
  double w = np ? 2.0 * support : support;
  size_t total = 0;
  for (int q = 0; all && q < R; ++q)
    for (size_t a = 0; q != world_rank && a < n; ++a) {
      const double *b = boxes + off[q];
      /* pairs with the rank's own particles: within its box */
      if (in_box(b, own[a].X, dim, support))
        own[a].edge = 1;
      if (in_boxes(b, (size_t)nbox[2 * q], nbox[2 * q + 1], own[a].X, dim, w))
        count[q]++, total++;
    }
  share_rec *send = malloc((total ? total : 1) * sizeof *send);
  ok = all && send != NULL;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  sph_status st =
      all ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "ghost search");
  size_t k = 0;
  for (int q = 0; st == SPH_OK && q < R; ++q)
    for (size_t a = 0; q != world_rank && a < n; ++a)
      if (in_boxes(boxes + off[q], (size_t)nbox[2 * q], nbox[2 * q + 1],
                   own[a].X, dim, w))
        send[k++] = own[a];
  if (st == SPH_OK)
    st = send_recs(send, count, type, cand, nc, err);
  free(send);
  free(boxes);
  free(nbox);
  free(count);
  return st;
}

/* sph_domain_create_share, with planes sph_domain_create_mirrored's
 * ghosts: every candidate (each lies in a box of find_mirror_ghosts), the
 * usefulness check counting those within one support of an owned one */
static sph_status share_create(sph_domain **out, sph_particles **ps,
                               const int64_t *gidx, size_t N, double support,
                               int dynamic, const sph_domain_plane *planes,
                               int np, sph_error *err) {
  *out = NULL;
  sph_particles *in = *ps;
  size_t m = in->n;
  int R = world_size, dim = in->dim;
  sph_domain *d = calloc(1, sizeof *d);
  int *owner = malloc((m ? m : 1) * sizeof *owner);
  int *count = calloc((size_t)R, sizeof *count);
  share_rec *send = malloc((m ? m : 1) * sizeof *send);
  int *axis = malloc(((size_t)R + 1) * sizeof *axis);
  double *cut = malloc(((size_t)R + 1) * sizeof *cut);
  size_t cap = dynamic ? sph_domain_dyn_capacity(N, R) : 0;
  if (d) {
    d->rank = world_rank;
    d->size = world_size;
    d->dim = dim;
    d->sums = malloc((size_t)world_size * 16 * sizeof *d->sums);
  }
  sph_status st = d && d->sums && owner && count && send && axis && cut
                      ? SPH_OK
                      : sph_error_set(err, SPH_ERR_NOMEM, "decomposition");
  sph_domain world = {.rank = world_rank, .size = world_size};
  st = sph_domain_agree(&world, st, err);
  MPI_Datatype type;
  MPI_Type_contiguous((int)sizeof(share_rec), MPI_BYTE, &type);
  MPI_Type_commit(&type);
  /* sph_domain_rcb's partition: ties by storage index */
  if (st == SPH_OK) {
    sph_domain_rcb_counted(in->field[SPH_FIELD_POSITION0], gidx, m, dim, owner,
                           axis, cut, NULL);
    for (size_t i = 0; i < m; ++i)
      if (owner[i] < 0)
        st = sph_error_set(err, SPH_ERR_NOMEM, "decomposition");
  }
  /* every particle to its owner */
  share_rec *own = NULL, *cand = NULL, *ghost = NULL;
  size_t nc = 0, ng = 0;
  if (st == SPH_OK) {
    int *at = calloc((size_t)R + 1, sizeof *at);
    for (size_t i = 0; at && i < m; ++i)
      count[owner[i]]++, at[owner[i] + 1]++;
    for (int q = 0; at && q < R; ++q)
      at[q + 1] += at[q];
    for (size_t i = 0; at && i < m; ++i) {
      share_rec *r = &send[at[owner[i]]++];
      memcpy(r->X, in->field[SPH_FIELD_POSITION0] + 3 * i, sizeof r->X);
      r->V = in->field[SPH_FIELD_VOLUME0][i];
      memcpy(r->v, in->field[SPH_FIELD_VELOCITY] + 3 * i, sizeof r->v);
      r->id = in->id[i];
      r->g = gidx[i];
      r->body = in->body[i];
      r->flags = in->flags[i];
      r->edge = 0;
    }
    st = sph_domain_agree(
        &world, at ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "ghosts"), err);
    free(at);
  }
  /* the share is in the records now */
  if (st == SPH_OK) {
    sph_particles_destroy(in);
    *ps = NULL;
  }
  if (st == SPH_OK)
    st = send_recs(send, count, type, &own, &d->n, err);
  free(send);
  free(count);
  free(owner);
  if (st == SPH_OK) {
    qsort(own, d->n, sizeof *own, cmp_rec_storage);
    for (size_t a = 0; a < d->n; ++a)
      own[a].owner = world_rank;
    /* a dynamic domain finds its ghosts at each rebuild */
    if (!dynamic)
      st = share_candidates(own, d->n, dim, support, planes, np, type, &cand,
                            &nc, err);
  }
  if (st == SPH_OK && !dynamic)
    st = share_ghosts(own, d->n, cand, nc, dim, support, &ghost, &ng, err);
  size_t ng_support = ng;
  if (st == SPH_OK && np > 0 && !dynamic) {
    free(ghost);
    qsort(cand, nc, sizeof *cand, cmp_rec_owner);
    ghost = cand, ng = nc;
    cand = NULL;
  }
  free(cand);
  if (st == SPH_OK) {
    d->ng = ng;
    size_t gm = d->n + ng > cap ? d->n + ng : cap;
    d->gidx = malloc((gm ? gm : 1) * sizeof *d->gidx);
    d->gX = malloc(3 * (ng + 1) * sizeof *d->gX);
    d->gV = malloc((ng + 1) * sizeof *d->gV);
    d->gbody = malloc((ng + 1) * sizeof *d->gbody);
    d->gid = malloc((ng + 1) * sizeof *d->gid);
    if (!d->gidx || !d->gX || !d->gV || !d->gbody || !d->gid)
      st = sph_error_set(err, SPH_ERR_NOMEM, "ghosts");
  }
  int *gowner = NULL;
  if (st == SPH_OK && !(gowner = malloc((ng + 1) * sizeof *gowner)))
    st = sph_error_set(err, SPH_ERR_NOMEM, "ghosts");
  if (st == SPH_OK) {
    for (size_t a = 0; a < d->n; ++a)
      d->gidx[a] = own[a].g;
    for (size_t j = 0; j < ng; ++j) {
      d->gidx[d->n + j] = ghost[j].g;
      memcpy(d->gX + 3 * j, ghost[j].X, 3 * sizeof *d->gX);
      d->gV[j] = ghost[j].V;
      d->gbody[j] = ghost[j].body;
      d->gid[j] = ghost[j].id;
      gowner[j] = ghost[j].owner;
    }
  }
  free(ghost);
  MPI_Type_free(&type);
  st = sph_domain_agree(&world, st, err);
  if (st == SPH_OK)
    st = halo_plan(d, st, ng_support, N, gowner, err);
  free(gowner);
  sph_particles *mine = NULL;
  if (st == SPH_OK)
    st = share_owned_set(own, d->n, cap > d->n ? cap : d->n, dim, &mine, err);
  free(own);
  st = sph_domain_agree(&world, st, err);
  if (st == SPH_OK)
    d->total = N;
  if (st == SPH_OK && dynamic)
    st = sph_domain_dyn_create(d, N, axis, cut, err);
  st = sph_domain_agree(&world, st, err);
  free(axis);
  free(cut);
  if (st != SPH_OK) {
    sph_particles_destroy(mine);
    sph_domain_destroy(d);
    return st;
  }
  *ps = mine;
  *out = d;
  return SPH_OK;
}

sph_status sph_domain_create_share(sph_domain **out, sph_particles **ps,
                                   const int64_t *gidx, size_t N,
                                   double support, int dynamic,
                                   sph_error *err) {
  return share_create(out, ps, gidx, N, support, dynamic, NULL, 0, err);
}

sph_status sph_domain_world_agree(sph_status st, sph_error *err) {
  return sph_domain_world_first(st, INT64_MAX, err);
}

sph_status sph_domain_world_first(sph_status st, int64_t key, sph_error *err) {
  if (world_size < 2)
    return st;
  /* the failing rank of the lowest key, then of the lowest rank */
  int64_t mine[2] = {st != SPH_OK ? key : INT64_MAX,
                     st != SPH_OK ? world_rank : world_size},
          low[2];
  MPI_Allreduce(mine, low, 1, MPI_INT64_T, MPI_MIN, MPI_COMM_WORLD);
  if (mine[0] != low[0])
    mine[1] = world_size;
  MPI_Allreduce(mine + 1, low + 1, 1, MPI_INT64_T, MPI_MIN, MPI_COMM_WORLD);
  if (low[1] == world_size)
    return SPH_OK;
  sph_error e;
  if (low[1] == world_rank)
    e = *err;
  MPI_Bcast(&e, (int)sizeof e, MPI_BYTE, (int)low[1], MPI_COMM_WORLD);
  *err = e;
  return e.code != SPH_OK ? e.code : SPH_ERR_IO;
}

int sph_domain_node_size(void) {
  if (world_size < 2)
    return 1;
  MPI_Comm node;
  int n = 1;
  if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, world_rank,
                          MPI_INFO_NULL, &node) != MPI_SUCCESS)
    return world_size;
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
  int rc = MPI_Waitall(nr, req, MPI_STATUSES_IGNORE);
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
  MPI_Allreduce(&v, &out, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  d->seconds += MPI_Wtime() - t0;
  return out;
}

double sph_domain_max(sph_domain *d, double v) {
  double out = v;
  if (d)
    MPI_Allreduce(&v, &out, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
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
    MPI_Allreduce(v, r, 2 * m, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
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
  MPI_Allgather(mine, count, MPI_DOUBLE, all, count, MPI_DOUBLE,
                MPI_COMM_WORLD);
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
    MPI_Allgather(v + off, (int)m, MPI_DOUBLE, work, (int)m, MPI_DOUBLE,
                  MPI_COMM_WORLD);
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
  if (d)
    MPI_Bcast(&v, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return v;
}

void sph_domain_gather_u64(sph_domain *d, const uint64_t *v, int count,
                           uint64_t *out) {
  if (d)
    MPI_Gather(v, count, MPI_UINT64_T, out, count, MPI_UINT64_T, 0,
               MPI_COMM_WORLD);
}

sph_status sph_domain_agree(sph_domain *d, sph_status st, sph_error *err) {
  if (!d)
    return st;
  int mine = st != SPH_OK ? d->rank : d->size, first = d->size;
  double t0 = MPI_Wtime();
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
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

sph_status sph_domain_create(sph_domain **out, sph_particles **ps,
                             double support, sph_error *err) {
  (void)ps, (void)support;
  *out = NULL;
  return sph_error_set(err, SPH_ERR_UNSUPPORTED, "built without MPI");
}

sph_status sph_domain_create_dynamic(sph_domain **out, sph_particles **ps,
                                     double support, sph_error *err) {
  return sph_domain_create(out, ps, support, err);
}

sph_status sph_domain_create_mirrored(sph_domain **out, sph_particles **ps,
                                      double support,
                                      const sph_domain_plane *planes,
                                      int nplanes, sph_error *err) {
  (void)planes, (void)nplanes;
  return sph_domain_create(out, ps, support, err);
}

sph_status sph_domain_create_share(sph_domain **out, sph_particles **ps,
                                   const int64_t *gidx, size_t N,
                                   double support, int dynamic,
                                   sph_error *err) {
  (void)gidx, (void)N, (void)dynamic;
  return sph_domain_create(out, ps, support, err);
}

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

sph_status sph_domain_create_share_mirrored(sph_domain **out,
                                            sph_particles **ps,
                                            const int64_t *gidx, size_t N,
                                            double support,
                                            const sph_domain_plane *planes,
                                            int nplanes, sph_error *err) {
#ifdef SPH_HAVE_MPI
  return share_create(out, ps, gidx, N, support, 0, planes, nplanes, err);
#else
  (void)gidx, (void)N, (void)planes, (void)nplanes;
  return sph_domain_create(out, ps, support, err);
#endif
}

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
