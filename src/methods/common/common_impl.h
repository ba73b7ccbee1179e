/* What the Lagrangian methods share (methods/common/): the reference
 * configuration (reference.c: same-body neighbours, the pair weights and
 * correction matrices of the corrected gradient of seed 000 eq. 21 / seed
 * 001 eq. 8, see methods/common/pair_iact.h, the conservative force loop,
 * per-particle material and density, the state arrays), fixed for the
 * total-Lagrangian methods and updated by ul-csph; the mirror images across
 * symmetry planes (images.c); the time-stepping glue, the derived output
 * fields and the energy (stepping.c). */
#ifndef SPH_METHODS_COMMON_IMPL_H
#define SPH_METHODS_COMMON_IMPL_H

#include <stddef.h>
#include <stdint.h>

#include "core/corrections.h"
#include "core/neighbors.h"
#include "core/tensor.h"
#include "integrators/integrator_impl.h"
#include "materials/material.h"
#include "methods/common/pair_iact.h"
#include "solver/sim.h"

/* The output fields the methods of sph_ref fill (sph_method_ops). */
#define SPH_REF_OUTPUT_FIELDS                                                  \
  (1ul << SPH_FIELD_POSITION0 | 1ul << SPH_FIELD_POSITION |                    \
   1ul << SPH_FIELD_VELOCITY | 1ul << SPH_FIELD_ACCELERATION |                 \
   1ul << SPH_FIELD_VOLUME0 | 1ul << SPH_FIELD_MASS |                          \
   1ul << SPH_FIELD_DEFGRAD | 1ul << SPH_FIELD_JACOBIAN |                      \
   1ul << SPH_FIELD_PK1 | 1ul << SPH_FIELD_STRESS |                            \
   1ul << SPH_FIELD_PRESSURE | 1ul << SPH_FIELD_VON_MISES |                    \
   1ul << SPH_FIELD_DISPLACEMENT)

/* ---- reference configuration (reference.c) ---- */

/* The serial run's mirror images, fixed at set-up, of a run over MPI ranks
 * with a dynamic domain (the method places those near a rank's particles
 * at each rebuild): image j is point n_real + j of the serial run, with
 * its source's storage index, signs (or reflection matrix) and initial
 * reference position; k is the most images of one source. */
typedef struct sph_mirror_table {
  size_t m, n_real;
  int k;
  int32_t *src;
  signed char *vsign, *rsign, *ssign; /* 3, 3, 1 per image */
  double *vmat;                       /* 9 per image, or NULL */
  double *X;                          /* 3 per image */
} sph_mirror_table;

typedef struct sph_ref {
  size_t n, n_ext;   /* real particles, real + mirror images + ghosts */
  size_t n_img;      /* real + mirror images; the ghosts of a distributed run
                        (sph_domain) follow, their state set by exchange */
  size_t cap;        /* points the per-point arrays hold (n_ext, or the
                        capacity of an updated-Lagrangian run over ranks) */
  double *X;         /* reference positions (3 n_ext) */
  double *V;         /* volumes (n_ext) */
  int32_t *body;     /* bodies (n_ext) */
  sph_neighbors *nl; /* over all n_ext points, same body only */
  double *w;         /* V_b W'(r_ab) / r_ab per slot */
  size_t w_cap;      /* slots w holds */
  int64_t *id;       /* particle id per point (n_ext) */
  double *L;         /* correction matrix per point (9 n_ext) */
  double *s;         /* sum_b w_ab r_ab per particle (3 n) */
  const sph_material **mat; /* per point (n_ext) */
  double *rho0;             /* per point (n_ext) */
  double cp;                /* largest p-wave speed of the materials */
  const double **axes; /* per real point its body's rotation (material axes),
                          NULL when no body is placed or for unplaced ones */
  /* state, n_ext entries each; the particle fields themselves when there
   * are no images */
  double *x, *p, *F, *J, *P;
  double *Qt; /* (P L)^T per point (9 n_ext) */
  int owns_state;
  /* mirror images */
  sph_mirror mirror;
  int32_t *src;
  signed char *vsign, *rsign, *ssign;
  double *vmat; /* 9 per point with an oblique plane (sph_mirror), or NULL */
  /* over MPI ranks: the serial run's order of the points (storage index of
   * a real, then the images' order), which the lists are sorted by; NULL
   * without a fixed domain */
  int64_t *key;
  /* over MPI ranks with mirror images, whose sources may be ghosts: the
   * ghosts' state is exchanged before the images are refreshed */
  int sync_images;
  /* over MPI ranks with a dynamic domain and planes, else NULL */
  sph_mirror_table *all_images;
  /* over MPI ranks: the points from 0 whose lists are whole, so their
   * corrections are computed here (0: n_img) */
  size_t n_whole;
  /* over MPI ranks with images: the images no owned particle neighbours,
   * whose lists may lack points the rank does not hold (n_img flags) */
  unsigned char *partial;
  size_t partial_cap;
} sph_ref;

/* Builds everything above in the reference configuration (timed as
 * "corrections"), with images across the scene's symmetry and
 * skew-symmetry planes in a layer two kernel supports thick, and sets the
 * initial state: x = X, p = rho0 v0, F = I (or the scene reference's
 * initial F), J = det F. Without `images` the planes are left to the
 * method's boundary terms. */
sph_status sph_ref_create(sph_ref *ref, sph_sim *sim, int images,
                          sph_error *err);
void sph_ref_destroy(sph_ref *ref);

/* Neighbour lists, correction matrices L, pair weights w and sums s from
 * the current X and V (the updated-Lagrangian methods call it at each
 * reference update; w grows only when the pair count exceeds it). */
sph_status sph_ref_rebuild(sph_ref *ref, const sph_sim *sim, sph_error *err);

/* Over MPI ranks with a dynamic domain (else nothing): the rebuild of
 * sph_domain_rebuild (migration by the current positions, re-balance, the
 * ghosts found again), then the points' bodies, ids, materials and axes
 * from the particle set and the terms renumbered. The caller tracks X and
 * its own per-point arrays (sph_domain_track) and rebuilds the reference. */
sph_status sph_ref_redistribute(sph_ref *ref, sph_sim *sim, sph_error *err);

/* Slot of (b -> a) for every slot (a -> b), for pair quantities that are
 * not antisymmetric (allocated here, freed by the caller). */
sph_status sph_ref_reverse_slots(const sph_ref *ref, size_t **rev,
                                 sph_error *err);
/* The same into rev of at least nl->count entries. */
sph_status sph_ref_reverse_fill(const sph_ref *ref, size_t *rev,
                                sph_error *err);

/* Over MPI ranks (else nothing): a ghost's list is partial, so its slots
 * toward this rank's particles, rev[k] for each slot k = (a -> b) of a
 * particle a with a ghost b, are evaluated from b's coefficients, which its
 * owner computes (sph_correction_coefficients): the corrected gradient of
 * kind (W~1 or L grad W~0) at X_b into grad (3 per slot) and, when lap is
 * not NULL, Lap W~_a(X_b) into lap; the cloud's rows are the particles'
 * (n_img). */
sph_status sph_ref_ghost_slots(const sph_sim *sim, const sph_ref *ref,
                               const sph_cloud *cloud, sph_gradient_kind kind,
                               const size_t *rev, double *grad, double *lap,
                               sph_error *err);

/* Corrected gradient grad_b(X_a) of slot k of particle a (set-up use). */
void sph_ref_gradient(const sph_ref *ref, size_t a, size_t k, double g[3]);

/* Q_a = P_a L_a, the stress the conservative force pairs with, stored
 * transposed (its columns contiguous), from the stress P_a */
static inline void sph_ref_force_matrix_of(const sph_ref *ref, size_t a,
                                           const double Pa[9]) {
  double Q[9];
  sph_mat3_mul(Pa, ref->L + 9 * a, Q);
  sph_mat3_transpose(Q, ref->Qt + 9 * a);
}

/* the same from ref->P */
static inline void sph_ref_force_matrix(const sph_ref *ref, size_t a) {
  sph_ref_force_matrix_of(ref, a, ref->P + 9 * a);
}

/* The pair sums of particle a over its neighbours (methods/common/pair_iact.h):
 * the uncorrected gradient of the vector field f (when f is not NULL), the pair
 * part of the conservative force (when `force`) and the Laplacian of f with the
 * per-slot weights `lap` (when both are not NULL); the constant arguments of
 * each caller specialise the loop. */
static inline void sph_ref_pair_sums(const sph_ref *ref, size_t a,
                                     const double *f, int force,
                                     const double *lap, ref_sums *s) {
  const sph_neighbors *nl = ref->nl;
  const double *Xa = ref->X + 3 * a;
  *s = (ref_sums){0};
  for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
    size_t b = (size_t)nl->index[k];
    ref_v2 r01;
    double r2;
    ref_iact_pair_vector2(Xa, ref->X + 3 * b, &r01, &r2);
    if (f) {
      const double *fa = f + 3 * a, *fb = f + 3 * b;
      ref_v2 df01 = ref_v2_load(fb) - ref_v2_load(fa);
      double df2 = fb[2] - fa[2];
      ref_iact_gradient2(s, ref->w[k], df01, df2, r01, r2);
      if (lap)
        ref_iact_laplacian2(s, lap[k], df01, df2);
    }
    if (force)
      ref_iact_force2(s, ref->w[k], ref->Qt + 9 * b, r01, r2);
  }
}

/* Internal force of seed 000 eq. 29c / 42 into dp (overwritten) for the
 * real particles, from ref->Qt (methods/common/pair_iact.h). */
void sph_ref_conservative_force(const sph_ref *ref, double *dp);

/* Extra per-point state of n_ext entries (e.g. the cofactor). */
sph_status sph_ref_alloc(const sph_ref *ref, size_t ncomp, double **out,
                         sph_error *err);

/* ---- mirror images (images.c) ---- */

/* The mirror images of sph_ref_create (its `images`, when the scene has
 * planes): points, volumes, bodies, sources and signs of the real points
 * and their images, with ref->mirror; over MPI ranks with a dynamic domain
 * the serial run's images as ref->all_images instead, which the method
 * places (methods/ul_csph/ul_csph_mirror.c). */
sph_status sph_images_build(sph_ref *ref, sph_sim *sim, int images,
                            sph_error *err);
/* ref->mirror from the images n .. n_img of ref (vmat with `oblique`). */
void sph_images_publish(sph_ref *ref, int oblique);
/* Point g of ref takes the signs (and reflection matrix) of image j of the
 * table t. */
void sph_images_assign(sph_ref *ref, size_t g, const sph_mirror_table *t,
                       size_t j);

/* Sets the images' state from their sources: positions, momenta, F (and H
 * when not NULL) as I + sigma R (A - I) R^T, J as 1 + sigma (J - 1), with R
 * the composed reflection (sign flips across coordinate planes). */
void sph_mirror_state(const sph_ref *ref, double *x, double *p, double *F,
                      double *H, double *J);
/* The particles that start on a symmetry plane stay on it with zero
 * normal momentum (on a skew-symmetry plane: zero tangential momentum and
 * displacement), the particles' x and p (each its own image). */
void sph_mirror_hold(const sph_sim *sim, const sph_ref *ref, double *x,
                     double *p);
/* How many of the particles at x lie across a plane from their body (over
 * every rank; collective). */
long sph_mirror_crossed(const sph_sim *sim, const sph_ref *ref,
                        const double *x);
/* A particle across a plane from its body and the image on its side trade
 * places (the same points, relabelled): at a reference update (x = X) its
 * x, X, p, F and F^r are reflected, its images' X with it, and the images'
 * state is mirrored again. */
void sph_mirror_fold(const sph_sim *sim, sph_ref *ref, double *x, double *p,
                     double *F, double *Fr);
/* Over MPI ranks with mirror images (sync_images): the ghosts' values of
 * `field` (ncomp a point), which the images of ghosts mirror, from their
 * owners; else nothing. */
sph_status sph_mirror_sources(const sph_sim *sim, const sph_ref *ref,
                              double *field, int ncomp, sph_error *err);

/* ---- time stepping, derived fields, energy (stepping.c) ---- */

/* Derived fields of the real particles: velocity, displacement, J, Cauchy
 * stress, pressure tr(sigma)/3 (seed 000 eq. 11), von Mises; copies the
 * state into the particle fields when the method keeps its own arrays.
 * P must hold the stress of the state, evaluated at Fs (NULL: the state's
 * F), which J (NULL: det Fs) and the Cauchy stress take. */
void sph_ref_derive(sph_sim *sim, const sph_ref *ref, const double *H,
                    const double *J, const double *Fs);

/* Largest p-wave speed of the current state (seed 000 eq. 44, "c_p from
 * the current state"): for each particle the largest eigenvalue of the
 * acoustic tensor Q_ik(N) = dP_iJ/dF_kL N_J N_L along the three material
 * axes (those of the body frame: F is turned back by a placed body's
 * rotation, so dt does not depend on the orientation), with dP/dF by finite
 * differences of the material's stress at (F, cof F, det F); at F = I it is the
 * linear p-wave speed. */
double sph_ref_max_wave_speed(const sph_ref *ref, const double *F);

/* Time step of seed 000 eq. 44: cfl h_min / c_p with c_p the larger of the
 * materials' linear speed and (if `current`) sph_ref_max_wave_speed. */
double sph_ref_stable_dt(const sph_ref *ref, const sph_sim *sim, double cfl,
                         int current);

/* SPH_ERR_NUMERIC naming the first particle whose position or momentum is
 * not finite. */
sph_status sph_ref_check_finite(const sph_ref *ref, sph_error *err);

/* The acceleration output field, dp / rho0, from the rates of the current
 * state (only when the scene asks for it). */
void sph_ref_acceleration(sph_sim *sim, const sph_ref *ref, const double *dp);

/* Adds the time since t0 to the method's force timer, then the terms'
 * rates on the state of ref (x, p, F) into dp. */
sph_status sph_step_rates_terms(sph_sim *sim, const sph_ref *ref, double *dp,
                                int timer, double t0, double t, sph_error *err);

/* The terms' constraints on the state of ref. */
sph_status sph_step_constrain_terms(sph_sim *sim, const sph_ref *ref, double t,
                                    sph_error *err);

/* The options of the leap-frog methods: `cfl` (default 0.3, in (0, 1])
 * and `integrator: leapfrog`. */
sph_status sph_step_leapfrog_options(sph_node *opt, double *cfl,
                                     sph_error *err);

/* lf over the real particles of ref with the method's rates and
 * constraints (ctx), the scene's body force and essential boundary
 * conditions, the latter imposed at t = 0. */
sph_status sph_step_leapfrog_attach(
    sph_sim *sim, const sph_ref *ref, sph_leapfrog *lf, double *dp,
    sph_status (*rates)(void *ctx, double t, sph_error *err),
    sph_status (*constrain)(void *ctx, double t, sph_error *err), void *ctx,
    sph_error *err);

/* The external terms the scene asks for (body force, contact), acting on
 * the momentum per reference volume. */
sph_status sph_step_external_terms(sph_sim *sim, const sph_ref *ref,
                                   sph_error *err);

/* Essential boundary conditions imposed directly, when the scene has any,
 * and the initial state constrained through `constrain`. */
sph_status sph_step_essential_bc(sph_sim *sim, const sph_ref *ref,
                                 sph_status (*constrain)(void *ctx, double t,
                                                         sph_error *err),
                                 void *ctx, sph_error *err);

/* sph_ref_derive (J = det F) and, when the scene asks for it, the acceleration
 * from the rates of the current state (computed if lf holds none). */
/* One leap-frog step and the finite-state check, their time added to the
 * `timer` (time_integration). */
sph_status sph_step_leapfrog(sph_sim *sim, const sph_ref *ref, sph_leapfrog *lf,
                             int timer, double dt, sph_error *err);
/* One Runge-Kutta step of ode and the finite-state check, their time added
 * to the `timer` (time_integration). */
sph_status sph_step_rk(sph_sim *sim, const sph_ref *ref, sph_ode *ode,
                       sph_rk_step integrate, int timer, double dt,
                       sph_error *err);
/* The acceleration output field from ode's rates at the current state
 * (x and p its first two arrays), when the scene asks for it. */
sph_status sph_step_rk_acceleration(sph_sim *sim, const sph_ref *ref,
                                    sph_ode *ode, sph_error *err);
/* The checkpointed state x, p and F of the real particles (method ops
 * `state`): returns 3. */
int sph_step_state_xpF(const sph_ref *ref, sph_state_array *out);
/* After a checkpoint has set the state: the rates of that state, which the
 * next step reuses as the uninterrupted run's did (the checkpoint then
 * restores the call counts, so this evaluation is not counted twice). */
sph_status sph_step_leapfrog_restore(sph_sim *sim, sph_leapfrog *lf,
                                     sph_error *err);
sph_status sph_step_leapfrog_derive(sph_sim *sim, const sph_ref *ref,
                                    sph_leapfrog *lf, const double *dp,
                                    sph_error *err);

/* Kinetic and strain energy of the real particles; H and J may be NULL. */
void sph_ref_energy(sph_sim *sim, const sph_ref *ref, const double *H,
                    const double *J, double *kinetic, double *strain);

#endif
