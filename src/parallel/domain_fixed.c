/* The partition's ghosts and halo from the whole set of particles (issue
 * 20): ghost layers of one kernel support found with the cell-list search,
 * with symmetry planes also the sources of mirror images (the owned box's
 * reflections, parallel/planes.h), the exchange plan, the owned set. */
#include "parallel/domain.h"
#include "parallel/domain_impl.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef SPH_HAVE_MPI
#include <mpi.h>
#endif

#ifdef SPH_HAVE_MPI

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
sph_status sph_domain_halo_plan(sph_domain *d, sph_status st, size_t ng_support,
                                size_t N, const int *gowner, sph_error *err) {
  long worst = -1;
  if (st == SPH_OK && (ng_support > d->n || d->n == 0))
    worst = sph_domain_world_rank();
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
                         sph_domain_world_size(), N, any);
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
  int *axis = malloc(((size_t)sph_domain_world_size() + 1) * sizeof *axis);
  double *cut = malloc(((size_t)sph_domain_world_size() + 1) * sizeof *cut);
  size_t cap =
      dynamic ? sph_domain_dyn_capacity(N, sph_domain_world_size()) : 0;
  sph_status st = d && owner && ghost && k && axis && cut
                      ? SPH_OK
                      : sph_error_set(err, SPH_ERR_NOMEM, "decomposition");
  if (d) {
    d->rank = sph_domain_world_rank();
    d->size = sph_domain_world_size();
    d->dim = all->dim;
    d->sums = malloc((size_t)sph_domain_world_size() * 16 * sizeof *d->sums);
    if (!d->sums)
      st = sph_error_set(err, SPH_ERR_NOMEM, "decomposition");
  }
  if (st == SPH_OK) {
    for (size_t i = 0; i < N; ++i)
      k[i] = (rcb_key){0.0, (int64_t)i};
    sph_domain_rcb(all->field[SPH_FIELD_POSITION0], all->dim, k, N, 0,
                   sph_domain_world_size(), owner, axis, cut);
    if (!dynamic)
      st =
          find_ghosts(all, owner, sph_domain_world_rank(), support, ghost, err);
  }
  /* owned in storage order, then ghosts by owner and storage order */
  for (size_t i = 0; st == SPH_OK && i < N; ++i) {
    d->n += owner[i] == sph_domain_world_rank();
    d->ng += ghost[i] != 0;
  }
  /* the usefulness check below counts the ghosts within one support */
  size_t ng_support = d ? d->ng : 0;
  if (st == SPH_OK && np > 0 && !dynamic) {
    st = find_mirror_ghosts(all, owner, sph_domain_world_rank(), support,
                            planes, np, ghost, err);
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
      if (owner[i] == sph_domain_world_rank())
        d->gidx[a++] = (int64_t)i;
    /* ghosts by owner (a counting sort), each owner's in storage order */
    size_t *at = calloc((size_t)sph_domain_world_size() + 1, sizeof *at);
    if (!at)
      st = sph_error_set(err, SPH_ERR_NOMEM, "ghosts");
    for (size_t i = 0; at && i < N; ++i)
      at[owner[i] + 1] += ghost[i] != 0;
    for (int q = 0; at && q < sph_domain_world_size(); ++q)
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
  st = sph_domain_halo_plan(d, st, ng_support, N, gowner, err);
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

#endif
