/* Particle files as body shapes (shape: {particles: {file}}): positions and
 * optional volumes from a CSV with a header naming its columns (x, y[, z]
 * [, volume], others ignored) or from a .vtp/.pvtp that sph wrote (its
 * points and `volume` array), checked (finite, positive volumes, distinct
 * positions, the scene's dimension) and measured (the median distance to
 * the nearest neighbour, the spacing of a body that gives none). */
#ifndef SPH_CLOUD_H
#define SPH_CLOUD_H

#include <stddef.h>

#include "sph/status.h"

typedef struct sph_cloud {
  size_t n;
  double *x;      /* 3 a particle (z = 0 in 2D) */
  double *v;      /* volumes; those of a file without them are set by
                     sph_cloud_set_volumes */
  int has_volume; /* the file gave them */
  double lo[3], hi[3];
  double nn_median; /* median nearest-neighbour distance (0: one point) */
  double step[3];   /* a lattice's step per axis (the verdict's checkerboard
                       parity), 0 when the particles are not on one */
} sph_cloud;

/* Reads the file at path (.csv/.txt, or .vtp/.pvtp) for a body of dimension
 * dim, positions scaled by `scale` and volumes by scale^dim. Errors name
 * the file (and a CSV's line): missing or empty, a missing column, a value
 * that is not a finite number, a volume <= 0, two particles at one
 * position, a 2D file for a 3D body or the reverse, no points. */
sph_status sph_cloud_read(const char *path, int dim, double scale,
                          sph_cloud **out, sph_error *err);

/* A file without volumes: each particle dp^dim. */
void sph_cloud_set_volumes(sph_cloud *c, int dim, double dp);

/* The particles' total volume (area in 2D). */
double sph_cloud_volume(const sph_cloud *c);

void sph_cloud_destroy(sph_cloud *c);

#endif
