/* 2D outlines as body shapes: a polygon with holes, given as rings of
 * vertices; inside by the even-odd rule (a ray along +x crosses the rings
 * an odd number of times; each edge half-open in y, so a ray through a
 * vertex counts it once), area by the shoelace formula. */
#ifndef SPH_POLYGON_H
#define SPH_POLYGON_H

#include <stddef.h>

#include "sph/status.h"

typedef struct sph_polygon sph_polygon;

/* A polygon of nrings rings (the outline first, then its holes): ring r
 * has the points xy[2 start[r]] .. xy[2 start[r + 1] - 1], start[nrings]
 * of them in all. Refuses a ring of under 3 points or without area, and
 * points that are not finite numbers (err names the ring). */
sph_status sph_polygon_create(sph_polygon **out, const double *xy,
                              const size_t *start, size_t nrings,
                              sph_error *err);
void sph_polygon_destroy(sph_polygon *p);

/* Whether (X[0], X[1]) is inside (even-odd over every ring). */
int sph_polygon_inside(const sph_polygon *p, const double X[3]);

/* The outline's bounding box and the area inside (the outline's less its
 * holes'). */
void sph_polygon_bounds(const sph_polygon *p, double lo[2], double hi[2]);
double sph_polygon_area(const sph_polygon *p);

#endif
