/* The partition, ghosts and halo from each rank's share of the particles,
 * without the whole set (issue 20): the records of sph_domain_rcb_counted's
 * partition sent to their owners, the ghosts among the candidates other
 * ranks send for the owned box (and its reflections across symmetry
 * planes). */
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
  int R = sph_domain_world_size();
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
    if (all[j].owner != sph_domain_world_rank())
      continue;
    for (size_t k = nl->offset[j]; k < nl->offset[j + 1]; ++k)
      if (all[nl->index[k]].owner != sph_domain_world_rank())
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
  int R = sph_domain_world_size();
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
    for (size_t a = 0; q != sph_domain_world_rank() && a < n; ++a) {
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
    for (size_t a = 0; q != sph_domain_world_rank() && a < n; ++a)
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

/* every particle of the share `in` as a record, grouped by owner
 * (count[q] to rank q) into send */
static sph_status pack_records(const sph_particles *in, const int64_t *gidx,
                               const int *owner, int *count, share_rec *send,
                               sph_domain *world, sph_error *err) {
  size_t m = in->n;
  int R = sph_domain_world_size();
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
  sph_status st = sph_domain_agree(
      world, at ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "ghosts"), err);
  free(at);
  return st;
}

/* the ghosts of the n owned records own (not of a dynamic domain, which
 * finds its ghosts at each rebuild): share_ghosts', or with planes every
 * candidate; *ng_support those within one support */
static sph_status ghost_records(share_rec *own, size_t n, int dim,
                                double support, int dynamic,
                                const sph_domain_plane *planes, int np,
                                MPI_Datatype type, share_rec **ghost,
                                size_t *ng, size_t *ng_support,
                                sph_error *err) {
  share_rec *cand = NULL;
  size_t nc = 0;
  sph_status st = SPH_OK;
  *ghost = NULL;
  *ng = 0;
  if (!dynamic)
    st = share_candidates(own, n, dim, support, planes, np, type, &cand, &nc,
                          err);
  if (st == SPH_OK && !dynamic)
    st = share_ghosts(own, n, cand, nc, dim, support, ghost, ng, err);
  *ng_support = *ng;
  if (st == SPH_OK && np > 0 && !dynamic) {
    free(*ghost);
    qsort(cand, nc, sizeof *cand, cmp_rec_owner);
    *ghost = cand, *ng = nc;
    cand = NULL;
  }
  free(cand);
  return st;
}

/* the storage indices of the owned and ghost records, the ghosts' reference
 * data and *gowner (malloc'd) their owners; room for cap points */
static sph_status store_ghosts(sph_domain *d, const share_rec *own,
                               const share_rec *ghost, size_t ng, size_t cap,
                               int **gowner, sph_error *err) {
  d->ng = ng;
  size_t gm = d->n + ng > cap ? d->n + ng : cap;
  d->gidx = malloc((gm ? gm : 1) * sizeof *d->gidx);
  d->gX = malloc(3 * (ng + 1) * sizeof *d->gX);
  d->gV = malloc((ng + 1) * sizeof *d->gV);
  d->gbody = malloc((ng + 1) * sizeof *d->gbody);
  d->gid = malloc((ng + 1) * sizeof *d->gid);
  if (!d->gidx || !d->gX || !d->gV || !d->gbody || !d->gid)
    return sph_error_set(err, SPH_ERR_NOMEM, "ghosts");
  if (!(*gowner = malloc((ng + 1) * sizeof **gowner)))
    return sph_error_set(err, SPH_ERR_NOMEM, "ghosts");
  for (size_t a = 0; a < d->n; ++a)
    d->gidx[a] = own[a].g;
  for (size_t j = 0; j < ng; ++j) {
    d->gidx[d->n + j] = ghost[j].g;
    memcpy(d->gX + 3 * j, ghost[j].X, 3 * sizeof *d->gX);
    d->gV[j] = ghost[j].V;
    d->gbody[j] = ghost[j].body;
    d->gid[j] = ghost[j].id;
    (*gowner)[j] = ghost[j].owner;
  }
  return SPH_OK;
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
  int R = sph_domain_world_size(), dim = in->dim;
  sph_domain *d = calloc(1, sizeof *d);
  int *owner = malloc((m ? m : 1) * sizeof *owner);
  int *count = calloc((size_t)R, sizeof *count);
  share_rec *send = malloc((m ? m : 1) * sizeof *send);
  int *axis = malloc(((size_t)R + 1) * sizeof *axis);
  double *cut = malloc(((size_t)R + 1) * sizeof *cut);
  size_t cap = dynamic ? sph_domain_dyn_capacity(N, R) : 0;
  if (d) {
    d->rank = sph_domain_world_rank();
    d->size = sph_domain_world_size();
    d->dim = dim;
    d->sums = malloc((size_t)sph_domain_world_size() * 16 * sizeof *d->sums);
  }
  sph_status st = d && d->sums && owner && count && send && axis && cut
                      ? SPH_OK
                      : sph_error_set(err, SPH_ERR_NOMEM, "decomposition");
  sph_domain world = {.rank = sph_domain_world_rank(),
                      .size = sph_domain_world_size()};
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
  share_rec *own = NULL, *ghost = NULL;
  size_t ng = 0, ng_support = 0;
  if (st == SPH_OK)
    st = pack_records(in, gidx, owner, count, send, &world, err);
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
      own[a].owner = sph_domain_world_rank();
    st = ghost_records(own, d->n, dim, support, dynamic, planes, np, type,
                       &ghost, &ng, &ng_support, err);
  }
  int *gowner = NULL;
  if (st == SPH_OK)
    st = store_ghosts(d, own, ghost, ng, cap, &gowner, err);
  free(ghost);
  MPI_Type_free(&type);
  st = sph_domain_agree(&world, st, err);
  if (st == SPH_OK)
    st = sph_domain_halo_plan(d, st, ng_support, N, gowner, err);
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

#else /* without MPI: one rank, no domain is ever made */

sph_status sph_domain_create_share(sph_domain **out, sph_particles **ps,
                                   const int64_t *gidx, size_t N,
                                   double support, int dynamic,
                                   sph_error *err) {
  (void)gidx, (void)N, (void)dynamic;
  return sph_domain_create(out, ps, support, err);
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
