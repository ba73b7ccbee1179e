/* What the total-Lagrangian methods share: the reference configuration
 * (same-body neighbours, corrected kernel gradients of seed 000 eq. 21 /
 * seed 001 eq. 8, reverse slots), per-particle material and density, the
 * derived output fields and the energy. */
#ifndef SPH_TL_COMMON_IMPL_H
#define SPH_TL_COMMON_IMPL_H

#include <stddef.h>

#include "sph/material.h"
#include "sph/neighbors.h"
#include "sph/sim.h"

typedef struct tl_reference {
  sph_neighbors *nl;        /* reference configuration, same body only */
  double *grad;             /* corrected gradient per slot (3) */
  size_t *rev;              /* slot of (b -> a) for slot (a -> b) */
  const sph_material **mat; /* per particle */
  double *rho0;             /* per particle */
  double cp;                /* largest p-wave speed of the materials */
} tl_reference;

/* Builds everything above in the reference configuration (timed as
 * "corrections") and allocates the state fields every TL method carries:
 * POSITION (= X), MOMENTUM (= rho0 v0), DEFGRAD (= I), JACOBIAN (= 1), PK1,
 * MASS and the derived output fields. */
sph_status tl_reference_create(tl_reference *ref, sph_sim *sim, sph_error *err);
void tl_reference_destroy(tl_reference *ref);

/* Derived fields from the state: velocity, displacement, J, Cauchy stress,
 * pressure tr(sigma)/3 (seed 000 eq. 11), von Mises. H and J may be NULL
 * (then cof F and det F); P must hold the stress of the state. */
void tl_derive(sph_sim *sim, const tl_reference *ref, const double *x,
               const double *p, const double *F, const double *J,
               const double *P);

/* Kinetic and strain energy; H and J may be NULL (cof F, det F). */
void tl_energy(sph_sim *sim, const tl_reference *ref, const double *p,
               const double *F, const double *H, const double *J,
               double *kinetic, double *strain);

#endif
