/* Domain decomposition over MPI ranks (issue 20): recursive coordinate
 * bisection of the reference positions balanced by count, ghost layers of
 * one kernel support found with the cell-list search, a fixed halo exchange
 * with MPI_Irecv/MPI_Isend, reductions in rank order and the gather of the
 * output fields to rank 0. Every MPI call of sph is in this file and
 * domain_dynamic.c (the updated-Lagrangian rebuild). */
#include "sph/domain.h"
#include "parallel/domain_impl.h"

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
sph_particles *sph_domain_global(const sph_domain *d) {
  return d ? d->all : NULL;
}
size_t sph_domain_particles(const sph_domain *d, const sph_particles *ps) {
  return d ? d->total : ps->n;
}
void sph_domain_drop_global(sph_domain *d) {
  if (!d)
    return;
  sph_particles_destroy(d->all);
  free(d->gbuf);
  free(d->all_gidx);
  d->all = NULL;
  d->gbuf = NULL;
  d->all_gidx = NULL;
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
  sph_particles_destroy(d->all);
  free(d->all_count);
  free(d->all_off);
  free(d->all_gidx);
  free(d->gbuf);
  free(d->counts);
  free(d->offs);
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

/* particles (of idx, m local) at or below the key (v, w) over all ranks */
static int64_t count_below(const uint64_t *u, const int64_t *t,
                           const size_t *idx, size_t m, uint64_t v, int64_t w,
                           int ties) {
  int64_t c = 0, all = 0;
  for (size_t j = 0; j < m; ++j)
    c += ties ? u[idx[j]] < v || (u[idx[j]] == v && t[idx[j]] <= w)
              : u[idx[j]] <= v;
  MPI_Allreduce(&c, &all, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  return all;
}

/* sph_domain_rcb's recursion over the local particles idx of ranks rank0
 * .. rank0 + nranks - 1: the box and count from reductions, the cut-th
 * key (coordinate, tie key) by bisection of its bits */
static void rcb_counted(const double *X, const int64_t *t, uint64_t *u,
                        size_t *idx, size_t m, int dim, int rank0, int nranks,
                        int *owner) {
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
  int64_t mine = (int64_t)m, n = 0;
  MPI_Allreduce(&mine, &n, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  int nlo = nranks / 2;
  int64_t cut = n * nlo / nranks;
  for (size_t j = 0; j < m; ++j)
    u[idx[j]] = ordered_bits(X[3 * idx[j] + ax]);
  /* the smallest coordinate key with cut particles at or below it, then
   * the smallest tie key among its particles that completes the cut */
  uint64_t lo = 0, top = UINT64_MAX;
  while (cut > 0 && lo < top) {
    uint64_t mid = lo + (top - lo) / 2;
    if (count_below(u, t, idx, m, mid, 0, 0) >= cut)
      top = mid;
    else
      lo = mid + 1;
  }
  int64_t wlo = INT64_MIN, wtop = INT64_MAX;
  while (cut > 0 && wlo < wtop) {
    int64_t mid = wlo + (int64_t)(((uint64_t)wtop - (uint64_t)wlo) / 2);
    if (count_below(u, t, idx, m, lo, mid, 1) >= cut)
      wtop = mid;
    else
      wlo = mid + 1;
  }
  /* the low ranks' particles first in idx */
  size_t nb = 0;
  for (size_t j = 0; j < m; ++j) {
    size_t i = idx[j];
    if (cut > 0 && (u[i] < lo || (u[i] == lo && t[i] <= wlo))) {
      idx[j] = idx[nb];
      idx[nb++] = i;
    }
  }
  rcb_counted(X, t, u, idx, nb, dim, rank0, nlo, owner);
  rcb_counted(X, t, u, idx + nb, m - nb, dim, rank0 + nlo, nranks - nlo, owner);
}

void sph_domain_rcb_counted(const double *X, const int64_t *t, size_t n,
                            int dim, int *owner) {
  uint64_t *u = malloc((n ? n : 1) * sizeof *u);
  size_t *idx = malloc((n ? n : 1) * sizeof *idx);
  for (size_t i = 0; idx && i < n; ++i)
    idx[i] = i;
  int ok = u && idx, all = 0;
  MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (all)
    rcb_counted(X, t, u, idx, n, dim, 0, world_size, owner);
  else
    for (size_t i = 0; i < n; ++i)
      owner[i] = -1;
  free(u);
  free(idx);
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
  return p->axis >= 0
             ? X[p->axis] - p->at
             : X[0] * p->n[0] + X[1] * p->n[1] + X[2] * p->n[2] - p->at;
}

/* reflection of the box lo, hi (bounding the reflected corners) */
static void reflect_box(const sph_domain_plane *p, const double *lo,
                        const double *hi, double *out) {
  double *olo = out, *ohi = out + 3;
  for (int c = 0; c < 3; ++c)
    olo[c] = INFINITY, ohi[c] = -INFINITY;
  for (int k = 0; k < 8; ++k) {
    double X[3], dist = box_corner(p, lo, hi, k, X);
    for (int c = 0; c < 3; ++c) {
      double y = p->axis >= 0 ? (c == p->axis ? 2.0 * p->at - X[c] : X[c])
                              : X[c] - 2.0 * dist * p->n[c];
      olo[c] = fmin(olo[c], y);
      ohi[c] = fmax(ohi[c], y);
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

#define MIRROR_BOXES 4096

/* the ghosts mirror images need (sph_domain_create_mirrored): the box of
 * the owned particles and its reflections across every plane it comes
 * within four supports of, chained until no new box appears; ghost[i] = 1
 * for every other rank's particle within two supports of one of the boxes
 * (all of them when the boxes do not settle) */
static sph_status find_mirror_ghosts(const sph_particles *ps, const int *owner,
                                     int r, double support,
                                     const sph_domain_plane *planes, int np,
                                     char *ghost, sph_error *err) {
  size_t N = ps->n, nb = 1;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  double *box = malloc(6 * MIRROR_BOXES * sizeof *box);
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
  double tol = 1e-9 * support;
  int grew = 1, full = 0;
  for (int pass = 0; grew && !full && pass < 16; ++pass) {
    grew = 0;
    for (int k = 0; k < np && !full; ++k)
      for (size_t b = 0, count = nb; b < count && !full; ++b) {
        double img[6];
        if (!box_near(&planes[k], box + 6 * b, box + 6 * b + 3, 4.0 * support))
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
        if (nb == MIRROR_BOXES) {
          full = 1;
          break;
        }
        memcpy(box + 6 * nb++, img, sizeof img);
        grew = 1;
      }
  }
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
static sph_status exchange_plan(sph_domain *d, const int *owner,
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
    d->recv_count[owner[d->gidx[d->n + g]]]++;
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

/* rank 0 learns every rank's owned storage indices (the gather's map) */
static sph_status gather_plan(sph_domain *d, size_t N, sph_error *err) {
  int R = d->size;
  int fail = 0;
  d->total = N;
  if (d->rank == 0) {
    d->all_count = malloc((size_t)R * sizeof(int));
    d->all_off = malloc(((size_t)R + 1) * sizeof(int));
    d->counts = malloc((size_t)R * sizeof(int));
    d->offs = malloc((size_t)R * sizeof(int));
    d->all_gidx = malloc((N ? N : 1) * sizeof(int64_t));
    d->gbuf = malloc(9 * (N ? N : 1) * sizeof(double));
    fail = !d->all_count || !d->all_off || !d->counts || !d->offs ||
           !d->all_gidx || !d->gbuf;
  }
  sph_status st = fail ? sph_error_set(err, SPH_ERR_NOMEM, "gather") : SPH_OK;
  SPH_TRY(sph_domain_agree(d, st, err));
  sph_domain_gather_map(d);
  return SPH_OK;
}

void sph_domain_gather_map(sph_domain *d) {
  int R = d->size, n = (int)d->n;
  MPI_Gather(&n, 1, MPI_INT, d->all_count, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (d->rank == 0) {
    d->all_off[0] = 0;
    for (int q = 0; q < R; ++q)
      d->all_off[q + 1] = d->all_off[q] + d->all_count[q];
  }
  MPI_Gatherv(d->gidx, n, MPI_INT64_T, d->all_gidx, d->all_count, d->all_off,
              MPI_INT64_T, 0, MPI_COMM_WORLD);
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
    d->gathered = ~0ul;
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
  /* a halo larger than the domain: more ranks than useful */
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
    st = exchange_plan(d, owner, err);
  st = sph_domain_agree(d, st, err);
  sph_particles *mine = NULL;
  if (st == SPH_OK)
    st = owned_set(all, d, cap > d->n ? cap : d->n, &mine, err);
  st = sph_domain_agree(d, st, err);
  if (st == SPH_OK)
    st = gather_plan(d, N, err);
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
  /* rank 0 keeps the whole set for the outputs */
  if (world_rank == 0)
    d->all = all;
  else
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

void sph_domain_gather_select(sph_domain *d, unsigned long fields) {
  if (d)
    d->gathered = fields;
}

sph_status sph_domain_gather(sph_domain *d, const sph_particles *local,
                             sph_error *err) {
  if (!d)
    return SPH_OK;
  sph_status st = SPH_OK;
  sph_particles *all = d->all;
  double t0 = MPI_Wtime();
  if (d->dyn) /* the owned sets change at every migration */
    sph_domain_gather_map(d);
  for (int f = 0; f < SPH_FIELD_COUNT; ++f) {
    /* the reference positions and volumes never change */
    if (!local->field[f] || f == SPH_FIELD_POSITION0 ||
        f == SPH_FIELD_VOLUME0 || !(d->gathered & 1ul << f))
      continue;
    int nc = sph_field_components((sph_field)f);
    if (d->rank == 0) {
      for (int q = 0; q < d->size; ++q) {
        d->counts[q] = nc * d->all_count[q];
        d->offs[q] = nc * d->all_off[q];
      }
      if (st == SPH_OK)
        st = sph_particles_require(all, (sph_field)f, err);
    }
    MPI_Gatherv(local->field[f], nc * (int)local->n, MPI_DOUBLE, d->gbuf,
                d->counts, d->offs, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (d->rank == 0 && st == SPH_OK) {
      size_t N = all->n, w = (size_t)nc;
      for (size_t k = 0; k < N; ++k)
        memcpy(all->field[f] + w * (size_t)d->all_gidx[k], d->gbuf + w * k,
               w * sizeof(double));
    }
  }
  MPI_Gatherv(local->flags, (int)local->n, MPI_UINT32_T, d->gbuf, d->all_count,
              d->all_off, MPI_UINT32_T, 0, MPI_COMM_WORLD);
  if (d->rank == 0) {
    const uint32_t *fl = (const uint32_t *)d->gbuf;
    for (size_t k = 0; k < all->n; ++k)
      all->flags[d->all_gidx[k]] = fl[k];
  }
  d->seconds += MPI_Wtime() - t0;
  return sph_domain_agree(d, st, err);
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
  int R = d->size, mine = (int)nwant;
  size_t nc = (size_t)ncomp;
  int *cnt = malloc(2 * ((size_t)R + 1) * sizeof *cnt);
  if (!cnt)
    return sph_error_set(err, SPH_ERR_NOMEM, "fetch");
  int *off = cnt + R + 1;
  MPI_Allgather(&mine, 1, MPI_INT, cnt, 1, MPI_INT, MPI_COMM_WORLD);
  off[0] = 0;
  for (int q = 0; q < R; ++q)
    off[q + 1] = off[q] + cnt[q];
  size_t total = (size_t)off[R];
  if (total == 0) {
    free(cnt);
    d->seconds += MPI_Wtime() - t0;
    return SPH_OK;
  }
  int64_t *all = malloc(total * sizeof *all);
  double *ans = calloc(total * nc, sizeof *ans);
  long f = !all || !ans, anyfail = 0;
  MPI_Allreduce(&f, &anyfail, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
  if (!anyfail) {
    MPI_Allgatherv(want, mine, MPI_INT64_T, all, cnt, off, MPI_INT64_T,
                   MPI_COMM_WORLD);
    /* the owner answers, the others add zeros: the sum is exact */
    for (size_t i = 0; i < total; ++i) {
      const int64_t *k =
          n ? bsearch(all + i, key, n, sizeof *key, cmp_i64) : NULL;
      if (k)
        memcpy(ans + nc * i, val + nc * (size_t)(k - key), nc * sizeof *ans);
    }
    MPI_Allreduce(MPI_IN_PLACE, ans, (int)(total * nc), MPI_DOUBLE, MPI_SUM,
                  MPI_COMM_WORLD);
    memcpy(out, ans + nc * (size_t)off[d->rank], nc * nwant * sizeof *out);
  }
  free(cnt);
  free(all);
  free(ans);
  d->seconds += MPI_Wtime() - t0;
  return anyfail ? sph_error_set(err, SPH_ERR_NOMEM, "fetch") : SPH_OK;
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

sph_status sph_domain_exchange(sph_domain *d, double *field, int ncomp,
                               sph_error *err) {
  (void)d, (void)field, (void)ncomp, (void)err;
  return SPH_OK;
}

double sph_domain_min(sph_domain *d, double v) { return (void)d, v; }
double sph_domain_max(sph_domain *d, double v) { return (void)d, v; }
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
sph_status sph_domain_gather(sph_domain *d, const sph_particles *local,
                             sph_error *err) {
  (void)d, (void)local, (void)err;
  return SPH_OK;
}
void sph_domain_gather_select(sph_domain *d, unsigned long fields) {
  (void)d, (void)fields;
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
