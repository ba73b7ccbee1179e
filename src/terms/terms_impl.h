/* Terms a method composes (docs/design.md sec. 4): each is an sph_term_ops
 * table plus a create function that adds it to the sim only when asked for. */
#ifndef SPH_TERMS_IMPL_H
#define SPH_TERMS_IMPL_H

#include <stddef.h>
#include <stdint.h>

#include "core/neighbors.h"
#include "solver/sim.h"
#include "terms/term_list.h"

#define SPH_TERM_EXTERN(id) extern const sph_term_ops id##_term_ops;
SPH_TERM_LIST(SPH_TERM_EXTERN)
SPH_TERM_LIST_EXTRA(SPH_TERM_EXTERN)
#undef SPH_TERM_EXTERN

/* NULL-terminated list of every term's ops table (term_list.h). */
const sph_term_ops *const *sph_term_list(void);

/* Projects a per-particle vector field w (3 per particle, e.g. the internal
 * forces) so that sum V w = 0 and sum V X x w = 0 over each body, in the
 * least-squares sense of seed 000 eq. 46-48: w^ = w + lambda x (X - Xc) +
 * mu; over MPI ranks (d not NULL) the n particles are this rank's and the
 * body's sums are global. */
void sph_momentum_projection(sph_domain *d, size_t n, const double *V,
                             const double *X, const int32_t *body, int nbodies,
                             double *w);

/* Angular momentum projection of the internal force (seed 000 eq. 45-48):
 * acts on stage->dp, so it must come before terms that add external or
 * dissipative contributions. */
sph_status angular_momentum_projection_create(sph_sim *sim, sph_error *err);

/* JST dissipation (seed 000 eq. 35-38) of momentum (ncomp 3, into dp) or of
 * the Jacobian (ncomp 1, into dJ), with the conservative projection of
 * eq. 49 or eq. 51 when `project` is set. `lap` holds the per-slot
 * Laplacian weights of `nl`; h is the particle spacing, cp the p-wave
 * speed. */
typedef struct jst_params {
  const sph_neighbors *nl; /* may list mirror images beyond the particles */
  const double *lap;       /* V_b Lap W~_b(X_a) per slot */
  const double *V;         /* volumes of every point of nl */
  int ncomp;
  double eps2, eps4, cp, h;
  int project;
  /* seed 004 eq. 28 (NULL: seed 000 eq. 35-38): the outer sums take
   * V_b (Lap W~_b(X_a) + Lap W~_a(X_b)) / 2 per slot, the inner Laplacian
   * (eq. 27) stays `lap` */
  const double *lap_sym;
  /* with lap_sym, the outer sums of the eps4 term as the adjoint of the
   * inner Laplacian in the volume-weighted inner product (NULL: eq. 28):
   * L*[w]_a = sum_b lap_adj_ab (w_b - w_a) + lap_diag_a w_a with
   * lap_adj_ab = V_b Lap W~_a(X_b) and lap_diag_a = sum_b (lap_adj_ab -
   * V_b Lap W~_b(X_a)), so that -eps4 c_p h^3 L*[L[u]] is dissipative,
   * conserves momentum and vanishes on linear u like eq. 28 */
  const double *lap_adj, *lap_diag;
  const double *cp_now; /* c_p of the step (NULL: cp) */
  /* L[u] of the real particles summed by the method in its own pair sweep
   * before the term runs, in this term's arithmetic (NULL: the term sums
   * it); the term fills the mirror images' entries */
  double *lu;
  /* over MPI ranks: the ghosts' u are not set by the method's sweep, the
   * term exchanges them (sph_domain_exchange) */
  int exchange_u;
} jst_params;
sph_status jst_dissipation_create(sph_sim *sim, const jst_params *p,
                                  sph_error *err);

/* Body force E_a = rho0 g (seed 000 eq. 27c) added to dp (g itself when
 * rho0 is NULL: updated methods integrate the velocity). */
sph_status body_force_create(sph_sim *sim, const double *rho0, sph_error *err);

/* Frictionless penalty contact with the scene's walls and, when asked,
 * between particles of different bodies (seed 001 sec. 2.4.2-2.4.3): adds
 * force / V0 to dp (force / mass when rho0 is NULL) and bounds the step. */
sph_status contact_create(sph_sim *sim, const double *rho0, sph_error *err);

/* Essential boundary conditions imposed directly on particles (seed 000
 * Algorithm 1 step 8): clamp, roller, prescribed velocity over a window.
 * Acts on momentum per reference volume (p = rho0 v), or on the velocity
 * when rho0 is NULL. */
sph_status essential_bc_create(sph_sim *sim, const double *rho0,
                               sph_error *err);

/* Essential boundary conditions by the Lagrange-multiplier least-squares
 * projection of seed 000 App. B over the particles of `cloud` (reference
 * configuration, no mirror images): clamps, rollers, prescribed velocities,
 * symmetry (normal) and skew-symmetry (tangential) planes constrain the
 * corrected-kernel interpolant of the momentum at the selected particles;
 * `global` adds the total momentum rows B.2. */
struct sph_cloud;
sph_status lagrange_projection_create(sph_sim *sim,
                                      const struct sph_cloud *cloud,
                                      const double *rho0, int global,
                                      sph_error *err);

#endif
