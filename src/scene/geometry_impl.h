/* What geometry.c (shapes, lattices, bodies) and relax.c (the relaxation,
 * serial and over MPI ranks) share. */
#ifndef SPH_GEOMETRY_IMPL_H
#define SPH_GEOMETRY_IMPL_H

#include <math.h>
#include <stddef.h>

#include "scene/scene.h"
#include "sph/status.h"

static inline double hypot3(double a, double b, double c) {
  return sqrt(a * a + b * b + c * c);
}

static inline int shape_is_axial(const sph_shape *s, int dim) {
  return s->kind == SPH_SHAPE_CYLINDER ||
         (s->kind == SPH_SHAPE_RING && dim == 3);
}

/* A growing set of points and their volumes. */
typedef struct pointset {
  double *x, *v;
  size_t n, cap;
} pointset;

/* An sph_point_fn appending to the pointset ctx. */
sph_status sph_pointset_push(void *ctx, const double X[3], double volume,
                             sph_error *err);

/* Relaxes the n points of p (body b's lattice, jittered) in place, serially
 * (b->relax_steps shifting steps). */
sph_status sph_body_relax(const sph_body *b, int dim, pointset *p,
                          sph_error *err);

#endif
