/* Reference solutions a scene can name in its `reference:` block, used to
 * set the initial state and to measure errors:
 *   reference: {analytic: swinging_cube, U0: 5e-4, A: 1, B: 1, C: 1}
 * is the swinging cube of seed 000 sec. 8.2 eq. 52,
 * u_i = U0 f_i(X) (m cos(w_d t) + (A_i - m) cos(w_s t)), m = (A + B + C)/3,
 * w_d = sqrt(3)/2 c_d pi, w_s = sqrt(3)/2 c_s pi (exact for every A, B, C:
 * the mean part is the dilatational mode, the zero-sum part a shear mode), with
 * f = (sin cos cos, cos sin cos, cos cos sin) of (pi X / 2) and the small
 * strain stress of the body's material. The initial state is F = I + grad u,
 * x = X + u and p = 0 (seed 000 sec. 8.2): methods that carry F as a
 * variable take F, those that derive it from the positions take x; methods
 * that cannot start deformed refuse the reference. Errors are L2 norms over the
 * particles (volume weighted), normalised by the amplitude of the exact field:
 * e_v by U0 max_i(w_d |m| + w_s |A_i - m|), e_P by the largest |P| at t = 0,
 * e_u by U0; the H1 seminorm error e_g of grad u_h = F - I (the DEFGRAD
 * field) by U0 pi / 2, the amplitude of grad f.
 *
 *   reference: {analytic: swinging_plate, U: 0.01}
 * is the swinging plate of seed 004 sec. 5.1 eq. 42-43 on [0, 2]^2 (2D),
 * u = U sin(w t) (-sin(pi X1/2) cos(pi X2/2), cos(pi X1/2) sin(pi X2/2)),
 * w = (pi/2) sqrt(2 mu / rho): the zero-sum mode of the cube in the plane,
 * started undeformed with the velocity U w f(X), with the same errors (e_P
 * normalised by the largest |P| of the mode at full amplitude). These are
 * particle (nodal) quadratures. With `norm: gauss`
 *   reference: {analytic: swinging_plate, U: 0.01, norm: gauss}
 * the paper's norms are reported beside them (l2_displacement_gauss,
 * h1_displacement_gauss): eq. 44-45, absolute, integrated with 5 x 5 Gauss
 * points on 10 x 10 tiles of [0, 2]^2 over the first-order corrected
 * kernel interpolant of the displacements (solver/reference_gauss.h); the
 * default `norm: nodal` reports the nodal errors only.
 *
 *   reference: {period: {at: [0.2, 0], component: y}, value: 0.254,
 *               tolerance: 0.05}
 * is a scalar reference: the period of the displacement component of the
 * particle nearest to `at` in the reference configuration, measured from the
 * zero crossings of that displacement at the output frames (linear
 * interpolation; near a crossing a sinusoid is linear to third order), as
 * the mean over the half periods between the first and the last crossing:
 * T = 2 (t_last - t_first) / (crossings - 1). Its error is |T - value| /
 * value; `tolerance` (optional) is reported with it. */
#ifndef SPH_REFERENCE_H
#define SPH_REFERENCE_H

#include "io/sink.h"
#include "scene/scene.h"
#include "solver/sim.h"
#include "sph/status.h"

typedef struct sph_reference sph_reference;

/* NaN where the reference does not give the quantity */
typedef struct sph_reference_error {
  double l2_velocity, l2_stress, l2_displacement, h1_displacement;
  double period, period_value, period_error, period_tolerance;
  /* norm: gauss, seed 004 eq. 44-45 (absolute) */
  double l2_displacement_gauss, h1_displacement_gauss;
} sph_reference_error;

/* NULL (and SPH_OK) when the scene has no reference block. */
sph_status sph_reference_create(sph_reference **out, const sph_scene *s,
                                sph_error *err);
void sph_reference_destroy(sph_reference *r);

/* Fills the particles' POSITION, VELOCITY and DEFGRAD with the state at
 * t = 0 and marks sim->initial_defgrad. */
sph_status sph_reference_initialise(const sph_reference *r, sph_sim *sim,
                                    sph_error *err);

/* Takes an output frame (after method->derive) into the measurement; over
 * MPI ranks collective (the owner of the observed particle gives it). */
void sph_reference_observe(sph_reference *r, const sph_frame *frame);

/* The measurement's state for checkpoints: fills arr and returns 1, or 0
 * when the reference keeps none (r may be NULL). */
int sph_reference_state(sph_reference *r, sph_state_array *arr);

/* Errors of the derived fields (velocity, first Piola-Kirchhoff stress,
 * displacement x - X) at the sim's time, or the measured period. Over MPI
 * ranks collective, the result on rank 0: it adds every particle's terms
 * in the serial order (a range of storage indices at a time), so the
 * errors are the serial run's. */
sph_status sph_reference_errors(const sph_reference *r, const sph_sim *sim,
                                sph_reference_error *e, sph_error *err);

#endif
