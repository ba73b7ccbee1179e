/* Outline files of 2D bodies: CSV (x, y a line, a blank line between
 * rings) and SVG (polygon, polyline, rect, circle, ellipse, and paths of
 * straight segments), read into the rings of polygon.h. */
#ifndef SPH_OUTLINE_READ_H
#define SPH_OUTLINE_READ_H

#include <stddef.h>

#include "sph/status.h"

/* The rings of the file at path (by its extension: .svg, or .csv/.txt):
 * *xy 2 numbers a point, ring r the points [start[r], start[r + 1]), both
 * malloc'd; SVG y turned up (y -> -y). Errors name the file and line. */
sph_status sph_outline_read(const char *path, double **xy, size_t **start,
                            size_t *nrings, sph_error *err);

#endif
