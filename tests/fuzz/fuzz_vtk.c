/* libFuzzer target for the VTK reader `sph render` uses (src/io/vtk_read.c,
 * issue 36): the .pvd collection, a .vtp and a .pvtp with its pieces.
 *
 * The input's first byte picks the file (its value mod 3: .pvd, .vtp,
 * .pvtp; bit 7 set: the points only, no named array), the second the point
 * count the reader is told the run has (0..255), and the rest is the file;
 * for a .pvtp the rest is cut at each "\n@@piece@@\n" into the .pvtp and up
 * to two pieces, written beside it as p0.vtp and p1.vtp. Each is read as
 * `sph render` reads it (the array "pressure", one component). A crash, a
 * sanitizer report, a leak or a hang is a finding; every refusal is fine.
 * tests/fuzz/replay_main.c runs the same function over the regression
 * inputs of tests/fuzz/regressions_vtk/ in the normal build. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/vtk_read.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64];
static const char *const files[] = {"f.pvd", "f.vtp", "f.pvtp", "p0.vtp",
                                    "p1.vtp"};

static void clean(void) {
  char path[128];
  for (size_t i = 0; i < sizeof files / sizeof *files; ++i) {
    snprintf(path, sizeof path, "%s/%s", dir, files[i]);
    unlink(path);
  }
  rmdir(dir);
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc;
  (void)argv;
  snprintf(dir, sizeof dir, "/tmp/sph_fuzz_vtk_XXXXXX");
  if (!mkdtemp(dir)) {
    perror("fuzz_vtk: mkdtemp");
    abort();
  }
  atexit(clean);
  return 0;
}

static void put(const char *name, const uint8_t *p, size_t len) {
  char path[128];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "wb");
  if (!f || fwrite(p, 1, len, f) != len || fclose(f) != 0)
    abort();
}

/* the next piece of [*p, end) up to the separator */
static size_t cut(const uint8_t **p, const uint8_t *end, const uint8_t **at) {
  static const char sep[] = "\n@@piece@@\n";
  const size_t sl = sizeof sep - 1;
  *at = *p;
  for (const uint8_t *q = *p; q + sl <= end; ++q)
    if (!memcmp(q, sep, sl)) {
      *p = q + sl;
      return (size_t)(q - *at);
    }
  *p = end;
  return (size_t)(end - *at);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 2)
    return 0;
  int kind = data[0] % 3, named = !(data[0] & 0x80);
  size_t n = data[1];
  const uint8_t *p = data + 2, *end = data + size, *at;
  const char *const *names = files;
  size_t len = cut(&p, end, &at);
  if (kind < 2) /* the separator is data there */
    len = (size_t)(end - at);
  put(names[kind], at, len);
  if (kind == 2)
    for (int r = 0; r < 2; ++r) {
      char piece[16];
      snprintf(piece, sizeof piece, "p%d.vtp", r);
      len = cut(&p, end, &at);
      put(piece, at, len);
    }
  char path[128];
  snprintf(path, sizeof path, "%s/%s", dir, names[kind]);
  sph_error err;
  sph_error_clear(&err);
  if (kind == 0) {
    sph_pvd pvd;
    if (sph_pvd_read(path, &pvd, &err) == SPH_OK)
      sph_pvd_destroy(&pvd);
    return 0;
  }
  double *x = malloc(3 * (n ? n : 1) * sizeof *x);
  double *v = malloc((n ? n : 1) * sizeof *v);
  double t;
  if (!x || !v)
    abort();
  sph_vtp_read(path, n, x, named ? "pressure" : NULL, 1, v, &t, &err);
  free(x);
  free(v);
  return 0;
}
