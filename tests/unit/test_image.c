/* Images: creation limits, the tolerant comparison on synthetic scenes
 * (identical, one odd pixel, shifted, recoloured, a missing small disc,
 * symmetry, tolerance), the difference image, PNG round trips and
 * byte-identical rewrites, other PNG colour types read through libpng,
 * broken files refused with the path named, and the speed at 1280x720. */
#include "test_util.h"

#include <png.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "render/image.h"
#include "test_image_util.h"

static char tmpdir[64];

static void make_tmpdir(void) {
  snprintf(tmpdir, sizeof tmpdir, "/tmp/sph_image_XXXXXX");
  ck_assert_ptr_nonnull(mkdtemp(tmpdir));
}

static void remove_tmpdir(void) {
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
  ck_assert_int_eq(system(cmd), 0);
}

static int exists(const char *p) {
  struct stat st;
  return stat(p, &st) == 0;
}

/* Whole file into a new buffer; returns its size (0 when unreadable). */
static size_t slurp(const char *path, unsigned char **buf) {
  *buf = NULL;
  FILE *f = fopen(path, "rb");
  if (!f)
    return 0;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  *buf = malloc((size_t)n + 1);
  size_t got = fread(*buf, 1, (size_t)n, f);
  fclose(f);
  return got;
}

static void write_bytes(const char *path, const void *data, size_t n) {
  FILE *f = fopen(path, "wb");
  ck_assert_ptr_nonnull(f);
  ck_assert_uint_eq(fwrite(data, 1, n, f), n);
  fclose(f);
}

static double seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static sph_imgdiff_result diff_ok(const sph_image *a, const sph_image *b,
                                  const sph_imgdiff_options *o) {
  sph_imgdiff_result r;
  sph_error err;
  sph_status st = sph_image_diff(a, b, o, &r, NULL, &err);
  ck_assert_msg(st == SPH_OK, "diff failed: %s", err.message);
  return r;
}

START_TEST(create_limits) {
  sph_image img;
  sph_error err;
  ck_assert_int_eq(sph_image_create(&img, 3, 2, &err), SPH_OK);
  ck_assert(img.width == 3 && img.height == 2 && img.rgba);
  unsigned char zero[24] = {0};
  ck_assert_int_eq(memcmp(img.rgba, zero, sizeof zero), 0);
  sph_image_destroy(&img);
  ck_assert(img.rgba == NULL && img.width == 0 && img.height == 0);
  sph_image_destroy(&img); /* twice is harmless */
  sph_image_destroy(NULL);
  const int bad[][2] = {{0, 5}, {5, 0}, {-1, 5}, {16385, 1}, {1, 16385}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    ck_assert_int_eq(sph_image_create(&img, bad[i][0], bad[i][1], &err),
                     SPH_ERR_ARG);
    ck_assert(img.rgba == NULL && img.width == 0);
  }
  ck_assert_ptr_nonnull(strstr(err.message, "16384"));
  ck_assert_int_eq(sph_image_create(&img, 16384, 1, &err), SPH_OK);
  sph_image_destroy(&img);
}
END_TEST

START_TEST(identical_images_pass) {
  sph_image a, b;
  sph_error err;
  ck_assert_int_eq(sph_test_scene(&a, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  ck_assert_int_eq(sph_test_scene(&b, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  sph_imgdiff_result r = diff_ok(&a, &b, NULL);
  ck_assert(r.passed);
  ck_assert_int_eq(r.bad_pixels, 0);
  ck_assert_int_eq(r.largest_cluster, 0);
  ck_assert_int_eq(r.max_channel_diff, 0);
  ck_assert(r.bad_fraction == 0.0);
  sph_imgdiff_options o;
  sph_imgdiff_defaults(&o);
  ck_assert(o.channel_tolerance == 16 && o.shift == 1 &&
            o.max_bad_fraction == 0.001 && o.max_cluster == 8);
  sph_image_destroy(&a);
  sph_image_destroy(&b);
}
END_TEST

START_TEST(one_odd_pixel) {
  sph_image a, b;
  sph_error err;
  ck_assert_int_eq(sph_test_scene(&a, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  ck_assert_int_eq(sph_test_scene(&b, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  sph_test_pixel(&b, 10, 12, 255, 255, 255, 255);
  sph_imgdiff_result r = diff_ok(&a, &b, NULL);
  ck_assert_int_eq(r.bad_pixels, 1);
  ck_assert_int_eq(r.largest_cluster, 1);
  ck_assert_int_ge(r.max_channel_diff, 200);
  ck_assert(r.passed); /* 1 of 76800 pixels, cluster 1 <= 8 */
  sph_imgdiff_options o;
  sph_imgdiff_defaults(&o);
  o.max_cluster = 0;
  r = diff_ok(&a, &b, &o);
  ck_assert_int_eq(r.bad_pixels, 1);
  ck_assert(!r.passed);
  /* the same with the roles swapped */
  r = diff_ok(&b, &a, NULL);
  ck_assert(r.bad_pixels == 1 && r.passed);
  sph_image_destroy(&a);
  sph_image_destroy(&b);
}
END_TEST

START_TEST(shifted_scenes) {
  sph_image a, b;
  sph_error err;
  ck_assert_int_eq(sph_test_scene(&a, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  /* one pixel in x, in y, diagonally: forgiven */
  const int ones[][2] = {{1, 0}, {-1, 0}, {0, 1}, {1, 1}, {-1, 1}};
  for (size_t i = 0; i < sizeof ones / sizeof ones[0]; ++i) {
    ck_assert_int_eq(
        sph_test_scene(&b, 320, 240, ones[i][0], ones[i][1], 0, 0, &err),
        SPH_OK);
    sph_imgdiff_result r = diff_ok(&a, &b, NULL);
    ck_assert_msg(r.passed && r.bad_pixels == 0,
                  "shift (%d, %d): %ld bad, cluster %ld", ones[i][0],
                  ones[i][1], r.bad_pixels, r.largest_cluster);
    ck_assert_int_gt(r.max_channel_diff, 100); /* not equal in place */
    sph_image_destroy(&b);
  }
  /* three pixels: crescents along the disc edges */
  ck_assert_int_eq(sph_test_scene(&b, 320, 240, 3, 0, 0, 0, &err), SPH_OK);
  sph_imgdiff_result r = diff_ok(&a, &b, NULL);
  ck_assert(!r.passed);
  ck_assert_int_gt(r.largest_cluster, 8);
  ck_assert_int_gt(r.bad_pixels, 100);
  /* ... which a shift allowance of 3 forgives */
  sph_imgdiff_options o;
  sph_imgdiff_defaults(&o);
  o.shift = 3;
  r = diff_ok(&a, &b, &o);
  ck_assert(r.passed && r.bad_pixels == 0);
  /* no allowance: even one pixel fails */
  sph_image_destroy(&b);
  ck_assert_int_eq(sph_test_scene(&b, 320, 240, 1, 0, 0, 0, &err), SPH_OK);
  o.shift = 0;
  r = diff_ok(&a, &b, &o);
  ck_assert(!r.passed);
  sph_image_destroy(&a);
  sph_image_destroy(&b);
}
END_TEST

START_TEST(other_colour_map_fails) {
  sph_image a, b;
  sph_error err;
  ck_assert_int_eq(sph_test_scene(&a, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  ck_assert_int_eq(sph_test_scene(&b, 320, 240, 0, 0, 1, 0, &err), SPH_OK);
  sph_imgdiff_result r = diff_ok(&a, &b, NULL);
  ck_assert(!r.passed);
  ck_assert(r.bad_fraction > 0.1);
  ck_assert_int_gt(r.largest_cluster, 1000);
  ck_assert_int_ge(r.max_channel_diff, 150);
  /* a tolerance of 255 accepts anything */
  sph_imgdiff_options o;
  sph_imgdiff_defaults(&o);
  o.channel_tolerance = 255;
  r = diff_ok(&a, &b, &o);
  ck_assert(r.passed && r.bad_pixels == 0);
  sph_image_destroy(&a);
  sph_image_destroy(&b);
}
END_TEST

START_TEST(missing_small_disc_fails_on_cluster) {
  sph_image a, b, d;
  sph_error err;
  ck_assert_int_eq(sph_test_scene(&a, 320, 240, 0, 0, 0, 1, &err), SPH_OK);
  ck_assert_int_eq(sph_test_scene(&b, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  sph_imgdiff_result r;
  ck_assert_int_eq(sph_image_diff(&a, &b, NULL, &r, &d, &err), SPH_OK);
  ck_assert_int_eq(r.bad_pixels, 29);
  ck_assert_int_eq(r.largest_cluster, 29);
  ck_assert(r.bad_fraction < 0.001); /* the fraction alone would pass */
  ck_assert(!r.passed);
  /* the difference image: red where the disc was, dimmed grey elsewhere */
  ck_assert(d.width == 320 && d.height == 240 && d.rgba);
  long red = 0, grey = 0, other = 0;
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 320; ++x) {
      const unsigned char *p = d.rgba + 4 * ((size_t)y * 320 + x);
      int in = (x - 40) * (x - 40) + (y - 200) * (y - 200) <= 9;
      if (p[3] != 255)
        other++;
      else if (in && p[0] == 255 && p[1] == 0 && p[2] == 0)
        red++;
      else if (!in && p[0] == p[1] && p[1] == p[2] && p[0] <= 128)
        grey++;
      else
        other++;
    }
  ck_assert_int_eq(red, 29);
  ck_assert_int_eq(grey, 320 * 240 - 29);
  ck_assert_int_eq(other, 0);
  sph_image_destroy(&d);
  /* a missing larger disc trips the fraction as well */
  sph_image_destroy(&b);
  ck_assert_int_eq(sph_image_create(&b, 320, 240, &err), SPH_OK);
  memcpy(b.rgba, a.rgba, (size_t)320 * 240 * 4);
  sph_test_disc(&b, 200, 120, 45, 40, 40, 48);
  r = diff_ok(&a, &b, NULL);
  ck_assert(!r.passed && r.bad_fraction > 0.001);
  sph_image_destroy(&a);
  sph_image_destroy(&b);
}
END_TEST

START_TEST(both_directions_checked) {
  /* B has a one-pixel line A lacks: every pixel of A finds its match in B,
   * only B against A sees the line */
  sph_image a, b;
  sph_error err;
  ck_assert_int_eq(sph_test_scene(&a, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  ck_assert_int_eq(sph_test_scene(&b, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  for (int x = 5; x < 65; ++x)
    sph_test_pixel(&b, x, 230, 255, 255, 0, 255);
  sph_imgdiff_result r1 = diff_ok(&a, &b, NULL);
  sph_imgdiff_result r2 = diff_ok(&b, &a, NULL);
  ck_assert_int_eq(r1.bad_pixels, 60);
  ck_assert_int_eq(r2.bad_pixels, 60);
  ck_assert(r1.largest_cluster == 60 && !r1.passed && !r2.passed);
  sph_image_destroy(&a);
  sph_image_destroy(&b);
}
END_TEST

START_TEST(channel_tolerance) {
  sph_image a, b;
  sph_error err;
  ck_assert_int_eq(sph_image_create(&a, 200, 100, &err), SPH_OK);
  ck_assert_int_eq(sph_image_create(&b, 200, 100, &err), SPH_OK);
  size_t n = (size_t)200 * 100;
  memset(a.rgba, 100, 4 * n);
  memset(b.rgba, 100, 4 * n);
  /* green up by 16 everywhere: equal at the default tolerance */
  for (size_t i = 0; i < n; ++i)
    b.rgba[4 * i + 1] = 116;
  sph_imgdiff_result r = diff_ok(&a, &b, NULL);
  ck_assert(r.passed && r.bad_pixels == 0 && r.max_channel_diff == 16);
  /* 17: every pixel is bad, one cluster */
  for (size_t i = 0; i < n; ++i)
    b.rgba[4 * i + 1] = 117;
  r = diff_ok(&a, &b, NULL);
  ck_assert(!r.passed && r.bad_pixels == (long)n);
  ck_assert(r.largest_cluster == (long)n && r.bad_fraction == 1.0);
  /* ... and equal again at tolerance 17 */
  sph_imgdiff_options o;
  sph_imgdiff_defaults(&o);
  o.channel_tolerance = 17;
  r = diff_ok(&a, &b, &o);
  ck_assert(r.passed && r.bad_pixels == 0);
  /* alpha is not compared */
  memset(b.rgba, 100, 4 * n);
  for (size_t i = 0; i < n; ++i)
    b.rgba[4 * i + 3] = 0;
  r = diff_ok(&a, &b, NULL);
  ck_assert(r.passed && r.bad_pixels == 0 && r.max_channel_diff == 0);
  sph_image_destroy(&a);
  sph_image_destroy(&b);
}
END_TEST

START_TEST(diff_errors) {
  sph_image a, b;
  sph_error err;
  sph_imgdiff_result r;
  ck_assert_int_eq(sph_test_scene(&a, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  ck_assert_int_eq(sph_test_scene(&b, 321, 240, 0, 0, 0, 0, &err), SPH_OK);
  sph_image d = {7, 7, NULL};
  ck_assert_int_eq(sph_image_diff(&a, &b, NULL, &r, &d, &err), SPH_ERR_ARG);
  ck_assert_msg(strstr(err.message, "320x240") &&
                    strstr(err.message, "321x240"),
                "message: %s", err.message);
  ck_assert(d.rgba == NULL && d.width == 0);
  sph_image_destroy(&b);
  ck_assert_int_eq(sph_test_scene(&b, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  sph_imgdiff_options o;
  sph_imgdiff_defaults(&o);
  o.shift = -1;
  ck_assert_int_eq(sph_image_diff(&a, &b, &o, &r, NULL, &err), SPH_ERR_RANGE);
  o.shift = SPH_IMGDIFF_MAX_SHIFT + 1;
  ck_assert_int_eq(sph_image_diff(&a, &b, &o, &r, NULL, &err), SPH_ERR_RANGE);
  o.shift = SPH_IMGDIFF_MAX_SHIFT;
  ck_assert_int_eq(sph_image_diff(&a, &b, &o, &r, NULL, &err), SPH_OK);
  sph_imgdiff_defaults(&o);
  o.channel_tolerance = 256;
  ck_assert_int_eq(sph_image_diff(&a, &b, &o, &r, NULL, &err), SPH_ERR_RANGE);
  sph_imgdiff_defaults(&o);
  o.max_bad_fraction = 1.5;
  ck_assert_int_eq(sph_image_diff(&a, &b, &o, &r, NULL, &err), SPH_ERR_RANGE);
  sph_imgdiff_defaults(&o);
  o.max_cluster = -1;
  ck_assert_int_eq(sph_image_diff(&a, &b, &o, &r, NULL, &err), SPH_ERR_RANGE);
  sph_image empty = {0, 0, NULL};
  ck_assert_int_eq(sph_image_diff(&a, &empty, NULL, &r, NULL, &err),
                   SPH_ERR_ARG);
  sph_image_destroy(&a);
  sph_image_destroy(&b);
}
END_TEST

START_TEST(png_round_trip) {
  make_tmpdir();
  sph_error err;
  sph_image a, back;
  char p1[128], p2[128];
  /* opaque: an RGB file (colour type 2, IHDR byte 25) */
  ck_assert_int_eq(sph_test_scene(&a, 320, 240, 0, 0, 0, 1, &err), SPH_OK);
  snprintf(p1, sizeof p1, "%s/a.png", tmpdir);
  snprintf(p2, sizeof p2, "%s/b.png", tmpdir);
  ck_assert_int_eq(sph_image_write_png(p1, &a, &err), SPH_OK);
  ck_assert_int_eq(sph_image_read_png(p1, &back, &err), SPH_OK);
  ck_assert(back.width == 320 && back.height == 240);
  ck_assert_int_eq(memcmp(a.rgba, back.rgba, (size_t)320 * 240 * 4), 0);
  sph_image_destroy(&back);
  unsigned char *f1, *f2;
  size_t n1 = slurp(p1, &f1);
  ck_assert_uint_gt(n1, 33);
  ck_assert_int_eq(f1[25], 2);
  ck_assert(memmem(f1, n1, "tIME", 4) == NULL);
  /* the same image again: the same bytes */
  ck_assert_int_eq(sph_image_write_png(p2, &a, &err), SPH_OK);
  size_t n2 = slurp(p2, &f2);
  ck_assert_uint_eq(n1, n2);
  ck_assert_int_eq(memcmp(f1, f2, n1), 0);
  free(f1);
  free(f2);
  /* varying alpha: an RGBA file (colour type 6), exact */
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 320; ++x)
      a.rgba[4 * ((size_t)y * 320 + x) + 3] = (unsigned char)((x + y) & 255);
  ck_assert_int_eq(sph_image_write_png(p1, &a, &err), SPH_OK);
  ck_assert_int_eq(sph_image_read_png(p1, &back, &err), SPH_OK);
  ck_assert_int_eq(memcmp(a.rgba, back.rgba, (size_t)320 * 240 * 4), 0);
  sph_image_destroy(&back);
  n1 = slurp(p1, &f1);
  ck_assert_int_eq(f1[25], 6);
  free(f1);
  /* a 1x1 image and an odd width */
  sph_image small;
  ck_assert_int_eq(sph_image_create(&small, 1, 1, &err), SPH_OK);
  sph_test_pixel(&small, 0, 0, 1, 2, 3, 255);
  ck_assert_int_eq(sph_image_write_png(p2, &small, &err), SPH_OK);
  ck_assert_int_eq(sph_image_read_png(p2, &back, &err), SPH_OK);
  ck_assert(back.width == 1 && back.height == 1);
  ck_assert_int_eq(memcmp(small.rgba, back.rgba, 4), 0);
  sph_image_destroy(&back);
  sph_image_destroy(&small);
  /* no temporary left behind; a write into a missing folder leaves nothing */
  char part[160], bad[160];
  snprintf(part, sizeof part, "%s.part", p1);
  ck_assert(!exists(part));
  snprintf(bad, sizeof bad, "%s/no/such/x.png", tmpdir);
  ck_assert_int_eq(sph_image_write_png(bad, &a, &err), SPH_ERR_IO);
  ck_assert_str_eq(err.file, bad);
  sph_image empty = {0, 0, NULL};
  ck_assert_int_eq(sph_image_write_png(p2, &empty, &err), SPH_ERR_ARG);
  sph_image_destroy(&a);
  remove_tmpdir();
}
END_TEST

/* Writes a PNG with libpng directly: `rows` hold packed samples of the given
 * colour type and bit depth (16-bit big-endian). */
static void write_raw_png(const char *path, int w, int h, int type, int depth,
                          int interlace, png_bytep *rows, png_colorp palette,
                          int npalette, png_bytep trans, int ntrans,
                          png_color_16p trans_colour) {
  FILE *f = fopen(path, "wb");
  ck_assert_ptr_nonnull(f);
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
  png_infop info = png_create_info_struct(png);
  ck_assert(png && info);
  if (setjmp(png_jmpbuf(png)))
    ck_abort_msg("libpng failed writing %s", path);
  png_init_io(png, f);
  png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, depth, type,
               interlace, PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  if (palette)
    png_set_PLTE(png, info, palette, npalette);
  if (trans || trans_colour)
    png_set_tRNS(png, info, trans, ntrans, trans_colour);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, NULL);
  png_destroy_write_struct(&png, &info);
  fclose(f);
}

START_TEST(png_colour_types) {
  make_tmpdir();
  sph_error err;
  sph_image img;
  char path[128];
  enum { W = 5, H = 3 };
  png_byte data[H][W * 8];
  png_bytep rows[H];
  for (int y = 0; y < H; ++y)
    rows[y] = data[y];
  long wrong = 0;
  /* 8-bit grey: v -> (v, v, v, 255) */
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      data[y][x] = (png_byte)(40 * x + 7 * y);
  snprintf(path, sizeof path, "%s/grey8.png", tmpdir);
  write_raw_png(path, W, H, PNG_COLOR_TYPE_GRAY, 8, PNG_INTERLACE_NONE, rows,
                NULL, 0, NULL, 0, NULL);
  ck_assert_int_eq(sph_image_read_png(path, &img, &err), SPH_OK);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const unsigned char *p = img.rgba + 4 * (y * W + x);
      int v = 40 * x + 7 * y;
      wrong += p[0] != v || p[1] != v || p[2] != v || p[3] != 255;
    }
  ck_assert_int_eq(wrong, 0);
  sph_image_destroy(&img);
  /* 16-bit grey with alpha: high bytes survive */
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      /* 0xNNNN is exactly NN in 8 bits */
      png_byte *s = &data[y][4 * x];
      s[0] = s[1] = (png_byte)(50 * x);
      s[2] = s[3] = (png_byte)(60 * y);
    }
  snprintf(path, sizeof path, "%s/greya16.png", tmpdir);
  write_raw_png(path, W, H, PNG_COLOR_TYPE_GRAY_ALPHA, 16, PNG_INTERLACE_NONE,
                rows, NULL, 0, NULL, 0, NULL);
  ck_assert_int_eq(sph_image_read_png(path, &img, &err), SPH_OK);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const unsigned char *p = img.rgba + 4 * (y * W + x);
      wrong += p[0] != 50 * x || p[2] != 50 * x || p[3] != 60 * y;
    }
  ck_assert_int_eq(wrong, 0);
  sph_image_destroy(&img);
  /* 16-bit RGB, interlaced */
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      png_byte *s = &data[y][6 * x];
      s[0] = (png_byte)(10 + x);
      s[1] = 0xff;
      s[2] = (png_byte)(20 + y);
      s[3] = 0;
      s[4] = 0xff;
      s[5] = 0xff;
    }
  snprintf(path, sizeof path, "%s/rgb16i.png", tmpdir);
  write_raw_png(path, W, H, PNG_COLOR_TYPE_RGB, 16, PNG_INTERLACE_ADAM7, rows,
                NULL, 0, NULL, 0, NULL);
  ck_assert_int_eq(sph_image_read_png(path, &img, &err), SPH_OK);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const unsigned char *p = img.rgba + 4 * (y * W + x);
      /* 0xNNff scales to NN + 1 (rounded), 0xNN00 to NN, 0xffff to 255 */
      wrong += p[0] != 11 + x || p[1] != 20 + y || p[2] != 255 || p[3] != 255;
    }
  ck_assert_msg(wrong == 0, "16-bit RGB: %ld wrong", wrong);
  sph_image_destroy(&img);
  /* 2-bit palette with a transparent entry */
  png_color pal[4] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {9, 9, 9}};
  png_byte trans[4] = {255, 128, 255, 0};
  for (int y = 0; y < H; ++y) {
    memset(data[y], 0, sizeof data[y]);
    for (int x = 0; x < W; ++x)
      data[y][x / 4] |= (png_byte)(((x + y) % 4) << (6 - 2 * (x % 4)));
  }
  snprintf(path, sizeof path, "%s/pal2.png", tmpdir);
  write_raw_png(path, W, H, PNG_COLOR_TYPE_PALETTE, 2, PNG_INTERLACE_NONE, rows,
                pal, 4, trans, 4, NULL);
  ck_assert_int_eq(sph_image_read_png(path, &img, &err), SPH_OK);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const unsigned char *p = img.rgba + 4 * (y * W + x);
      int k = (x + y) % 4;
      wrong += p[0] != pal[k].red || p[1] != pal[k].green ||
               p[2] != pal[k].blue || p[3] != trans[k];
    }
  ck_assert_int_eq(wrong, 0);
  sph_image_destroy(&img);
  /* 1-bit grey with a transparent colour (tRNS): 0 -> transparent black */
  for (int y = 0; y < H; ++y)
    data[y][0] = (png_byte)(y % 2 ? 0x50 : 0xa8); /* 01010 / 10101 */
  png_color_16 tc = {0, 0, 0, 0, 0};
  snprintf(path, sizeof path, "%s/grey1t.png", tmpdir);
  write_raw_png(path, W, H, PNG_COLOR_TYPE_GRAY, 1, PNG_INTERLACE_NONE, rows,
                NULL, 0, NULL, 0, &tc);
  ck_assert_int_eq(sph_image_read_png(path, &img, &err), SPH_OK);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const unsigned char *p = img.rgba + 4 * (y * W + x);
      int on = (x + y) % 2 == 0;
      int v = on ? 255 : 0;
      wrong += p[0] != v || p[1] != v || p[2] != v || p[3] != (on ? 255 : 0);
    }
  ck_assert_int_eq(wrong, 0);
  sph_image_destroy(&img);
  remove_tmpdir();
}
END_TEST

START_TEST(broken_files_refused) {
  make_tmpdir();
  sph_error err;
  sph_image a, img;
  char good[128], path[128];
  ck_assert_int_eq(sph_test_scene(&a, 320, 240, 0, 0, 0, 0, &err), SPH_OK);
  snprintf(good, sizeof good, "%s/good.png", tmpdir);
  ck_assert_int_eq(sph_image_write_png(good, &a, &err), SPH_OK);
  sph_image_destroy(&a);
  unsigned char *bytes;
  size_t n = slurp(good, &bytes);
  ck_assert_uint_gt(n, 100);
  /* missing */
  snprintf(path, sizeof path, "%s/missing.png", tmpdir);
  ck_assert_int_eq(sph_image_read_png(path, &img, &err), SPH_ERR_IO);
  ck_assert_str_eq(err.file, path);
  ck_assert(img.rgba == NULL && img.width == 0);
  /* a text file and an empty file */
  snprintf(path, sizeof path, "%s/notes.png", tmpdir);
  write_bytes(path, "just some text\n", 15);
  ck_assert_int_eq(sph_image_read_png(path, &img, &err), SPH_ERR_SYNTAX);
  ck_assert_str_eq(err.file, path);
  ck_assert_ptr_nonnull(strstr(err.message, "not a PNG"));
  write_bytes(path, "", 0);
  ck_assert_int_eq(sph_image_read_png(path, &img, &err), SPH_ERR_SYNTAX);
  ck_assert_str_eq(err.file, path);
  /* truncated inside the signature, IHDR, IDAT, and just before IEND ends */
  const size_t cuts[] = {4, 20, 60, n / 2, n - 1};
  snprintf(path, sizeof path, "%s/cut.png", tmpdir);
  for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; ++i) {
    write_bytes(path, bytes, cuts[i]);
    ck_assert_int_eq(sph_image_read_png(path, &img, &err), SPH_ERR_SYNTAX);
    ck_assert_str_eq(err.file, path);
    ck_assert_msg(strstr(err.message, "truncated"), "cut at %zu: %s", cuts[i],
                  err.message);
    ck_assert(img.rgba == NULL);
  }
  /* a flipped byte inside the image data: a CRC error */
  bytes[n / 2] ^= 0x55;
  snprintf(path, sizeof path, "%s/corrupt.png", tmpdir);
  write_bytes(path, bytes, n);
  ck_assert_int_eq(sph_image_read_png(path, &img, &err), SPH_ERR_SYNTAX);
  ck_assert_str_eq(err.file, path);
  ck_assert_ptr_nonnull(strstr(err.message, "corrupt"));
  /* a folder */
  ck_assert_int_eq(sph_image_read_png(tmpdir, &img, &err), SPH_ERR_IO);
  ck_assert_str_eq(err.file, tmpdir);
  /* the formatted error names the file */
  char msg[1200];
  sph_error_format(&err, msg, sizeof msg);
  ck_assert_ptr_nonnull(strstr(msg, tmpdir));
  free(bytes);
  remove_tmpdir();
}
END_TEST

START_TEST(speed_1280x720) {
  sph_error err;
  sph_image a, b, c;
  ck_assert_int_eq(sph_image_create(&a, 1280, 720, &err), SPH_OK);
  ck_assert_int_eq(sph_image_create(&b, 1280, 720, &err), SPH_OK);
  ck_assert_int_eq(sph_image_create(&c, 1280, 720, &err), SPH_OK);
  /* forty discs on a gradient, their one-pixel shift, and another colour
   * map on another background (every pixel bad: the slow path everywhere) */
  for (int k = 0; k < 3; ++k) {
    sph_image *img = k == 0 ? &a : k == 1 ? &b : &c;
    int dx = k == 1;
    for (int y = 0; y < 720; ++y)
      for (int x = 0; x < 1280; ++x)
        sph_test_pixel(img, x, y, k == 2 ? 200 : 30 + y / 12, 30 + y / 12,
                       38 + y / 12, 255);
    for (int i = 0; i < 40; ++i) {
      int cx = 60 + (i * 131) % 1160 + dx, cy = 60 + (i * 71) % 600;
      int r = 10 + (i * 17) % 50;
      int red = k == 2 ? 40 : 230, blue = k == 2 ? 230 : 40;
      sph_test_disc(img, cx, cy, r, red, 60 + 4 * i, blue);
    }
  }
  double t0 = seconds();
  sph_imgdiff_result r1 = diff_ok(&a, &a, NULL);
  double t1 = seconds();
  sph_imgdiff_result r2 = diff_ok(&a, &b, NULL);
  double t2 = seconds();
  sph_image d;
  sph_imgdiff_result r3;
  ck_assert_int_eq(sph_image_diff(&a, &c, NULL, &r3, &d, &err), SPH_OK);
  double t3 = seconds();
  printf("imgdiff 1280x720: identical %.3f s, shifted %.3f s, recoloured "
         "(%.0f %% bad, with diff image) %.3f s\n",
         t1 - t0, t2 - t1, 100.0 * r3.bad_fraction, t3 - t2);
  ck_assert(r1.passed && r2.passed && !r3.passed);
  ck_assert_int_eq(r2.bad_pixels, 0);
  /* generous: sanitizer builds run the same test */
  ck_assert_msg(t3 - t0 < 5.0, "too slow: %.3f s", t3 - t0);
  sph_image_destroy(&a);
  sph_image_destroy(&b);
  sph_image_destroy(&c);
  sph_image_destroy(&d);
}
END_TEST

int main(void) {
  Suite *s = suite_create("image");
  TCase *tc = tcase_create("image");
  tcase_set_timeout(tc, 60);
  tcase_add_test(tc, create_limits);
  tcase_add_test(tc, identical_images_pass);
  tcase_add_test(tc, one_odd_pixel);
  tcase_add_test(tc, shifted_scenes);
  tcase_add_test(tc, other_colour_map_fails);
  tcase_add_test(tc, missing_small_disc_fails_on_cluster);
  tcase_add_test(tc, both_directions_checked);
  tcase_add_test(tc, channel_tolerance);
  tcase_add_test(tc, diff_errors);
  tcase_add_test(tc, png_round_trip);
  tcase_add_test(tc, png_colour_types);
  tcase_add_test(tc, broken_files_refused);
  tcase_add_test(tc, speed_1280x720);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
