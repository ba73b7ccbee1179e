/* Private state of the domain decomposition (issue 20), shared by the
 * partition (domain.c), the fixed halo of the total-Lagrangian methods
 * from the whole set (domain_fixed.c) or each rank's share
 * (domain_share.c), the exchanges and reductions (domain_comm.c) and the
 * rebuilt halo, migration and re-balancing of the updated-Lagrangian ones
 * (domain_dynamic.c). */
#ifndef SPH_DOMAIN_IMPL_H
#define SPH_DOMAIN_IMPL_H

#include "parallel/domain.h"

typedef struct sph_domain_dyn sph_domain_dyn;

struct sph_domain {
  int rank, size, dim;
  size_t n;          /* owned */
  size_t ng;         /* ghosts */
  size_t base;       /* first ghost point of exchanged arrays (0: n) */
  int64_t *gidx;     /* storage index in the whole set: owned, then ghosts */
  double *gX, *gV;   /* ghosts' reference positions and volumes */
  int32_t *gbody;    /* ghosts' bodies */
  int64_t *gid;      /* ghosts' particle ids */
  int *recv_count;   /* ghosts owned by each rank */
  int *recv_off;     /* their first ghost */
  int *send_count;   /* owned particles each rank holds as ghosts */
  int *send_off;     /* their first entry of send_idx */
  int32_t *send_idx; /* owned indices to send, grouped by rank */
  size_t nsend;      /* entries of send_idx */
  double *buf;       /* packed sends, 9 per entry (dynamic: wider) */
  void *req;         /* 2 size requests */
  double seconds;    /* in exchanges, reductions and gathers */
  double sent, messages; /* doubles and messages the exchanges sent */
  double *sums;          /* 16 per rank: sph_domain_sum's gather */
  size_t total;          /* particles of the whole run */
  double *pbuf;          /* sph_domain_box_points' packed sends */
  size_t pbuf_cap;
  sph_domain_dyn *dyn; /* updated-Lagrangian runs, else NULL */
};

/* MPI only: waits for the n MPI_Requests at req, polling about 50 us, then
 * sleeping 50 us between polls (SPH_MPI_WAIT=spin: polling only); the MPI
 * return code. */
int sph_domain_wait(int n, void *req);

typedef struct rcb_key {
  double x;
  int64_t i;
} rcb_key;

void sph_domain_rcb(const double *X, int dim, rcb_key *k, size_t n, int rank0,
                    int nranks, int *owner, int *axis, double *cutv);

/* The partition of sph_domain_rcb computed without any rank holding the
 * whole set (collective): each rank passes its n particles' positions X (3
 * per particle) and tie keys t (unique over all ranks; the storage index
 * makes it sph_domain_rcb's partition); owner[i] is the rank that owns
 * particle i. Each cut is found by counting bisection (MPI_Allreduce).
 * With axis and cut (R + 1 each; NULL on every rank or on none) the cut
 * tree is sph_domain_rcb's too: ranks from s on lie at or above cut[s]
 * along axis[s], s = 1 .. R - 1, the same values but for the sign of a
 * zero. work: room for 2 n keys, or NULL to allocate it (owner -1 on
 * every particle when that fails on some rank). */
void sph_domain_rcb_counted(const double *X, const int64_t *t, size_t n,
                            int dim, int *owner, int *axis, double *cut,
                            uint64_t *work);

/* The box lo, hi (box[0..5]) and its reflections across every plane it
 * comes within `near` of, chained over at most `passes` passes over the
 * planes or until no new box appears (boxes equal within tol are one),
 * into box (6 each, room for max): their count, 0 when they do not settle
 * within max. */
#define SPH_DOMAIN_MIRROR_BOXES 4096
size_t sph_domain_mirror_boxes(const sph_domain_plane *planes, int np,
                               double near, double tol, int passes, double *box,
                               size_t max);

/* domain_fixed.c: a halo larger than the domain (ng_support ghosts within
 * one support of N particles): more ranks than useful; then the exchange's
 * plan from the ghosts' owners gowner (collective, agreed; MPI only). */
sph_status sph_domain_halo_plan(sph_domain *d, sph_status st, size_t ng_support,
                                size_t N, const int *gowner, sph_error *err);

/* domain_dynamic.c: the local capacity (owned + ghosts) for N particles
 * over R ranks; the dynamic state from the first partition (the particle
 * count and the cut tree, axis and cut R + 1 each: nothing N-sized is
 * kept); its destruction */
size_t sph_domain_dyn_capacity(size_t N, int R);
sph_status sph_domain_dyn_create(sph_domain *d, size_t N, const int *axis,
                                 const double *cut, sph_error *err);
void sph_domain_dyn_destroy(sph_domain_dyn *y);

#endif
