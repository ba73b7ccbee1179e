/* Geometry generators: shapes as signed distance functions and the particle
 * lattices that fill them (box, cylinder, ring/annulus, disc, sphere,
 * spherical shell), with optional jitter and relaxation to an irregular,
 * uniform distribution. */
#ifndef SPH_GEOMETRY_H
#define SPH_GEOMETRY_H

#include <stddef.h>

#include "scene/scene.h"
#include "sph/status.h"

/* Signed distance from X to the shape's surface (negative inside). 2D shapes
 * ignore z. */
double sph_shape_distance(const sph_shape *s, int dim, const double X[3]);

/* Axis-aligned bounding box of the shape. */
void sph_shape_bounds(const sph_shape *s, int dim, double lo[3], double hi[3]);

/* Exact area (2D) or volume (3D) of the shape. */
double sph_shape_measure(const sph_shape *s, int dim);

/* Particles of one body in its own frame (the scene applies the body's
 * transform): *x (3 per particle) and *v (volumes), malloc'd,
 * *n of them. Deterministic for a given body (seeded RNG). */
/* A body's particle before relaxation, in its own frame. */
typedef sph_status (*sph_point_fn)(void *ctx, const double X[3], double volume,
                                   sph_error *err);

/* Calls fn for each particle of the body in creation order, as
 * sph_body_generate makes them (lattice and jitter) but without storing
 * them, and for a `relax` body its points before the relaxation; *n is the
 * number visited. Stops at fn's first error. */
sph_status sph_body_visit(const sph_body *b, int dim, sph_point_fn fn,
                          void *ctx, size_t *n, sph_error *err);

sph_status sph_body_generate(const sph_body *b, int dim, double **x,
                             double **volume, size_t *n, sph_error *err);

/* Over MPI ranks (collective): sph_body_visit of a lattice or jitter body,
 * and for a `relax` body every particle as sph_body_generate makes it (the
 * relaxed points, bit for bit, with their equal volumes) in creation order,
 * the relaxation made per rank: on the first call each rank relaxes the
 * slice [N r / R, N (r + 1) / R) of the N points into *slice (NULL before;
 * kept for later calls, sph_body_slice_destroy after), with the other
 * ranks' points within reach as ghosts; each call streams every rank's
 * slice in rank order. */
typedef struct sph_body_slice sph_body_slice;
sph_status sph_body_visit_share(const sph_body *b, int dim,
                                sph_body_slice **slice, sph_point_fn fn,
                                void *ctx, size_t *n, sph_error *err);
void sph_body_slice_destroy(sph_body_slice *s);

#endif
