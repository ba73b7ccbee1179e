/* Triangle meshes as body shapes: a surface read from a file (STL, OBJ,
 * PLY... through libassimp), its size and soundness (bounding box, signed
 * volume by the divergence theorem, open edges), and which points it holds:
 * ray parity along the three coordinate axes, by majority vote, so that a
 * small hole, a flipped or duplicated triangle or a second shell only
 * misleads the rays that pass through it. Each axis has a 2D grid of the
 * triangles' projected boxes; rays are decided exactly on edges and
 * vertices (simulation of simplicity: the ray is moved by (d, d^2), d -> 0),
 * so a closed surface is crossed an odd number of times whatever the ray. */
#ifndef SPH_MESH_H
#define SPH_MESH_H

#include <stddef.h>

#include "sph/status.h"

typedef struct sph_mesh sph_mesh;

typedef struct sph_mesh_info {
  size_t triangles;  /* as read */
  size_t open_edges; /* edges of one triangle only */
  double lo[3], hi[3];
  double volume; /* signed, after flipping */
} sph_mesh_info;

/* Reads the triangles of a mesh file into *tri (9 numbers a triangle,
 * malloc'd), *n of them; SPH_ERR_IO when it is missing, unreadable, has no
 * triangles or this build has no mesh reader (libassimp). */
sph_status sph_mesh_read(const char *path, double **tri, size_t *n,
                         sph_error *err);

/* The same from bytes in memory; hint: the format's file extension ("stl"). */
sph_status sph_mesh_read_memory(const void *bytes, size_t len, const char *hint,
                                double **tri, size_t *n, sph_error *err);

/* A mesh of n triangles (9 numbers each: three corners), scaled by `scale`
 * and with every triangle's orientation reversed when `flip`. */
sph_status sph_mesh_create(sph_mesh **out, const double *tri, size_t n,
                           double scale, int flip, sph_error *err);
void sph_mesh_destroy(sph_mesh *m);

const sph_mesh_info *sph_mesh_get_info(const sph_mesh *m);

/* Whether X is inside (at least two of the three axis rays cross the
 * surface an odd number of times beyond X). */
int sph_mesh_inside(const sph_mesh *m, const double X[3]);

/* The distance from X to the nearest triangle (every triangle's box looked
 * at: for the small meshes of selections). */
double sph_mesh_distance(const sph_mesh *m, const double X[3]);

/* The same for every point of a lattice: point (i, j, k) is
 * (x[0][i], x[1][j], x[2][k]), n[c] values on axis c, each axis ascending;
 * inside[(i n1 + j) n2 + k] set to 0 or 1. Rows in parallel (OpenMP), the
 * result independent of the thread count. */
sph_status sph_mesh_inside_lattice(const sph_mesh *m, const long n[3],
                                   const double *const x[3],
                                   unsigned char *inside, sph_error *err);

#endif
