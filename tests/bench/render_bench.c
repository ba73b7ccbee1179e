/* render_bench: seconds per frame of the OSMesa sphere pass for random
 * spheres in a unit cube (radius from the mean spacing), seen by the fitted
 * perspective camera.
 *   render_bench [WIDTH HEIGHT [N...]] (default 1280 720 10000 100000 1000000)
 * Prints context creation time, then per N the first frame and the mean of
 * the following frames; SPH_BENCH_PPM=path writes the last frame. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "gl_impl.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Repeatable uniform numbers in [0, 1). */
static double next_uniform(uint64_t *s) {
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*s >> 11) / 9007199254740992.0;
}

static int fail(const char *what, const sph_error *err) {
  fprintf(stderr, "render_bench: %s: %s\n", what, err->message);
  return 1;
}

int main(int argc, char **argv) {
  int w = argc > 2 ? atoi(argv[1]) : 1280, h = argc > 2 ? atoi(argv[2]) : 720;
  size_t counts[16] = {10000, 100000, 1000000};
  int nc = 3;
  if (argc > 3) {
    nc = 0;
    for (int a = 3; a < argc && nc < 16; ++a)
      counts[nc++] = (size_t)strtoull(argv[a], NULL, 10);
  }
  sph_error err;
  sph_gl *gl = NULL;
  /* context */
  double t0 = now();
  if (sph_gl_create(w, h, &gl, &err) != SPH_OK)
    return fail("create", &err);
  printf("context %dx%d: %.3f s\n", w, h, now() - t0);
  sph_image img = {w, h, malloc((size_t)w * h * 4)};
  if (!img.rgba)
    return 1;
  for (int c = 0; c < nc; ++c) {
    size_t n = counts[c];
    float *xyz = malloc(n * 3 * sizeof *xyz);
    unsigned char *rgb = malloc(n * 3);
    if (!xyz || !rgb)
      return 1;
    /* random centres, colours by height */
    uint64_t seed = 12345;
    for (size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k)
        xyz[3 * i + k] = (float)next_uniform(&seed);
      double t = xyz[3 * i + 1];
      rgb[3 * i + 0] = (unsigned char)(40 + 200 * t);
      rgb[3 * i + 1] = 120;
      rgb[3 * i + 2] = (unsigned char)(240 - 200 * t);
    }
    float r = (float)(0.5 / cbrt((double)n));
    const double lo[3] = {-r, -r, -r}, hi[3] = {1 + r, 1 + r, 1 + r};
    sph_view v;
    sph_view_fit(lo, hi, 35.0, 25.0, 1.0, 0, 3, w, h, &v);
    /* first frame (buffer growth, shader variants), then the steady state */
    t0 = now();
    if (sph_gl_draw_spheres(gl, &v, n, xyz, r, rgb, NULL, &img, &err) != SPH_OK)
      return fail("draw", &err);
    double first = now() - t0;
    int frames = n >= 1000000 ? 3 : 5;
    t0 = now();
    for (int f = 0; f < frames; ++f)
      if (sph_gl_draw_spheres(gl, &v, n, xyz, r, rgb, NULL, &img, &err) !=
          SPH_OK)
        return fail("draw", &err);
    printf("%8zu spheres: first %.3f s, then %.3f s per frame\n", n, first,
           (now() - t0) / frames);
    free(xyz);
    free(rgb);
  }
  /* optional picture of the last frame */
  const char *ppm = getenv("SPH_BENCH_PPM");
  if (ppm) {
    FILE *f = fopen(ppm, "wb");
    if (f) {
      fprintf(f, "P6\n%d %d\n255\n", w, h);
      for (size_t i = 0; i < (size_t)w * h; ++i)
        fwrite(img.rgba + 4 * i, 1, 3, f);
      fclose(f);
    }
  }
  free(img.rgba);
  t0 = now();
  sph_gl_destroy(gl);
  printf("destroy: %.3f s\n", now() - t0);
  return 0;
}
