/* The pressure checkerboard indicator and the lattice parity it projects
 * on (see stability.h): the volume-weighted correlation of a field with the
 * +-1 parity of a particle's lattice cell; bodies without a lattice (relaxed
 * bodies, irregular particle files) carry parity 0 and are left out. */
#include "solver/stability.h"

#include "parallel/domain.h"
#include "scene/cloud.h"
#include "scene/geometry.h"

#include <math.h>

double sph_checkerboard_indicator_over(sph_domain *dom,
                                       const signed char *parity,
                                       const double *volume, const double *f,
                                       size_t n) {
  double sm[2] = {0.0, 0.0}; /* sum V, sum V f */
  for (size_t a = 0; a < n; ++a)
    if (parity[a]) {
      sm[0] += volume[a];
      sm[1] += volume[a] * f[a];
    }
  sph_domain_sum(dom, sm, 2);
  double sv = sm[0], mean = sm[1];
  if (!(sv > 0.0))
    return NAN;
  mean /= sv;
  double pv[2] = {0.0, 0.0}; /* projection, variance */
  for (size_t a = 0; a < n; ++a)
    if (parity[a]) {
      double d = f[a] - mean;
      pv[0] += volume[a] * parity[a] * d;
      pv[1] += volume[a] * d * d;
    }
  sph_domain_sum(dom, pv, 2);
  return pv[1] > 0.0 ? fabs(pv[0]) / sqrt(sv * pv[1]) : 0.0;
}

double sph_checkerboard_indicator(const signed char *parity,
                                  const double *volume, const double *f,
                                  size_t n) {
  return sph_checkerboard_indicator_over(NULL, parity, volume, f, n);
}

void sph_lattice_parity(const sph_scene *s, const sph_particles *ps,
                        signed char *parity) {
  for (size_t a = 0; a < ps->n; ++a) {
    const sph_body *b = &s->bodies[ps->body[a]];
    double X[3];
    sph_body_local(b, ps->field[SPH_FIELD_POSITION0] + 3 * a, X);
    parity[a] = 0;
    /* a particle file: its own lattice, when it is on one */
    const double *step =
        b->shape.kind == SPH_SHAPE_PARTICLES ? b->shape.cloud->step : NULL;
    if (b->distribution == SPH_DIST_RELAX || (step && !(step[0] > 0.0)))
      continue;
    double lo[3], hi[3];
    sph_shape_bounds(&b->shape, s->dimension, lo, hi);
    long sum = 0;
    for (int c = 0; c < s->dimension; ++c) {
      double h = step ? step[c]
                 : b->lattice == SPH_LATTICE_FACES
                     ? (hi[c] - lo[c]) / (b->count[c] - 1)
                     : b->spacing;
      double off = step || b->lattice == SPH_LATTICE_FACES ? 0.0 : 0.5;
      sum += lround((X[c] - lo[c]) / h - off);
    }
    parity[a] = (sum % 2) ? -1 : 1;
  }
}
