/* The verdict's energy growth from rest (issue 35): a free body at rest or
 * translating rigidly whose energy beyond the translation passes the
 * energy floor trips `energy_growth` (see sph_verdict_energy_from_rest). */
#include <math.h>
#include <stdio.h>

#include "solver/sim.h"
#include "solver/stability.h"

/* Issue 35: free bodies (no boundary, wall or external work) that start
 * at rest or translating rigidly (energy beyond the translation |P|^2 / 2M
 * below SPH_REST_START sum m c0^2, a strain of about 1e-6) must keep the
 * kinetic energy of their motion relative to the mean velocity P / M,
 * sum m |v - P / M|^2 / 2 (summed directly: no cancellation), below the
 * energy floor (a uniform strain of about 1e-10): a growing round-off (an
 * unstable mode of the discretisation) passes it long before the relative
 * bound or a fracture sees it. The stored energy is not used: its
 * evaluation's round-off (mu eps V) lies above the floor. Judged from the
 * checkpointed energy0 and lin0, so a resumed run judges alike. */
void sph_verdict_energy_from_rest(sph_verdict *v, const sph_frame *fr, double E,
                                  const double lin[3]) {
  char msg[256];
  const sph_scene *s = fr->sim->scene;
  const sph_particles *ps = fr->ps;
  const double *m = ps->field[SPH_FIELD_MASS];
  const double *vel = ps->field[SPH_FIELD_VELOCITY];
  if (!v->energy_tracked || s->nboundaries || s->contact.nwalls || !m || !vel)
    return;
  (void)E;
  double M = 0.0, p0 = 0.0;
  for (size_t a = 0; a < ps->n; ++a)
    M += m[a];
  sph_domain_sum(v->dom, &M, 1);
  if (!(M > 0.0))
    return;
  for (int c = 0; c < 3; ++c)
    p0 += v->lin0[c] * v->lin0[c];
  double e0 = v->energy0 - p0 / (2 * M);
  if (e0 > SPH_REST_START / SPH_ENERGY_FLOOR * v->energy_floor)
    return;
  double k = 0.0;
  for (size_t a = 0; a < ps->n; ++a)
    for (int c = 0; c < 3; ++c) {
      double d = vel[3 * a + c] - lin[c] / M;
      k += 0.5 * m[a] * d * d;
    }
  sph_domain_sum(v->dom, &k, 1);
  if (k <= v->energy_floor)
    return;
  snprintf(msg, sizeof msg,
           "energy growth from rest: kinetic energy %.3g J relative to the "
           "mean velocity exceeds %.3g J (a uniform strain of about 1e-10) "
           "in a free body that started at rest or translating",
           k, v->energy_floor);
  sph_verdict_fail(v, SPH_INDICATOR_ENERGY_GROWTH, fr->time, msg);
}
