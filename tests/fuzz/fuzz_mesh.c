/* libFuzzer target for mesh bodies (issue 34): the input's first byte
 * picks the format libassimp is told (its value mod 5: stl, obj, ply, off,
 * 3mf), bit 7 flips the normals, the rest is the file.
 * libassimp 5.2's own importers (STL, 3MF) leak a few hundred bytes on some
 * broken files, inside the library: LeakSanitizer looks away while it reads
 * (sph's copy of the triangles is freed here, and its leaks still count). What
 * is read is made a mesh (size, volume, open edges, ray grids) and an 8 x 8 x 8
 * lattice over its box, a little beyond, is tested inside, as a body's fill
 * does, and its centre alone. A crash, a sanitizer report, a leak or a hang is
 * a finding; every refusal is fine. tests/fuzz/replay_main.c runs it over
 * tests/fuzz/regressions_mesh/ in the normal build. */
#include <stdint.h>
#include <stdlib.h>

#include "scene/mesh.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#include <sanitizer/lsan_interface.h>
#define LIBRARY_LEAKS_IGNORED(call)                                            \
  (__lsan_disable(), lsan_result = (call), __lsan_enable(), lsan_result)
static sph_status lsan_result;
#endif
#endif
#ifndef LIBRARY_LEAKS_IGNORED
#define LIBRARY_LEAKS_IGNORED(call) (call)
#endif

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc;
  (void)argv;
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static const char *const hints[] = {"stl", "obj", "ply", "off", "3mf"};
  if (size < 2)
    return 0;
  sph_error err;
  double *tri;
  size_t n;
  if (LIBRARY_LEAKS_IGNORED(sph_mesh_read_memory(
          data + 1, size - 1, hints[data[0] % 5], &tri, &n, &err)) != SPH_OK)
    return 0;
  sph_mesh *m;
  sph_status st = sph_mesh_create(&m, tri, n, 1.0, data[0] & 0x80, &err);
  free(tri);
  if (st != SPH_OK)
    return 0;
  const sph_mesh_info *in = sph_mesh_get_info(m);
  long dims[3] = {8, 8, 8};
  double axes[3][8], mid[3];
  const double *x[3] = {axes[0], axes[1], axes[2]};
  for (int c = 0; c < 3; ++c) {
    double h = (in->hi[c] - in->lo[c]) / 6.0;
    for (int i = 0; i < 8; ++i)
      axes[c][i] = in->lo[c] + (i - 1) * h;
    mid[c] = 0.5 * (in->lo[c] + in->hi[c]);
  }
  unsigned char inside[512];
  sph_mesh_inside_lattice(m, dims, x, inside, &err);
  (void)sph_mesh_inside(m, mid);
  sph_mesh_destroy(m);
  return 0;
}
