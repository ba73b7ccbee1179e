/* Reference solutions a scene can name in its `reference:` block, used to
 * set the initial state and to measure errors:
 *   reference: {analytic: swinging_cube, U0: 5e-4, A: 1, B: 1, C: 1}
 * is the dilatational mode of the unit cube of seed 000 sec. 8.2 eq. 52,
 * u_i = U0 cos(w t) A_i f_i(X), w = sqrt(3)/2 c_d pi, with
 * f = (sin cos cos, cos sin cos, cos cos sin) of (pi X / 2) and the small
 * strain stress of the body's material. The initial state is F = I + grad u
 * and p = 0 (seed 000 sec. 8.2). Errors are L2 norms over the particles
 * (volume weighted), normalised by the amplitude of the exact field:
 * e_v by U0 w max|A_i|, e_P by the largest |P| at t = 0, e_u by U0. */
#ifndef SPH_REFERENCE_H
#define SPH_REFERENCE_H

#include "sph/scene.h"
#include "sph/sim.h"
#include "sph/status.h"

typedef struct sph_reference sph_reference;

typedef struct sph_reference_error {
  double l2_velocity, l2_stress, l2_displacement;
} sph_reference_error;

/* NULL (and SPH_OK) when the scene has no reference block. */
sph_status sph_reference_create(sph_reference **out, const sph_scene *s,
                                sph_error *err);
void sph_reference_destroy(sph_reference *r);

/* Fills the particles' VELOCITY and DEFGRAD with the state at t = 0 and
 * marks sim->initial_defgrad. */
sph_status sph_reference_initialise(const sph_reference *r, sph_sim *sim,
                                    sph_error *err);

/* Errors of the derived fields (velocity, first Piola-Kirchhoff stress,
 * displacement since t = 0) at the sim's time. */
void sph_reference_errors(const sph_reference *r, const sph_sim *sim,
                          sph_reference_error *e);

#endif
