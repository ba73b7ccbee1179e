/* Private state of the ul-csph method (seed 001 sec. 3-4). */
#ifndef SPH_UL_CSPH_IMPL_H
#define SPH_UL_CSPH_IMPL_H

#include "integrators/integrator_impl.h"
#include "methods/common/common_impl.h"

/* an image a rank places: its serial number, source point and slot */
typedef struct ul_placed {
  int64_t j;
  size_t s, k;
  int far; /* beyond two supports of the owned box: a partial list */
} ul_placed;

typedef struct ul_csph {
  sph_ref ref; /* X, V, nl, L, w of the current reference x^r */
  double cfl;
  int update_every;       /* steps between reference updates */
  double update_distance; /* or when a particle has moved this many dp */
  double since;           /* steps since the last update (a state array) */
  double *V0;             /* initial volumes (n_ext) */
  double *Fr, *Jr;        /* F^r and det F^r per point (9 n_ext, n_ext) */
  /* Hessian-difference stabilisation (sec. 3.4): eta and the vector h of
   * Remark 2; per slot H~_k(x_a) h, g_k(x_a).h and the reverse slot, per
   * point their sums over the slots (sum_k V_k H~_k h, sum_k g_k.h) */
  double eta, h[3];
  double *hv, *gh, *sv, *sgh;
  double *A; /* the linear correction of eq. 19 per point (9 n_ext) */
  size_t *rev, slot_cap;
  double *f0, *S;        /* unstabilised f, P F^r^T / J^r (9 n_ext) */
  double *x, *p, *F, *P; /* particle fields */
  double *dp;            /* rate of momentum */
  sph_leapfrog lf;
  int timer_force, timer_update, timer_integration;
  struct sph_sim *sim;
  /* over MPI ranks with symmetry planes (ul_csph_mirror.c): per particle
   * its images' serial numbers (-1: none) and reference positions (kimg,
   * 3 kimg), per point an image's serial number, the placement's work */
  int mirrored; /* the scene has symmetry or skew-symmetry planes */
  int kimg;
  double *imgj, *imgX;
  int64_t *gj;
  ul_placed *placed;
} ul_csph;

/* ul_csph_mirror.c: nothing without sph_mirror_table. Set-up (the owned
 * particles' images, tracked by the domain); after x^r = x, the owned
 * particles' images' reference positions kept; before a rebuild, x, p, F
 * into the particle set that migrates; after it, the ghosts moved behind
 * the images placed in the serial order. */
sph_status ul_mirror_setup(ul_csph *m, sph_error *err);
void ul_mirror_store(ul_csph *m);
void ul_mirror_sync(ul_csph *m);
sph_status ul_mirror_place(ul_csph *m, sph_error *err);

#endif
