/* Mesh fill speed (not a test): reads a mesh, builds its ray grids and
 * fills it with a lattice of the given spacing as a body does
 * (sph_body_generate), printing each phase's wall time.
 *   build/tests/mesh_bench MESH SPACING   (threads: OMP_NUM_THREADS)
 * tests/bench/mesh_bench.sh makes a 100k-triangle sphere and fills it with
 * about 1M particles. */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

#include "scene/geometry.h"
#include "scene/mesh.h"

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: mesh_bench MESH SPACING\n");
    return 2;
  }
  sph_error err;
  double *tri, t0 = omp_get_wtime();
  size_t n;
  if (sph_mesh_read(argv[1], &tri, &n, &err) != SPH_OK) {
    fprintf(stderr, "%s\n", err.message);
    return 1;
  }
  double t1 = omp_get_wtime();
  sph_body b = {.name = "part", .lattice = SPH_LATTICE_CELL_CENTRED};
  b.spacing = atof(argv[2]);
  b.shape.kind = SPH_SHAPE_MESH;
  if (sph_mesh_create(&b.shape.mesh, tri, n, 1.0, 0, &err) != SPH_OK) {
    fprintf(stderr, "%s\n", err.message);
    return 1;
  }
  free(tri);
  const sph_mesh_info *in = sph_mesh_get_info(b.shape.mesh);
  for (int c = 0; c < 3; ++c) {
    b.shape.min[c] = in->lo[c];
    b.shape.max[c] = in->hi[c];
  }
  double t2 = omp_get_wtime(), *x, *v;
  if (sph_body_generate(&b, 3, &x, &v, &n, &err) != SPH_OK) {
    fprintf(stderr, "%s\n", err.message);
    return 1;
  }
  double t3 = omp_get_wtime(), vol = 0.0;
  for (size_t a = 0; a < n; ++a)
    vol += v[a];
  printf("%zu triangles, %zu open edges, volume %.6g; %d threads\n"
         "read %.3f s, grids %.3f s, fill %.3f s: %zu particles (volume "
         "%.6g), %.3f s in all\n",
         in->triangles, in->open_edges, in->volume, omp_get_max_threads(),
         t1 - t0, t2 - t1, t3 - t2, n, vol, t3 - t0);
  free(x);
  free(v);
  sph_mesh_destroy(b.shape.mesh);
  return 0;
}
