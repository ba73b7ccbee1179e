/* Overlay: colour map end points and lightness, nice ticks and their labels,
 * FreeType text (width, ink box, clipping, repeatability, missing fonts),
 * the colour bar's end colours, tick-label alignment and extent, and a composed
 * demo frame written as PPM to the build directory (overlay_demo.ppm, with the
 * viridis test bar in overlay_colorbar_viridis.ppm). */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "overlay_impl.h"

static const unsigned char black[3] = {0, 0, 0};

/* CIELAB lightness of an 8-bit sRGB colour */
static double lightness(const unsigned char c[3]) {
  double lin[3];
  for (int i = 0; i < 3; ++i) {
    double v = c[i] / 255.0;
    lin[i] = v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
  }
  double y = 0.2126729 * lin[0] + 0.7151522 * lin[1] + 0.0721750 * lin[2];
  return y > 216.0 / 24389.0 ? 116.0 * cbrt(y) - 16.0 : y * 24389.0 / 27.0;
}

static int near_rgb(const unsigned char *a, int r, int g, int b, int tol) {
  return abs(a[0] - r) <= tol && abs(a[1] - g) <= tol && abs(a[2] - b) <= tol;
}

static sph_image image_new(int w, int h, unsigned char grey) {
  sph_image img = {w, h, malloc((size_t)4 * w * h)};
  for (int i = 0; i < w * h; ++i) {
    memset(img.rgba + 4 * i, grey, 3);
    img.rgba[4 * i + 3] = 255;
  }
  return img;
}

static const unsigned char *pixel(const sph_image *img, int x, int y) {
  return img->rgba + 4 * ((size_t)y * img->width + x);
}

static sph_text *open_font(void) {
  sph_text *t = NULL;
  sph_error err;
  ck_assert_int_eq(sph_text_create(NULL, &t, &err), SPH_OK);
  return t;
}

/* Writes the image as binary PPM (alpha dropped) for a reviewer to view. */
static void write_ppm(const sph_image *img, const char *name) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", SPH_BINARY_DIR, name);
  FILE *f = fopen(path, "wb");
  ck_assert_ptr_nonnull(f);
  fprintf(f, "P6\n%d %d\n255\n", img->width, img->height);
  for (int i = 0; i < img->width * img->height; ++i)
    fwrite(img->rgba + 4 * i, 1, 3, f);
  ck_assert_int_eq(fclose(f), 0);
}

START_TEST(colormap_end_points) {
  sph_test_enable_fp_traps();
  unsigned char c[3];
  sph_colormap_eval(SPH_CMAP_COOL_WARM, 0.0, c);
  ck_assert(near_rgb(c, 59, 76, 192, 0));
  sph_colormap_eval(SPH_CMAP_COOL_WARM, 1.0, c);
  ck_assert(near_rgb(c, 180, 4, 38, 0));
  sph_colormap_eval(SPH_CMAP_COOL_WARM, 0.5, c);
  ck_assert_msg(near_rgb(c, 221, 221, 221, 1), "mid %d %d %d", c[0], c[1],
                c[2]);
  /* viridis: (68, 1, 84), (33, 145, 140) half way, (253, 231, 37) */
  sph_colormap_eval(SPH_CMAP_VIRIDIS, 0.0, c);
  ck_assert(near_rgb(c, 68, 1, 84, 0));
  sph_colormap_eval(SPH_CMAP_VIRIDIS, 0.5, c);
  ck_assert_msg(near_rgb(c, 33, 145, 140, 1), "mid %d %d %d", c[0], c[1], c[2]);
  sph_colormap_eval(SPH_CMAP_VIRIDIS, 1.0, c);
  ck_assert(near_rgb(c, 253, 231, 37, 0));
  /* out of range clamps, NaN has its own colour */
  unsigned char d[3];
  sph_colormap_eval(SPH_CMAP_VIRIDIS, -3.0, c);
  sph_colormap_eval(SPH_CMAP_VIRIDIS, 0.0, d);
  ck_assert_mem_eq(c, d, 3);
  sph_colormap_eval(SPH_CMAP_COOL_WARM, INFINITY, c);
  sph_colormap_eval(SPH_CMAP_COOL_WARM, 1.0, d);
  ck_assert_mem_eq(c, d, 3);
  for (int k = 0; k < 2; ++k) {
    sph_colormap_eval((sph_colormap_kind)k, NAN, c);
    sph_colormap_nan((sph_colormap_kind)k, d);
    ck_assert_mem_eq(c, d, 3);
  }
  /* the table is the evaluation at i / (n - 1) */
  unsigned char table[3 * 17];
  sph_colormap_table(SPH_CMAP_COOL_WARM, 17, table);
  sph_colormap_eval(SPH_CMAP_COOL_WARM, 5.0 / 16.0, c);
  ck_assert_mem_eq(table + 15, c, 3);
}
END_TEST

START_TEST(colormap_lightness) {
  sph_test_enable_fp_traps();
  /* viridis: lightness rises strictly; cool-warm: rises to the white middle
   * and falls after it */
  enum { N = 64 };
  unsigned char c[3];
  int viridis_ok = 1, cw_ok = 1;
  double prev_v = -1.0, prev_c = -1.0;
  for (int i = 0; i <= N; ++i) {
    double t = (double)i / N;
    sph_colormap_eval(SPH_CMAP_VIRIDIS, t, c);
    double lv = lightness(c);
    viridis_ok &= lv > prev_v;
    prev_v = lv;
    sph_colormap_eval(SPH_CMAP_COOL_WARM, t, c);
    double lc = lightness(c);
    if (i > 0)
      cw_ok &= i <= N / 2 ? lc > prev_c : lc < prev_c;
    prev_c = lc;
  }
  ck_assert(viridis_ok);
  ck_assert(cw_ok);
}
END_TEST

/* ticks and labels of [min, max] equal the expected lists */
static void expect_ticks(double min, double max, int max_ticks, int n,
                         const double *want, const char *const *labels) {
  double t[16];
  char l[16][SPH_TICK_LABEL_MAX];
  int got = sph_colorbar_ticks(min, max, max_ticks, t);
  ck_assert_msg(got == n, "[%g, %g]: %d ticks, want %d", min, max, got, n);
  sph_colorbar_labels(t, got, l);
  for (int i = 0; i < n; ++i) {
    ck_assert_msg(fabs(t[i] - want[i]) <= 1e-12 * fabs(want[i]) + 1e-300,
                  "[%g, %g] tick %d: %.17g", min, max, i, t[i]);
    ck_assert_str_eq(l[i], labels[i]);
  }
}

START_TEST(tick_cases) {
  sph_test_enable_fp_traps();
  expect_ticks(0.0, 1.0, 6, 6, (double[]){0, 0.2, 0.4, 0.6, 0.8, 1.0},
               (const char *[]){"0.0", "0.2", "0.4", "0.6", "0.8", "1.0"});
  expect_ticks(-3e6, 7.5e6, 6, 5, (double[]){-2e6, 0, 2e6, 4e6, 6e6},
               (const char *[]){"-2e6", "0", "2e6", "4e6", "6e6"});
  expect_ticks(7.5e6, -3e6, 6, 5, (double[]){-2e6, 0, 2e6, 4e6, 6e6},
               (const char *[]){"-2e6", "0", "2e6", "4e6", "6e6"});
  /* engineering form: mantissas 1 to 999, never "0.5e5" */
  expect_ticks(1e4, 4.3e5, 5, 4, (double[]){1e5, 2e5, 3e5, 4e5},
               (const char *[]){"100e3", "200e3", "300e3", "400e3"});
  expect_ticks(0.0, 100.0, 5, 3, (double[]){0, 50, 100},
               (const char *[]){"0", "50", "100"});
  expect_ticks(-0.013, 0.0042, 5, 3, (double[]){-0.01, -0.005, 0},
               (const char *[]){"-0.010", "-0.005", "0.000"});
}
END_TEST

START_TEST(bar_end_labels) {
  /* the range's ends, three significant digits of the span, the ticks'
   * scheme */
  char l[SPH_TICK_LABEL_MAX];
  sph_colorbar_end_label(4.29e5, 1.34e4, 4.29e5, l);
  ck_assert_str_eq(l, "429e3");
  sph_colorbar_end_label(1.34e4, 1.34e4, 4.29e5, l);
  ck_assert_str_eq(l, "13e3");
  sph_colorbar_end_label(-3.2945e6, -3.2945e6, 3.2945e6, l);
  ck_assert_str_eq(l, "-3.29e6");
  sph_colorbar_end_label(0.8512, 0.8512, 1.1488, l);
  ck_assert_str_eq(l, "0.851");
  sph_colorbar_end_label(0.0, 0.0, 2.0, l);
  ck_assert_str_eq(l, "0");
  /* a span that overflows (issue 36: a signed overflow under UBSan) */
  sph_colorbar_end_label(1e308, -1e308, 1e308, l);
  ck_assert_str_eq(l, "100e306");
  sph_colorbar_end_label(-1e308, -1e308, 1e308, l);
  ck_assert_str_eq(l, "-100e306");
}
END_TEST

START_TEST(tick_tiny_and_degenerate) {
  sph_test_enable_fp_traps();
  /* tiny magnitudes take the exponent form */
  expect_ticks(
      1e-9, 3e-9, 5, 5, (double[]){1e-9, 1.5e-9, 2e-9, 2.5e-9, 3e-9},
      (const char *[]){"1.0e-9", "1.5e-9", "2.0e-9", "2.5e-9", "3.0e-9"});
  /* a narrow range around 1: enough decimals to tell the ticks apart */
  expect_ticks(
      1.0, 1.000001, 6, 6,
      (double[]){1.0, 1.0000002, 1.0000004, 1.0000006, 1.0000008, 1.000001},
      (const char *[]){"1.0000000", "1.0000002", "1.0000004", "1.0000006",
                       "1.0000008", "1.0000010"});
  /* a point, zero, and a range below label resolution give one tick */
  expect_ticks(5.0, 5.0, 6, 1, (double[]){5.0}, (const char *[]){"5.000"});
  expect_ticks(0.0, 0.0, 6, 1, (double[]){0.0}, (const char *[]){"0"});
  expect_ticks(2.5e5, 2.5e5, 6, 1, (double[]){2.5e5},
               (const char *[]){"250.0e3"});
  double t[8];
  ck_assert_int_eq(sph_colorbar_ticks(1.0, 1.0 + 1e-15, 6, t), 1);
  ck_assert_int_eq(sph_colorbar_ticks(0.0, 1.0, 0, t), 0);
  /* one tick allowed: a nice value inside */
  ck_assert_int_eq(sph_colorbar_ticks(0.11, 0.14, 1, t), 1);
  ck_assert(t[0] >= 0.11 && t[0] <= 0.14);
}
END_TEST

START_TEST(tick_properties) {
  /* many ranges: inside, ascending, evenly spaced nice steps, within the
   * limit, and at least two when five are allowed */
  static const double ranges[][2] = {
      {0.0, 1.0},       {-1.0, 1.0},     {0.013, 0.0171}, {-7e-4, 3e-3},
      {12.0, 987.0},    {1e5, 1.3e5},    {-2e9, -1e9},    {3.3, 3.31},
      {-1e-6, 1e-6},    {0.5, 4.5},      {6.0, 14.0},     {2.0, 6.0},
      {273.15, 373.15}, {1e300, 1.5e300}};
  int bad = 0;
  char why[256] = "";
  for (size_t r = 0; r < sizeof ranges / sizeof ranges[0]; ++r)
    for (int n = 1; n <= 12; ++n) {
      double t[12], lo = ranges[r][0], hi = ranges[r][1];
      int m = sph_colorbar_ticks(lo, hi, n, t);
      int ok = m >= 1 && m <= n && (n < 5 || m >= 2);
      double span = hi - lo, eps = 1e-9 * span;
      for (int i = 0; i < m; ++i)
        ok &= t[i] >= lo - eps && t[i] <= hi + eps;
      if (m >= 2) {
        double s = t[1] - t[0];
        double mant = s / pow(10.0, floor(log10(s) + 1e-9));
        ok &= fabs(mant - 1.0) < 1e-6 || fabs(mant - 2.0) < 1e-6 ||
              fabs(mant - 5.0) < 1e-6;
        for (int i = 1; i < m; ++i)
          ok &= fabs(t[i] - t[i - 1] - s) <= 1e-9 * s;
      }
      if (!ok && !bad)
        snprintf(why, sizeof why, "[%g, %g] with %d: %d ticks", lo, hi, n, m);
      bad |= !ok;
    }
  ck_assert_msg(!bad, "%s", why);
}
END_TEST

START_TEST(text_width) {
  sph_text *t = open_font();
  ck_assert_int_eq(sph_text_width(t, 16, ""), 0);
  const char *s = "twisting_column";
  int prev = 0;
  char buf[32];
  for (size_t n = 1; n <= strlen(s); ++n) {
    snprintf(buf, sizeof buf, "%.*s", (int)n, s);
    int w = sph_text_width(t, 16, buf);
    ck_assert_msg(w > prev, "%s: %d after %d", buf, w, prev);
    prev = w;
  }
  ck_assert_int_gt(sph_text_width(t, 32, s), sph_text_width(t, 16, s));
  /* about half an em per character in DejaVu Sans */
  ck_assert(prev > 5 * 15 && prev < 12 * 15);
  /* control characters take no room; bad UTF-8 is one replacement glyph */
  ck_assert_int_eq(sph_text_width(t, 16, "ab\tc"),
                   sph_text_width(t, 16, "abc"));
  ck_assert_int_eq(sph_text_width(t, 16, "\xff"),
                   sph_text_width(t, 16, "\xef\xbf\xbd"));
  int asc, desc;
  sph_text_metrics(t, 16, &asc, &desc);
  ck_assert(asc >= 14 && asc <= 17 && desc >= 3 && desc <= 5);
  sph_text_destroy(t);
}
END_TEST

START_TEST(text_draw_box) {
  sph_text *t = open_font();
  enum { W = 240, H = 60, X = 10, Y = 40, PX = 16 };
  sph_image img = image_new(W, H, 255);
  const char *s = "Hello, SPH 1.5e6 [Pa]";
  sph_text_draw(t, &img, X, Y, PX, s, black);
  int w = sph_text_width(t, PX, s), asc, desc, box[4];
  sph_text_metrics(t, PX, &asc, &desc);
  sph_text_bounds(t, PX, s, box);
  /* changed pixels: inside the ink box, the advance box and the line box */
  int changed = 0, full = 0, x0 = W, y0 = H, x1 = -1, y1 = -1;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const unsigned char *p = pixel(&img, x, y);
      if (p[0] == 255 && p[1] == 255 && p[2] == 255)
        continue;
      changed++;
      full += p[0] == 0;
      x0 = x < x0 ? x : x0, y0 = y < y0 ? y : y0;
      x1 = x > x1 ? x : x1, y1 = y > y1 ? y : y1;
    }
  ck_assert_int_gt(changed, 200);
  ck_assert_int_gt(full, 60); /* hinted stems reach full coverage */
  ck_assert(x0 >= X + box[0] && x1 < X + box[2]);
  ck_assert(y0 >= Y + box[1] && y1 < Y + box[3]);
  ck_assert(x0 >= X && x1 <= X + w);
  ck_assert(y0 >= Y - asc && y1 < Y + desc);
  /* the ink box is tight to within a pixel */
  ck_assert(x0 <= X + box[0] + 1 && x1 >= X + box[2] - 2);
  ck_assert(y0 <= Y + box[1] + 1 && y1 >= Y + box[3] - 2);
  /* alpha stays opaque */
  int alpha_ok = 1;
  for (int i = 0; i < W * H; ++i)
    alpha_ok &= img.rgba[4 * i + 3] == 255;
  ck_assert(alpha_ok);
  free(img.rgba);
  sph_text_destroy(t);
}
END_TEST

START_TEST(text_clipped) {
  /* text hanging over every edge writes nothing outside the buffer */
  sph_text *t = open_font();
  enum { W = 50, H = 20 };
  sph_image img = {W, H, malloc(4 * W * H + 64)};
  memset(img.rgba, 255, 4 * W * H);
  memset(img.rgba + 4 * W * H, 0xA5, 64);
  sph_text_draw(t, &img, -7, 5, 24, "Wgy_|", black);
  sph_text_draw(t, &img, 30, 25, 24, "Wgy_|", black);
  sph_text_draw(t, &img, -1000, -1000, 24, "far away", black);
  sph_text_draw(t, &img, 0, 14, 16, "x\xe2\x82", black); /* cut UTF-8 */
  int guard = 1;
  for (int i = 0; i < 64; ++i)
    guard &= img.rgba[4 * W * H + i] == 0xA5;
  ck_assert(guard);
  int changed = 0;
  for (int i = 0; i < 4 * W * H; ++i)
    changed += img.rgba[i] != 255;
  ck_assert_int_gt(changed, 0);
  free(img.rgba);
  sph_text_destroy(t);
}
END_TEST

START_TEST(text_repeatable) {
  /* two text objects at once, sizes switched in between: identical bytes */
  sph_text *a = open_font(), *b = open_font();
  sph_image i1 = image_new(200, 40, 230), i2 = image_new(200, 40, 230);
  static const unsigned char red[3] = {200, 30, 20};
  sph_text_draw(a, &i1, 3, 28, 18, "t = 0.0250 s  \xc2\xb5m", red);
  sph_text_width(b, 40, "other size");
  sph_text_draw(b, &i2, 3, 28, 18, "t = 0.0250 s  \xc2\xb5m", red);
  ck_assert_mem_eq(i1.rgba, i2.rgba, 4 * 200 * 40);
  sph_text_draw(a, &i1, 3, 28, 18, "again", red);
  sph_text_width(a, 9, "x");
  sph_text_draw(a, &i2, 3, 28, 18, "again", red);
  ck_assert_mem_eq(i1.rgba, i2.rgba, 4 * 200 * 40);
  free(i1.rgba);
  free(i2.rgba);
  sph_text_destroy(a);
  sph_text_destroy(b);
}
END_TEST

START_TEST(font_missing) {
  sph_text *t = (sph_text *)1;
  sph_error err;
  const char *path = "/nonexistent/fonts/NoSuchFont.ttf";
  ck_assert_int_eq(sph_text_create(path, &t, &err), SPH_ERR_IO);
  ck_assert_ptr_null(t);
  ck_assert_str_eq(err.file, path);
  ck_assert_ptr_nonnull(strstr(err.message, path));
  ck_assert_int_eq(sph_text_create(SPH_SOURCE_DIR "/CMakeLists.txt", &t, &err),
                   SPH_ERR_IO);
  ck_assert_ptr_nonnull(strstr(err.message, "not a font"));
}
END_TEST

/* Draws a bar into a 300 x 400 image and checks end colours, outline,
 * triangles and that every label is centred on its tick. */
static void check_bar(sph_colormap_kind map, double lo, double hi,
                      const char *ppm) {
  sph_text *t = open_font();
  sph_image img = image_new(300, 400, 255);
  sph_colorbar cb = {.map = map,
                     .min = lo,
                     .max = hi,
                     .title = "pressure [Pa]",
                     .clamped_low = 1,
                     .clamped_high = 1,
                     .x = 220,
                     .y = 70,
                     .width = 18,
                     .height = 280};
  sph_colorbar_draw(&img, t, &cb);
  unsigned char top[3], bottom[3], mid[3];
  sph_colormap_eval(map, 1.0, top);
  sph_colormap_eval(map, 0.0, bottom);
  int cx = cb.x + cb.width / 2;
  ck_assert_mem_eq(pixel(&img, cx, cb.y), top, 3);
  ck_assert_mem_eq(pixel(&img, cb.x, cb.y), top, 3);
  ck_assert_mem_eq(pixel(&img, cx, cb.y + cb.height - 1), bottom, 3);
  sph_colormap_eval(map, 0.5, mid);
  const unsigned char *m = pixel(&img, cx, cb.y + cb.height / 2);
  ck_assert(near_rgb(m, mid[0], mid[1], mid[2], 3));
  /* outline outside the rectangle; triangles filled with the end colours */
  ck_assert_mem_eq(pixel(&img, cb.x - 1, cb.y + 100), black, 3);
  ck_assert_mem_eq(pixel(&img, cb.x + cb.width, cb.y + 100), black, 3);
  ck_assert_mem_eq(pixel(&img, cx, cb.y - 5), top, 3);
  ck_assert_mem_eq(pixel(&img, cx, cb.y + cb.height + 4), bottom, 3);
  /* tick rows in the column just right of the outline */
  int tick_rows[16], nt = 0;
  for (int y = cb.y; y < cb.y + cb.height && nt < 16; ++y)
    if (pixel(&img, cb.x + cb.width + 2, y)[0] == 0)
      tick_rows[nt++] = y;
  double ticks[16];
  int want = sph_colorbar_ticks(lo, hi, 11, ticks);
  ck_assert_int_ge(nt, 3);
  ck_assert_int_le(nt, want);
  ck_assert(tick_rows[0] >= cb.y && tick_rows[nt - 1] < cb.y + cb.height);
  /* each label's ink centred on its tick within a pixel */
  int lx0 = cb.x + cb.width + 6, worst = 0;
  for (int i = 0; i < nt; ++i) {
    int r = tick_rows[i], top_ink = -1, bot_ink = -1;
    for (int y = r - 12; y <= r + 12; ++y)
      for (int x = lx0; x < img.width; ++x)
        if (pixel(&img, x, y)[0] < 128) {
          top_ink = top_ink < 0 ? y : top_ink;
          bot_ink = y;
          break;
        }
    int off = top_ink < 0 ? 99 : abs(top_ink + bot_ink + 1 - 2 * r - 1);
    worst = off > worst ? off : worst;
  }
  ck_assert_msg(worst <= 2, "label off its tick by %d half-pixels", worst);
  /* the title sits above the upper triangle, inside the image */
  int title_ink = 0;
  for (int y = 0; y < cb.y - 18; ++y)
    for (int x = 0; x < img.width; ++x)
      title_ink += pixel(&img, x, y)[0] < 128;
  ck_assert_int_gt(title_ink, 50);
  /* drawn again: the same bytes */
  sph_image again = image_new(300, 400, 255);
  sph_colorbar_draw(&again, t, &cb);
  ck_assert_mem_eq(img.rgba, again.rgba, 4 * 300 * 400);
  if (ppm)
    write_ppm(&img, ppm);
  free(again.rgba);
  free(img.rgba);
  sph_text_destroy(t);
}

START_TEST(colorbar_ends) {
  check_bar(SPH_CMAP_COOL_WARM, -3e6, 7.5e6, NULL);
  check_bar(SPH_CMAP_VIRIDIS, 0.0, 1.0, "overlay_colorbar_viridis.ppm");
}
END_TEST

START_TEST(colorbar_extent) {
  /* the ink of a bar placed by its extent ends inside the image, at most a
   * few pixels short of the extent (glyph side bearings) */
  sph_text *t = open_font();
  sph_image img = image_new(320, 240, 255);
  sph_colorbar cb = {.map = SPH_CMAP_COOL_WARM,
                     .min = -4.3e6,
                     .max = 4.3e6,
                     .y = 48,
                     .width = 8,
                     .height = 144};
  int ext = sph_colorbar_extent(&img, t, &cb);
  ck_assert_int_gt(ext, cb.width + 20);
  cb.x = img.width - 5 - ext;
  sph_colorbar_draw(&img, t, &cb);
  int right = -1;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (!near_rgb(pixel(&img, x, y), 255, 255, 255, 0))
        right = x > right ? x : right;
  ck_assert_msg(right < cb.x + ext && right >= cb.x + ext - 4 &&
                    right < img.width - 4,
                "ink ends at %d, bar %d + extent %d", right, cb.x, ext);
  free(img.rgba);
  sph_text_destroy(t);
}
END_TEST

START_TEST(demo_frame) {
  /* a stand-in for a rendered frame: a shaded "column" coloured by a
   * pressure-like field, with the colour bar and the label block on top */
  enum { W = 640, H = 400 };
  sph_text *t = open_font();
  sph_image img = image_new(W, H, 0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      unsigned char *p = img.rgba + 4 * (y * W + x);
      memset(p, 250 - 40 * y / H, 3);
    }
  double lo = -3e6, hi = 7.5e6;
  for (int y = 60; y < 360; ++y)
    for (int x = 150; x < 390; ++x) {
      double u = (x - 270) / 120.0, v = (y - 210) / 150.0;
      double p = 9e6 * u * v + 2e6 * sin(6.0 * v + 3.0 * u) + 1.5e6;
      unsigned char c[3];
      sph_colormap_eval(SPH_CMAP_COOL_WARM, (p - lo) / (hi - lo), c);
      double shade = 0.75 + 0.25 * (1.0 - u * u);
      unsigned char *q = img.rgba + 4 * (y * W + x);
      for (int k = 0; k < 3; ++k)
        q[k] = (unsigned char)(c[k] * shade + 0.5);
    }
  sph_colorbar cb = {.map = SPH_CMAP_COOL_WARM,
                     .min = lo,
                     .max = hi,
                     .title = "pressure [Pa]",
                     .clamped_low = 1,
                     .clamped_high = 1,
                     .x = 560,
                     .y = 80,
                     .width = 18,
                     .height = 270};
  sph_colorbar_draw(&img, t, &cb);
  sph_overlay_label(&img, t, 8, 8,
                    "twisting_column   pressure   t = 0.0250 s\n"
                    "tl-jst, 4096 particles");
  /* the label box is translucent white: lighter than the background */
  ck_assert_int_gt(pixel(&img, 9, 9)[0], pixel(&img, 9, 100)[0]);
  write_ppm(&img, "overlay_demo.ppm");
  free(img.rgba);
  sph_text_destroy(t);
}
END_TEST

int main(void) {
  Suite *s = suite_create("overlay");
  TCase *tc = tcase_create("overlay");
  tcase_set_timeout(tc, 60);
  tcase_add_test(tc, colormap_end_points);
  tcase_add_test(tc, colormap_lightness);
  tcase_add_test(tc, tick_cases);
  tcase_add_test(tc, tick_tiny_and_degenerate);
  tcase_add_test(tc, bar_end_labels);
  tcase_add_test(tc, tick_properties);
  tcase_add_test(tc, text_width);
  tcase_add_test(tc, text_draw_box);
  tcase_add_test(tc, text_clipped);
  tcase_add_test(tc, text_repeatable);
  tcase_add_test(tc, font_missing);
  tcase_add_test(tc, colorbar_ends);
  tcase_add_test(tc, colorbar_extent);
  tcase_add_test(tc, demo_frame);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
