/* Updated-Lagrangian runs over MPI ranks (issue 20): the ghosts found again
 * at every rebuild of the neighbour lists (the other ranks' particles in a
 * rank's box of owned particles widened by the search radius), migration of
 * the particles that left their rank's region of the recursive coordinate
 * bisection (the cut planes of the last partition) to their owner with all
 * their per-particle values, re-balancing by a new RCB of the current
 * positions when the count imbalance exceeds SPH_DOMAIN_IMBALANCE (by
 * counting bisection over the owned particles: no rank holds them all),
 * and a halo exchange of several arrays in one message per neighbour rank; for
 * checkpoints, a rank's owned particles packed with the cut tree and the
 * halo plan, put back in place on --resume. Every
 * buffer is sized at set-up (or at the first rebuild, in the method's
 * set-up); a rank that would outgrow them fails with SPH_ERR_RANGE. */
#include "parallel/domain_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef SPH_HAVE_MPI
#include <mpi.h>
#endif

#define DYN_MAX_ARRAYS 32
#define DYN_MAX_WIDTH 32 /* doubles a particle in sph_domain_exchange_many */

struct sph_domain_dyn {
  size_t cap, N;
  int *axis;   /* the cut tree: ranks from s on lie at or above cut[s] */
  double *cut; /* along axis[s], s = 1 .. R - 1 */
  double *arr[DYN_MAX_ARRAYS]; /* the method's own per-particle arrays */
  int nc[DYN_MAX_ARRAYS];
  int narr;
  int width;      /* doubles a packed particle; 0 before the first rebuild */
  double *in;     /* packed particles received (cap) */
  int *dest;      /* owner after the rebuild, per owned particle (cap) */
  int *cs, *cr;   /* particles sent to, received from each rank */
  int *os, *orr;  /* their first packed particle */
  int *at;        /* packing cursor per rank */
  double *box;    /* 6 per rank: the owned particles' boxes, widened */
  int *count;     /* owned per rank */
  uint64_t *work; /* re-balance: 2 keys per owned particle (cap) */
  double migrated, rebalances, rebuilds;
  double halo_max, ghosts_max; /* the largest halo and ghost layer */
  double *ckpt;                /* a checkpoint's domain state (ckpt_len) */
  int resumed; /* the next rebuild sends the checkpoint's ghosts */
  /* symmetry planes: ghosts also around the box's reflections */
  sph_domain_plane planes[32];
  int np;
  double depth; /* supports around each box */
  double *mbox; /* the boxes of one rank (SPH_DOMAIN_MIRROR_BOXES) */
};

size_t sph_domain_dyn_capacity(size_t N, int R) {
  /* owned with the imbalance allowed, and as many ghosts (more ghosts than
   * owned particles: more ranks than useful) */
  size_t c = (size_t)ceil(2.5 * (double)N / (double)R) + 64;
  return c < N ? c : N;
}

void sph_domain_dyn_destroy(sph_domain_dyn *y) {
  if (!y)
    return;
  free(y->axis);
  free(y->cut);
  free(y->in);
  free(y->dest);
  free(y->cs);
  free(y->cr);
  free(y->os);
  free(y->orr);
  free(y->at);
  free(y->box);
  free(y->count);
  free(y->work);
  free(y->ckpt);
  free(y->mbox);
  free(y);
}

size_t sph_domain_capacity(const sph_domain *d, const sph_particles *ps) {
  return d && d->dyn ? d->dyn->cap : ps->n;
}

sph_status sph_domain_track(sph_domain *d, double *array, int ncomp,
                            sph_error *err) {
  if (!d || !d->dyn)
    return SPH_OK;
  sph_domain_dyn *y = d->dyn;
  if (y->narr == DYN_MAX_ARRAYS || y->width)
    return sph_error_set(err, SPH_ERR_RANGE,
                         "domain: at most %d tracked arrays, registered "
                         "before the first rebuild",
                         DYN_MAX_ARRAYS);
  y->arr[y->narr] = array;
  y->nc[y->narr++] = ncomp;
  return SPH_OK;
}

sph_domain_moves sph_domain_moves_of(const sph_domain *d) {
  sph_domain_moves m = {0.0, 0.0, 0.0, 0.0, 0.0};
  if (d && d->dyn)
    m = (sph_domain_moves){d->dyn->migrated, d->dyn->rebalances,
                           d->dyn->rebuilds, d->dyn->halo_max,
                           d->dyn->ghosts_max};
  return m;
}

#ifdef SPH_HAVE_MPI

/* doubles of a checkpoint's domain state: the rank count, the packed
 * width, the 5 counters, the cut tree (axis and cut, R + 1 each), the send
 * counts (R) and the send list (room for cap) */
static size_t ckpt_len(size_t R, size_t cap) { return 9 + 3 * R + cap; }

sph_status sph_domain_dyn_create(sph_domain *d, size_t N, const int *axis,
                                 const double *cut, sph_error *err) {
  size_t R = (size_t)d->size, cap = sph_domain_dyn_capacity(N, d->size);
  sph_domain_dyn *y = d->dyn = calloc(1, sizeof *y);
  if (!y)
    return sph_error_set(err, SPH_ERR_NOMEM, "dynamic domain");
  y->cap = cap;
  y->N = N;
  y->axis = malloc((R + 1) * sizeof *y->axis);
  y->cut = malloc((R + 1) * sizeof *y->cut);
  y->dest = malloc(cap * sizeof *y->dest);
  y->cs = calloc(R, sizeof *y->cs);
  y->cr = calloc(R, sizeof *y->cr);
  y->os = calloc(R + 1, sizeof *y->os);
  y->orr = calloc(R + 1, sizeof *y->orr);
  y->at = calloc(R, sizeof *y->at);
  y->box = malloc(6 * R * sizeof *y->box);
  y->count = malloc(R * sizeof *y->count);
  y->work = malloc(2 * cap * sizeof *y->work);
  y->ckpt = calloc(ckpt_len(R, cap), sizeof *y->ckpt);
  free(d->send_idx);
  d->send_idx = malloc(cap * sizeof *d->send_idx);
  if (!y->axis || !y->cut || !y->dest || !y->cs || !y->cr || !y->os ||
      !y->orr || !y->at || !y->box || !y->count || !y->work || !y->ckpt ||
      !d->send_idx)
    return sph_error_set(err, SPH_ERR_NOMEM, "dynamic domain");
  memcpy(y->axis, axis, (R + 1) * sizeof *axis);
  memcpy(y->cut, cut, (R + 1) * sizeof *cut);
  return SPH_OK;
}

/* ---- one particle's values ---------------------------------------------- */

static int packed_width(const sph_domain_dyn *y, const sph_particles *ps) {
  int w = 4; /* storage index, id, body, flags */
  for (int f = 0; f < SPH_FIELD_COUNT; ++f)
    w += ps->field[f] ? sph_field_components((sph_field)f) : 0;
  for (int i = 0; i < y->narr; ++i)
    w += y->nc[i];
  return w;
}

static void pack(const sph_domain *d, const sph_particles *ps, size_t a,
                 double *o) {
  const sph_domain_dyn *y = d->dyn;
  memcpy(o, &d->gidx[a], sizeof *o); /* integers by their bits */
  memcpy(o + 1, &ps->id[a], sizeof *o);
  o[2] = (double)ps->body[a];
  o[3] = (double)ps->flags[a];
  o += 4;
  for (int f = 0; f < SPH_FIELD_COUNT; ++f) {
    if (!ps->field[f])
      continue;
    size_t nc = (size_t)sph_field_components((sph_field)f);
    memcpy(o, ps->field[f] + nc * a, nc * sizeof *o);
    o += nc;
  }
  for (int i = 0; i < y->narr; ++i) {
    size_t nc = (size_t)y->nc[i];
    memcpy(o, y->arr[i] + nc * a, nc * sizeof *o);
    o += nc;
  }
}

static void unpack(sph_domain *d, sph_particles *ps, size_t a,
                   const double *o) {
  const sph_domain_dyn *y = d->dyn;
  memcpy(&d->gidx[a], o, sizeof *o);
  memcpy(&ps->id[a], o + 1, sizeof *o);
  ps->body[a] = (int32_t)o[2];
  ps->flags[a] = (uint32_t)o[3];
  o += 4;
  for (int f = 0; f < SPH_FIELD_COUNT; ++f) {
    if (!ps->field[f])
      continue;
    size_t nc = (size_t)sph_field_components((sph_field)f);
    memcpy(ps->field[f] + nc * a, o, nc * sizeof *o);
    o += nc;
  }
  for (int i = 0; i < y->narr; ++i) {
    size_t nc = (size_t)y->nc[i];
    memcpy(y->arr[i] + nc * a, o, nc * sizeof *o);
    o += nc;
  }
}

/* particle `from` to slot `to` of the local set */
static void move(sph_domain *d, sph_particles *ps, size_t from, size_t to) {
  const sph_domain_dyn *y = d->dyn;
  d->gidx[to] = d->gidx[from];
  ps->id[to] = ps->id[from];
  ps->body[to] = ps->body[from];
  ps->flags[to] = ps->flags[from];
  for (int f = 0; f < SPH_FIELD_COUNT; ++f) {
    size_t nc = (size_t)sph_field_components((sph_field)f);
    if (ps->field[f])
      memcpy(ps->field[f] + nc * to, ps->field[f] + nc * from,
             nc * sizeof(double));
  }
  for (int i = 0; i < y->narr; ++i) {
    size_t nc = (size_t)y->nc[i];
    memcpy(y->arr[i] + nc * to, y->arr[i] + nc * from, nc * sizeof(double));
  }
}

/* ---- the rebuild ----------------------------------------------------------
 */

/* the rank whose RCB region holds x */
static int tree_owner(const sph_domain_dyn *y, const double *x, int nranks) {
  int rank0 = 0;
  while (nranks > 1) {
    int nlo = nranks / 2, s = rank0 + nlo;
    if (x[y->axis[s]] < y->cut[s]) {
      nranks = nlo;
    } else {
      rank0 = s;
      nranks -= nlo;
    }
  }
  return rank0;
}

/* a new RCB of the current positions (ties by storage index: the
 * partition of the serial positions) by counting bisection over the owned
 * particles, and its cut tree */
static void rebalance(sph_domain *d, sph_particles *ps) {
  sph_domain_dyn *y = d->dyn;
  sph_domain_rcb_counted(ps->field[SPH_FIELD_POSITION], d->gidx, d->n, d->dim,
                         y->dest, y->axis, y->cut, y->work);
  y->rebalances += 1.0;
}

/* sends the packed particles (cs, os) and receives into y->in (cr, orr) */
static int swap(sph_domain *d, int w) {
  sph_domain_dyn *y = d->dyn;
  MPI_Request *req = d->req;
  int nr = 0;
  for (int q = 0; q < d->size; ++q)
    if (y->cr[q])
      MPI_Irecv(y->in + (size_t)w * (size_t)y->orr[q], w * y->cr[q], MPI_DOUBLE,
                q, 8, MPI_COMM_WORLD, &req[nr++]);
  for (int q = 0; q < d->size; ++q)
    if (y->cs[q])
      MPI_Isend(d->buf + (size_t)w * (size_t)y->os[q], w * y->cs[q], MPI_DOUBLE,
                q, 8, MPI_COMM_WORLD, &req[nr++]);
  return sph_domain_wait(nr, req) == MPI_SUCCESS;
}

/* the particles of this rank that belong elsewhere, to their owners */
static sph_status migrate(sph_domain *d, sph_particles *ps, sph_error *err) {
  sph_domain_dyn *y = d->dyn;
  int R = d->size, w = y->width;
  size_t n = d->n;
  memset(y->cs, 0, (size_t)R * sizeof *y->cs);
  for (size_t a = 0; a < n; ++a)
    y->cs[y->dest[a]] += y->dest[a] != d->rank;
  y->os[0] = 0;
  for (int q = 0; q < R; ++q)
    y->os[q + 1] = y->os[q] + y->cs[q];
  memcpy(y->at, y->os, (size_t)R * sizeof *y->at);
  size_t kept = 0;
  for (size_t a = 0; a < n; ++a) {
    int q = y->dest[a];
    if (q != d->rank)
      pack(d, ps, a, d->buf + (size_t)w * (size_t)y->at[q]++);
    else if (kept++ != a)
      move(d, ps, a, kept - 1);
  }
  MPI_Alltoall(y->cs, 1, MPI_INT, y->cr, 1, MPI_INT, MPI_COMM_WORLD);
  y->orr[0] = 0;
  for (int q = 0; q < R; ++q)
    y->orr[q + 1] = y->orr[q] + y->cr[q];
  size_t nin = (size_t)y->orr[R];
  sph_status st = SPH_OK;
  if (kept + nin > y->cap)
    st = sph_error_set(err, SPH_ERR_RANGE,
                       "rank %d would own %zu particles, more than the %zu "
                       "its arrays hold (migration); run on fewer ranks",
                       d->rank, kept + nin, y->cap);
  SPH_TRY(sph_domain_agree(d, st, err));
  if (!swap(d, w))
    return sph_error_set(err, SPH_ERR_IO, "migration failed");
  for (size_t k = 0; k < nin; ++k)
    unpack(d, ps, kept + k, y->in + (size_t)w * k);
  d->n = ps->n = kept + nin;
  double moved = (double)(n - kept);
  sph_domain_sum(d, &moved, 1);
  y->migrated += moved;
  return SPH_OK;
}

/* the ghosts of the send lists (cs, send_idx; k entries in all) to their
 * ranks, after the owned particles; the halo plan of sph_domain_exchange */
static sph_status send_ghosts(sph_domain *d, sph_particles *ps, size_t k,
                              sph_error *err) {
  sph_domain_dyn *y = d->dyn;
  int R = d->size, w = y->width;
  size_t n = d->n;
  MPI_Alltoall(y->cs, 1, MPI_INT, y->cr, 1, MPI_INT, MPI_COMM_WORLD);
  y->os[0] = y->orr[0] = 0;
  for (int q = 0; q < R; ++q) {
    y->os[q + 1] = y->os[q] + y->cs[q];
    y->orr[q + 1] = y->orr[q] + y->cr[q];
  }
  size_t ng = (size_t)y->orr[R];
  sph_status st = SPH_OK;
  if (k > y->cap || n + ng > y->cap)
    st = sph_error_set(err, SPH_ERR_RANGE,
                       "rank %d would hold %zu owned and %zu ghost particles "
                       "and send %zu, more than the %zu its arrays hold; run "
                       "on fewer ranks",
                       d->rank, n, ng, k, y->cap);
  SPH_TRY(sph_domain_agree(d, st, err));
  long ns = (long)k;
#pragma omp parallel for schedule(static)
  for (long j = 0; j < ns; ++j)
    pack(d, ps, (size_t)d->send_idx[j], d->buf + (size_t)w * (size_t)j);
  if (!swap(d, w))
    return sph_error_set(err, SPH_ERR_IO, "ghost exchange failed");
  long ngl = (long)ng;
#pragma omp parallel for schedule(static)
  for (long g = 0; g < ngl; ++g)
    unpack(d, ps, n + (size_t)g, y->in + (size_t)w * (size_t)g);
  /* the plan of the per-pass exchanges */
  d->ng = ng;
  d->nsend = k;
  memcpy(d->send_count, y->cs, (size_t)R * sizeof *y->cs);
  memcpy(d->send_off, y->os, ((size_t)R + 1) * sizeof *y->os);
  memcpy(d->recv_count, y->cr, (size_t)R * sizeof *y->cr);
  memcpy(d->recv_off, y->orr, ((size_t)R + 1) * sizeof *y->orr);
  return SPH_OK;
}

/* whether x lies within w of one of the nb boxes */
static int in_boxes(const double *b, size_t nb, double w, const double *x) {
  for (size_t k = 0; k < nb; ++k, b += 6)
    if (x[0] >= b[0] - w && x[1] >= b[1] - w && x[2] >= b[2] - w &&
        x[0] <= b[3] + w && x[1] <= b[4] + w && x[2] <= b[5] + w)
      return 1;
  return 0;
}

/* the other ranks' particles in this rank's box widened by radius (with
 * symmetry planes: within depth radii of the box or of its reflections), as
 * ghosts after the owned ones */
static sph_status find_ghosts(sph_domain *d, sph_particles *ps, double radius,
                              sph_error *err) {
  sph_domain_dyn *y = d->dyn;
  int R = d->size;
  size_t n = d->n;
  const double *x = ps->field[SPH_FIELD_POSITION];
  double pad = y->np ? 0.0 : radius;
  double box[6] = {INFINITY,  INFINITY,  INFINITY,
                   -INFINITY, -INFINITY, -INFINITY};
  for (size_t a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c) {
      box[c] = fmin(box[c], x[3 * a + c] - pad);
      box[3 + c] = fmax(box[3 + c], x[3 * a + c] + pad);
    }
  MPI_Allgather(box, 6, MPI_DOUBLE, y->box, 6, MPI_DOUBLE, MPI_COMM_WORLD);
  size_t k = 0;
  for (int q = 0; q < R; ++q) {
    y->cs[q] = 0;
    const double *b = y->box + 6 * q;
    size_t nb = 1;
    double w = y->depth * radius;
    if (y->np && q != d->rank) {
      memcpy(y->mbox, b, 6 * sizeof *b);
      /* two passes, as the images are made (methods/common/images.c) */
      nb = sph_domain_mirror_boxes(y->planes, y->np, w + 2.0 * radius,
                                   1e-9 * radius, 2, y->mbox,
                                   SPH_DOMAIN_MIRROR_BOXES);
      w = nb ? w : INFINITY; /* boxes that never settle: every particle */
      nb = nb ? nb : 1;
      b = y->mbox;
    }
    for (size_t a = 0; q != d->rank && a < n; ++a) {
      const double *p = x + 3 * a;
      if (y->np ? !in_boxes(b, nb, w, p)
                : p[0] < b[0] || p[1] < b[1] || p[2] < b[2] || p[0] > b[3] ||
                      p[1] > b[4] || p[2] > b[5])
        continue;
      if (k < y->cap)
        d->send_idx[k] = (int32_t)a;
      ++k;
      y->cs[q]++;
    }
  }
  return send_ghosts(d, ps, k, err);
}

sph_status sph_domain_dyn_mirror(sph_domain *d, const sph_domain_plane *planes,
                                 int np, double depth, sph_error *err) {
  if (!d || !d->dyn || np <= 0)
    return SPH_OK;
  sph_domain_dyn *y = d->dyn;
  if (np > (int)(sizeof y->planes / sizeof *y->planes))
    return sph_error_set(err, SPH_ERR_RANGE, "domain: at most %d planes",
                         (int)(sizeof y->planes / sizeof *y->planes));
  free(y->mbox);
  y->mbox = malloc(6 * SPH_DOMAIN_MIRROR_BOXES * sizeof *y->mbox);
  if (!y->mbox)
    return sph_error_set(err, SPH_ERR_NOMEM, "dynamic domain");
  memcpy(y->planes, planes, (size_t)np * sizeof *planes);
  y->np = np;
  y->depth = depth;
  return SPH_OK;
}

sph_status sph_domain_allgather(sph_domain *d, const double *mine, int w,
                                double *all, sph_error *err) {
  if (!d || !d->dyn)
    return SPH_OK;
  int R = d->size, n = (int)d->n * (w + 1);
  int *cnt = malloc(2 * (size_t)R * sizeof *cnt);
  double *o = malloc(((size_t)n + 1) * sizeof *o);
  double *in = malloc((d->dyn->N * (size_t)(w + 1) + 1) * sizeof *in);
  sph_status st =
      cnt && o && in ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "gather");
  st = sph_domain_agree(d, st, err);
  if (st == SPH_OK) {
    /* records of the storage index and the w values */
    for (size_t a = 0; a < d->n; ++a) {
      o[(size_t)(w + 1) * a] = (double)d->gidx[a];
      memcpy(o + (size_t)(w + 1) * a + 1, mine + (size_t)w * a,
             (size_t)w * sizeof *o);
    }
    MPI_Allgather(&n, 1, MPI_INT, cnt, 1, MPI_INT, MPI_COMM_WORLD);
    int at = 0;
    for (int q = 0; q < R; ++q) {
      cnt[R + q] = at;
      at += cnt[q];
    }
    MPI_Allgatherv(o, n, MPI_DOUBLE, in, cnt, cnt + R, MPI_DOUBLE,
                   MPI_COMM_WORLD);
    for (int i = 0; i < at; i += w + 1)
      memcpy(all + (size_t)w * (size_t)in[i], in + i + 1,
             (size_t)w * sizeof *all);
  }
  free(cnt);
  free(o);
  free(in);
  return st;
}

sph_status sph_domain_rebuild(sph_domain *d, sph_particles *ps, double radius,
                              sph_error *err) {
  if (!d || !d->dyn)
    return SPH_OK;
  sph_domain_dyn *y = d->dyn;
  double t0 = MPI_Wtime();
  int w = packed_width(y, ps);
  if (!y->width) { /* the first rebuild, in the method's set-up */
    y->width = w;
    size_t b = (size_t)(w > DYN_MAX_WIDTH ? w : DYN_MAX_WIDTH) * y->cap;
    free(d->buf);
    free(y->in);
    d->buf = malloc(b * sizeof *d->buf);
    y->in = malloc(b * sizeof *y->in);
    sph_status st = d->buf && y->in
                        ? SPH_OK
                        : sph_error_set(err, SPH_ERR_NOMEM, "dynamic domain");
    SPH_TRY(sph_domain_agree(d, st, err));
  } else if (w != y->width) {
    return sph_error_set(err, SPH_ERR_ARG,
                         "domain: the particle fields changed after set-up");
  }
  if (y->resumed) { /* a checkpoint's owned particles: its ghosts, no moves */
    y->resumed = 0;
    memcpy(y->cs, d->send_count, (size_t)d->size * sizeof *y->cs);
    SPH_TRY(send_ghosts(d, ps, d->nsend, err));
    d->seconds += MPI_Wtime() - t0;
    return SPH_OK;
  }
  /* re-balance when the most loaded rank owns too many */
  int n = (int)d->n, most = 0;
  MPI_Allgather(&n, 1, MPI_INT, y->count, 1, MPI_INT, MPI_COMM_WORLD);
  for (int q = 0; q < d->size; ++q)
    most = y->count[q] > most ? y->count[q] : most;
  const double *x = ps->field[SPH_FIELD_POSITION];
  if (most > (1.0 + SPH_DOMAIN_IMBALANCE) * (double)y->N / d->size)
    rebalance(d, ps);
  else
    for (size_t a = 0; a < d->n; ++a)
      y->dest[a] = tree_owner(y, x + 3 * a, d->size);
  SPH_TRY(migrate(d, ps, err));
  SPH_TRY(find_ghosts(d, ps, radius, err));
  y->rebuilds += 1.0;
  double halo = (double)d->nsend;
  sph_domain_sum(d, &halo, 1);
  y->halo_max = fmax(y->halo_max, halo);
  y->ghosts_max = fmax(y->ghosts_max, sph_domain_max(d, (double)d->ng));
  d->seconds += MPI_Wtime() - t0;
  return SPH_OK;
}

/* ---- checkpoints --------------------------------------------------------
 */

int sph_domain_checkpoint(sph_domain *d, const sph_particles *ps, size_t n,
                          int fill, double **particles, size_t *np,
                          double **state, size_t *ns) {
  if (!d || !d->dyn)
    return 0;
  sph_domain_dyn *y = d->dyn;
  size_t R = (size_t)d->size, w = (size_t)y->width;
  n = n < y->cap ? n : y->cap;
  *particles = d->buf;
  *np = w * n;
  *state = y->ckpt;
  *ns = ckpt_len(R, y->cap);
  if (!fill)
    return 1;
  for (size_t a = 0; a < n; ++a)
    pack(d, ps, a, d->buf + w * a);
  double *o = y->ckpt;
  memset(o, 0, *ns * sizeof *o);
  double head[7] = {(double)R,   (double)w,   y->migrated,  y->rebalances,
                    y->rebuilds, y->halo_max, y->ghosts_max};
  memcpy(o, head, sizeof head);
  double *ax = o + 7, *cut = ax + R + 1, *sc = cut + R + 1, *si = sc + R;
  for (size_t s = 1; s < R; ++s) { /* the cuts s = 1 .. R - 1 */
    ax[s] = (double)y->axis[s];
    cut[s] = y->cut[s];
  }
  for (size_t q = 0; q < R; ++q)
    sc[q] = (double)d->send_count[q];
  for (size_t k = 0; k < d->nsend; ++k)
    si[k] = (double)d->send_idx[k];
  return 1;
}

sph_status sph_domain_resume(sph_domain *d, sph_particles *ps, size_t n,
                             sph_error *err) {
  if (!d || !d->dyn)
    return SPH_OK;
  sph_domain_dyn *y = d->dyn;
  size_t R = (size_t)d->size, w = (size_t)y->width, k = 0;
  const double *o = y->ckpt;
  const double *ax = o + 7, *cut = ax + R + 1, *sc = cut + R + 1, *si = sc + R;
  int ok = o[0] == (double)R && o[1] == (double)w && n <= y->cap &&
           sc[d->rank] == 0.0;
  for (size_t s = 1; ok && s < R; ++s)
    ok = ax[s] >= 0.0 && ax[s] < (double)d->dim && isfinite(cut[s]);
  for (size_t q = 0; ok && q < R; ++q) {
    ok = sc[q] >= 0.0 && sc[q] <= (double)y->cap;
    k += ok ? (size_t)sc[q] : 0;
  }
  ok = ok && k <= y->cap;
  for (size_t j = 0; ok && j < k; ++j)
    ok = si[j] >= 0.0 && si[j] < (double)n;
  for (size_t a = 0; ok && a < n; ++a) {
    int64_t g;
    memcpy(&g, d->buf + w * a, sizeof g);
    ok = g >= 0 && (size_t)g < y->N;
  }
  if (!ok)
    return sph_error_set(err, SPH_ERR_IO,
                         "its domain state does not fit this run (rank "
                         "count, fields or particle indices)");
  for (size_t a = 0; a < n; ++a)
    unpack(d, ps, a, d->buf + w * a);
  d->n = ps->n = n;
  y->migrated = o[2];
  y->rebalances = o[3];
  y->rebuilds = o[4];
  y->halo_max = o[5];
  y->ghosts_max = o[6];
  for (size_t s = 1; s < R; ++s) {
    y->axis[s] = (int)ax[s];
    y->cut[s] = cut[s];
  }
  for (size_t q = 0; q < R; ++q)
    d->send_count[q] = (int)sc[q];
  for (size_t j = 0; j < k; ++j)
    d->send_idx[j] = (int32_t)si[j];
  d->nsend = k;
  y->resumed = 1;
  return SPH_OK;
}

sph_status sph_domain_exchange_many(sph_domain *d, double *const *fields,
                                    const int *ncomp, int count,
                                    sph_error *err) {
  if (!d)
    return SPH_OK;
  if (!d->dyn) {
    for (int i = 0; i < count; ++i)
      SPH_TRY(sph_domain_exchange(d, fields[i], ncomp[i], err));
    return SPH_OK;
  }
  sph_domain_dyn *y = d->dyn;
  int w = 0;
  for (int i = 0; i < count; ++i)
    w += ncomp[i];
  if (w > DYN_MAX_WIDTH)
    return sph_error_set(err, SPH_ERR_RANGE,
                         "halo exchange of %d values a particle, at most %d", w,
                         DYN_MAX_WIDTH);
  double t0 = MPI_Wtime();
  long ns = (long)d->nsend;
#pragma omp parallel for schedule(static)
  for (long k = 0; k < ns; ++k) {
    double *o = d->buf + (size_t)w * (size_t)k;
    size_t a = (size_t)d->send_idx[k];
    for (int i = 0; i < count; ++i) {
      size_t nc = (size_t)ncomp[i];
      memcpy(o, fields[i] + nc * a, nc * sizeof *o);
      o += nc;
    }
  }
  memcpy(y->cs, d->send_count, (size_t)d->size * sizeof *y->cs);
  memcpy(y->os, d->send_off, ((size_t)d->size + 1) * sizeof *y->os);
  memcpy(y->cr, d->recv_count, (size_t)d->size * sizeof *y->cr);
  memcpy(y->orr, d->recv_off, ((size_t)d->size + 1) * sizeof *y->orr);
  int ok = swap(d, w);
  long ng = (long)d->ng;
  size_t n = d->n;
#pragma omp parallel for schedule(static)
  for (long g = 0; g < ng; ++g) {
    const double *o = y->in + (size_t)w * (size_t)g;
    for (int i = 0; i < count; ++i) {
      size_t nc = (size_t)ncomp[i];
      memcpy(fields[i] + nc * (n + (size_t)g), o, nc * sizeof *o);
      o += nc;
    }
  }
  d->seconds += MPI_Wtime() - t0;
  return ok ? SPH_OK : sph_error_set(err, SPH_ERR_IO, "halo exchange failed");
}

#else /* without MPI no domain is ever made */

int sph_domain_checkpoint(sph_domain *d, const sph_particles *ps, size_t n,
                          int fill, double **particles, size_t *np,
                          double **state, size_t *ns) {
  (void)d, (void)ps, (void)n, (void)fill, (void)particles, (void)np;
  (void)state, (void)ns;
  return 0;
}

sph_status sph_domain_resume(sph_domain *d, sph_particles *ps, size_t n,
                             sph_error *err) {
  (void)d, (void)ps, (void)n, (void)err;
  return SPH_OK;
}

sph_status sph_domain_dyn_create(sph_domain *d, size_t N, const int *axis,
                                 const double *cut, sph_error *err) {
  (void)d, (void)N, (void)axis, (void)cut;
  return sph_error_set(err, SPH_ERR_UNSUPPORTED, "built without MPI");
}

sph_status sph_domain_rebuild(sph_domain *d, sph_particles *ps, double radius,
                              sph_error *err) {
  (void)d, (void)ps, (void)radius, (void)err;
  return SPH_OK;
}

sph_status sph_domain_dyn_mirror(sph_domain *d, const sph_domain_plane *planes,
                                 int np, double depth, sph_error *err) {
  (void)d, (void)planes, (void)np, (void)depth, (void)err;
  return SPH_OK;
}

sph_status sph_domain_allgather(sph_domain *d, const double *mine, int w,
                                double *all, sph_error *err) {
  (void)d, (void)mine, (void)w, (void)all, (void)err;
  return SPH_OK;
}

sph_status sph_domain_exchange_many(sph_domain *d, double *const *fields,
                                    const int *ncomp, int count,
                                    sph_error *err) {
  (void)d, (void)fields, (void)ncomp, (void)count, (void)err;
  return SPH_OK;
}

#endif
