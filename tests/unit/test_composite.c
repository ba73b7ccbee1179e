/* Sort-last compositing (sph/composite.h, render/gl.c's tagged draw): a
 * lattice of lit spheres in three layers, with coincident spheres (equal
 * depths) and spheres the clip plane removes, dealt out in ascending keys
 * to three "ranks" drawn tagged and composited pixel by pixel with the
 * reduction's own rule gives the frame drawn whole byte for byte, in
 * perspective and orthographic views; the tags name the first drawn of
 * coincident spheres. The exact selection over the ranks equals sorting
 * (NaN and infinities left out, -0 as +0, duplicates), and the reduction
 * helpers pass values through without a domain. */
#include "test_util.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_impl.h"
#include "parallel/composite.h"

enum { W = 160, H = 121, N = 300, RANKS = 3 }; /* an odd height: a middle row */

/* N spheres on a jittered lattice, every 7th a copy of the one before
 * (the same centre: equal depths), colours from the index */
static void spheres(float *xyz, unsigned char *rgb, uint32_t *key) {
  unsigned s = 12345u;
  for (int i = 0; i < N; ++i) {
    s = s * 1103515245u + 12345u;
    float j = (float)((s >> 16) & 1023) / 1023.0f;
    xyz[3 * i] = (float)(i % 10) * 0.2f - 0.9f + 0.05f * j;
    xyz[3 * i + 1] = (float)(i / 10 % 6) * 0.2f - 0.5f;
    xyz[3 * i + 2] = (float)(i / 60) * 0.2f - 0.4f - 0.03f * j;
    if (i % 7 == 6)
      memcpy(xyz + 3 * i, xyz + 3 * (i - 1), 3 * sizeof *xyz);
    rgb[3 * i] = (unsigned char)(37 * i);
    rgb[3 * i + 1] = (unsigned char)(91 * i + 7);
    rgb[3 * i + 2] = (unsigned char)(13 * i + 100);
    key[i] = (uint32_t)(1000 + 3 * i);
  }
}

static void composite_matches(int ortho) {
  float xyz[3 * N], part_xyz[3 * N];
  unsigned char rgb[3 * N], part_rgb[3 * N];
  uint32_t key[N], part_key[N];
  spheres(xyz, rgb, key);
  sph_view v = {{0.6, 0.8, 3.0}, {0, 0, 0}, {0, 1, 0}, 40.0,
                ortho,           2.4,       0.5,       10.0};
  double plane[4] = {-1.0, 0.0, 0.0, 0.7};
  sph_gl *gl = NULL;
  sph_error err;
  ck_assert_msg(sph_gl_create(W, H, &gl, &err) == SPH_OK, "%s", err.message);
  /* the whole frame: a flat rim and fill under the lit spheres */
  sph_image whole = {W, H, malloc(W * H * 4)};
  sph_gl_layer all[3] = {{N, xyz, 0.12f, rgb, plane, 1, NULL, key},
                         {N, xyz, 0.1f, rgb + 3, plane, 1, NULL, key},
                         {N, xyz, 0.08f, rgb, plane, 0, NULL, key}};
  all[1].n = N - 1;
  ck_assert(sph_gl_draw_layers(gl, &v, all, 3, &whole, &err) == SPH_OK);
  /* each rank draws every RANKS-th sphere, in ascending keys */
  const sph_composite_px *px = NULL;
  sph_composite_px *acc = malloc(W * H * sizeof *acc);
  for (int r = 0; r < RANKS; ++r) {
    size_t m = 0;
    for (int i = r; i < N; i += RANKS, ++m) {
      memcpy(part_xyz + 3 * m, xyz + 3 * i, 3 * sizeof *xyz);
      memcpy(part_rgb + 3 * m, rgb + 3 * i, 3);
      part_key[m] = key[i];
    }
    /* the fill layer's colours are shifted by one sphere: its own copy */
    unsigned char fill[3 * N];
    for (size_t k = 0, i = r; i < N - 1; i += RANKS, ++k)
      memcpy(fill + 3 * k, rgb + 3 * (i + 1), 3);
    size_t mf = ((size_t)(N - 1) + RANKS - 1 - r) / RANKS;
    sph_gl_layer l[3] = {
        {m, part_xyz, 0.12f, part_rgb, plane, 1, NULL, part_key},
        {mf, part_xyz, 0.1f, fill, plane, 1, NULL, part_key},
        {m, part_xyz, 0.08f, part_rgb, plane, 0, NULL, part_key}};
    ck_assert_msg(sph_gl_draw_tagged(gl, &v, l, 3, &px, &err) == SPH_OK, "%s",
                  err.message);
    for (size_t p = 0; p < (size_t)W * H; ++p)
      if (r == 0 || sph_composite_wins(&px[p], &acc[p]))
        acc[p] = px[p];
  }
  /* the composite is the whole frame, and some pixels show each layer */
  int layers[4] = {0, 0, 0, 0};
  for (size_t p = 0; p < (size_t)W * H; ++p) {
    ck_assert_mem_eq(&acc[p].rgba, whole.rgba + 4 * p, 4);
    ck_assert_uint_le(acc[p].layer, 3);
    layers[acc[p].layer]++;
  }
  ck_assert_int_gt(layers[0], 0);
  ck_assert_int_gt(layers[1], 0);
  ck_assert_int_gt(layers[3], 0);
  /* coincident spheres: the first drawn (lower key) holds the pixel */
  int seen = 0;
  for (size_t p = 0; p < (size_t)W * H; ++p) {
    uint32_t k = acc[p].key;
    if (acc[p].layer == 3 && (k - 1000) % 3 == 0 && (k - 1000) / 3 % 7 == 6)
      seen++;
  }
  ck_assert_int_eq(seen, 0);
  free(whole.rgba);
  free(acc);
  sph_gl_destroy(gl);
}

START_TEST(composite_perspective) { composite_matches(0); }
END_TEST

START_TEST(composite_ortho) { composite_matches(1); }
END_TEST

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

START_TEST(select_equals_sorting) {
  enum { M = 5000 };
  double *v = malloc(M * sizeof *v), *f = malloc(M * sizeof *f);
  unsigned s = 7u;
  size_t nf = 0;
  for (int i = 0; i < M; ++i) {
    s = s * 1103515245u + 12345u;
    int r = (int)((s >> 8) % 1000);
    v[i] = r < 5     ? NAN
           : r < 8   ? INFINITY
           : r < 10  ? -INFINITY
           : r < 40  ? -0.0
           : r < 70  ? 0.0
           : r < 200 ? 1.5 /* duplicates */
                     : ldexp((double)(r - 600), (int)(s % 40) - 20);
    if (isfinite(v[i]))
      f[nf++] = v[i] == 0.0 ? 0.0 : v[i];
  }
  qsort(f, nf, sizeof *f, cmp_double);
  uint64_t k[4] = {0, nf / 100, nf / 2, nf - 1};
  double out[4];
  sph_composite_select(NULL, v, M, k, 4, out);
  for (int t = 0; t < 4; ++t) {
    ck_assert_msg(out[t] == f[k[t]] && !signbit(out[t]) == !signbit(f[k[t]]),
                  "rank %llu: %g, sorted %g", (unsigned long long)k[t], out[t],
                  f[k[t]]);
  }
  /* every rank of a smaller set */
  for (uint64_t r = 0; r < 64; ++r) {
    double o;
    sph_composite_select(NULL, v, 100, &r, 1, &o);
    double g[100];
    size_t ng = 0;
    for (int i = 0; i < 100; ++i)
      if (isfinite(v[i]))
        g[ng++] = v[i] == 0.0 ? 0.0 : v[i];
    qsort(g, ng, sizeof *g, cmp_double);
    if (r < ng)
      ck_assert(o == g[r]);
  }
  free(v);
  free(f);
}
END_TEST

START_TEST(reductions_without_domain) {
  double lo[2] = {1.0, -2.0}, hi[2] = {3.0, 4.0};
  sph_domain_minmax(NULL, lo, hi, 2);
  ck_assert(lo[0] == 1.0 && lo[1] == -2.0 && hi[0] == 3.0 && hi[1] == 4.0);
  uint64_t c[2] = {5, 7};
  sph_composite_sum_u64(NULL, c, 2);
  ck_assert(c[0] == 5 && c[1] == 7);
  sph_composite_px a = {2, 10, 5, 0}, b = {1, 1, 1, 0};
  ck_assert(sph_composite_wins(&a, &b)); /* a later layer */
  b = (sph_composite_px){2, 10, 4, 0};
  ck_assert(!sph_composite_wins(&a, &b)); /* a tie: the lower key */
  b = (sph_composite_px){2, 11, 1, 0};
  ck_assert(sph_composite_wins(&a, &b)); /* nearer */
  sph_composite_px out;
  sph_error err;
  ck_assert(sph_composite_reduce(NULL, &a, 1, &out, &err) == SPH_OK);
  ck_assert_mem_eq(&out, &a, sizeof a);
}
END_TEST

int main(void) {
  Suite *s = suite_create("composite");
  TCase *tc = tcase_create("composite");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, composite_perspective);
  tcase_add_test(tc, composite_ortho);
  tcase_add_test(tc, select_equals_sorting);
  tcase_add_test(tc, reductions_without_domain);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
