/* The stability verdict of a run: indicators checked at every output time,
 * the first one that trips and when. Thresholds:
 *  - nan: any non-finite position, velocity or stress;
 *  - J <= 0 anywhere (inverted material);
 *  - energy growth: kinetic + strain energy above (1 + SPH_ENERGY_GROWTH_MAX)
 *    times its initial value (only for scenes without prescribed velocities
 *    or body forces, whose external work is not tracked);
 *  - pressure checkerboard: the red-black mode fraction of BENCHMARKS.md
 *    D.3, C = |sum V s (p - pbar)| / sqrt(sum V * sum V (p - pbar)^2) with
 *    s_a = (-1)^(i+j+k) the parity of the particle's lattice index (bodies
 *    made from a lattice, jittered or not; relaxed bodies carry no parity).
 *    0 <= C <= 1: about 0 for smooth fields, 1 for a pure red-black
 *    alternation; tripped above SPH_CHECKERBOARD_MAX. */
#ifndef SPH_STABILITY_H
#define SPH_STABILITY_H

#include "sph/sink.h"

#define SPH_ENERGY_GROWTH_MAX 0.05
#define SPH_CHECKERBOARD_MAX 0.5

typedef struct sph_verdict {
  int stable;
  int nan;
  char reason[256];
  double t_tripped;
  int energy_tracked;
  int frames;
  double energy0, energy_max, energy_final;
  double J_min, J_max;
  double checkerboard, checkerboard_max;
  double lin0[3], ang0[3], lin_scale, ang_scale;
  double lin_drift, ang_drift; /* largest relative drift seen */
  signed char *parity;         /* s_a = +-1, 0 without a lattice */
  int has_parity;
} sph_verdict;

sph_status sph_verdict_create(sph_verdict **out, const sph_sim *sim,
                              sph_error *err);
void sph_verdict_destroy(sph_verdict *v);

/* Updates the indicators from a frame (after method->derive). */
void sph_verdict_observe(sph_verdict *v, const sph_frame *frame);

/* Marks the run unstable for a reason found elsewhere (a failed step). */
void sph_verdict_fail(sph_verdict *v, double t, const char *reason);

/* The checkerboard indicator C of field f (see above); NaN when no particle
 * has a parity. */
double sph_checkerboard_indicator(const signed char *parity,
                                  const double *volume, const double *f,
                                  size_t n);

/* Lattice parity of every particle of a scene's bodies. */
void sph_lattice_parity(const sph_scene *s, const sph_particles *ps,
                        signed char *parity);

/* summary.json (keys documented in the README): `sinks` holds the wall
 * seconds of each of the nsinks sinks; mp4_seconds >= 0 adds the time the
 * mp4 took to assemble. */
sph_status sph_summary_write(const char *path, const sph_sim *sim,
                             const sph_verdict *v, double wall_seconds,
                             const sph_sink *sinks, int nsinks,
                             double mp4_seconds, int completed, sph_error *err);

#endif
