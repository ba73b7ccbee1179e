/* OSMesa sphere renderer: disc size and shading of one sphere (ortho and
 * perspective, also 400 px wide), top-first rows, depth-correct occlusion in
 * either draw order, layers painted over one another (flat colours), the
 * clip plane, byte-identical repeat frames, the camera fit, argument errors
 * and the refused swrast driver; writes gl_demo_lattice.ppm to the build
 * directory. */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_impl.h"

static const double deg = 3.14159265358979323846 / 180.0;

/* An image of the given size with its own pixel buffer. */
static sph_image image_new(int w, int h) {
  sph_image img = {w, h, calloc((size_t)w * h * 4, 1)};
  ck_assert_ptr_nonnull(img.rgba);
  return img;
}

static const unsigned char *px(const sph_image *img, int x, int y) {
  return img->rgba + ((size_t)y * img->width + x) * 4;
}

static int is_background(const unsigned char *p) {
  return p[0] == SPH_GL_BACKGROUND && p[1] == SPH_GL_BACKGROUND &&
         p[2] == SPH_GL_BACKGROUND && p[3] == 255;
}

static int luminance(const unsigned char *p) { return p[0] + p[1] + p[2]; }

/* Camera on +Z looking at the origin, +Y up. */
static sph_view front_view(int ortho, double height_or_fov, double dist) {
  sph_view v = {{0, 0, dist}, {0, 0, 0}, {0, 1, 0}, 40.0,
                ortho,        2.0,       0.1,       100.0};
  if (ortho)
    v.ortho_height = height_or_fov;
  else
    v.fovy_deg = height_or_fov;
  return v;
}

static sph_gl *context(int w, int h) {
  sph_gl *gl = NULL;
  sph_error err;
  sph_status st = sph_gl_create(w, h, &gl, &err);
  ck_assert_msg(st == SPH_OK, "sph_gl_create: %s", err.message);
  return gl;
}

static void draw(sph_gl *gl, const sph_view *v, size_t n, const float *xyz,
                 float r, const unsigned char *rgb, const double *plane,
                 sph_image *img) {
  sph_error err;
  sph_status st = sph_gl_draw_spheres(gl, v, n, xyz, r, rgb, plane, img, &err);
  ck_assert_msg(st == SPH_OK, "sph_gl_draw_spheres: %s", err.message);
}

/* Checks that the pixels of img inside radius rad - 1 around (cx, cy) are
 * sphere, those beyond rad + 1 background, and every alpha is 255 (counted
 * first: Check records every passing assertion). */
static void check_disc(const sph_image *img, double cx, double cy, double rad) {
  int inside = 0, holes = 0, strays = 0, alpha = 0, hx = -1, hy = -1;
  for (int y = 0; y < img->height; ++y)
    for (int x = 0; x < img->width; ++x) {
      const unsigned char *p = px(img, x, y);
      double rho = hypot(x + 0.5 - cx, y + 0.5 - cy);
      alpha += p[3] != 255;
      if (rho < rad - 1.0) {
        inside++;
        if (is_background(p))
          holes++, hx = x, hy = y;
      } else if (rho > rad + 1.0 && !is_background(p)) {
        strays++, hx = x, hy = y;
      }
    }
  ck_assert_msg(inside > 0 && holes == 0 && strays == 0 && alpha == 0,
                "disc r %g at %g,%g: %d holes, %d strays (last %d,%d), %d "
                "alpha",
                rad, cx, cy, holes, strays, hx, hy, alpha);
}

/* The brightest pixel at radius in [rad - 3, rad - 1] around (cx, cy). */
static int rim_max(const sph_image *img, double cx, double cy, double rad) {
  int best = 0;
  for (int y = 0; y < img->height; ++y)
    for (int x = 0; x < img->width; ++x) {
      double rho = hypot(x + 0.5 - cx, y + 0.5 - cy);
      if (rho >= rad - 3.0 && rho <= rad - 1.0) {
        int l = luminance(px(img, x, y));
        best = l > best ? l : best;
      }
    }
  return best;
}

START_TEST(one_sphere_ortho) {
  /* 200 px show 2 world units: radius 0.5 is 50 px */
  sph_gl *gl = context(200, 200);
  sph_image img = image_new(200, 200);
  sph_view v = front_view(1, 2.0, 5.0);
  const float c[3] = {0, 0, 0};
  const unsigned char col[3] = {200, 60, 40};
  draw(gl, &v, 1, c, 0.5f, col, NULL, &img);
  check_disc(&img, 100.0, 100.0, 50.0);
  /* lit: centre brighter than the rim, and of the sphere's hue */
  const unsigned char *mid = px(&img, 100, 100);
  ck_assert_int_gt(luminance(mid), rim_max(&img, 100.0, 100.0, 50.0) + 60);
  ck_assert(mid[0] > mid[1] + 60 && mid[0] > mid[2] + 60);
  /* rows are top first: a sphere at +x, +y lands top right */
  const float c2[3] = {0.5f, 0.5f, 0.0f};
  draw(gl, &v, 1, c2, 0.2f, col, NULL, &img);
  check_disc(&img, 150.0, 50.0, 20.0);
  sph_gl_destroy(gl);
  free(img.rgba);
}
END_TEST

START_TEST(radius_factor_per_sphere) {
  /* radius 0.25 with factor 2 (ortho, 100 px per unit) draws the 50 px
   * disc of radius 0.5; factor 1 the 25 px one */
  sph_gl *gl = context(200, 200);
  sph_image img = image_new(200, 200);
  sph_view v = front_view(1, 2.0, 5.0);
  const float c[3] = {0, 0, 0}, c2[3] = {0.5f, 0.5f, 0.0f};
  const unsigned char col[3] = {200, 60, 40};
  const float two = 2.0f, one = 1.0f;
  sph_gl_layer l = {1, c, 0.25f, col, NULL, 0, &two, NULL};
  sph_error err;
  ck_assert_int_eq(sph_gl_draw_layers(gl, &v, &l, 1, &img, &err), SPH_OK);
  check_disc(&img, 100.0, 100.0, 50.0);
  l.xyz = c2;
  l.scale = &one;
  ck_assert_int_eq(sph_gl_draw_layers(gl, &v, &l, 1, &img, &err), SPH_OK);
  check_disc(&img, 150.0, 50.0, 25.0);
  /* a factor that is not positive is refused */
  const float zero = 0.0f;
  l.scale = &zero;
  ck_assert_int_eq(sph_gl_draw_layers(gl, &v, &l, 1, &img, &err), SPH_ERR_ARG);
  sph_gl_destroy(gl);
  free(img.rgba);
}
END_TEST

START_TEST(one_sphere_perspective) {
  /* silhouette radius of a sphere on the axis: h/2 tan(asin(r/d)) / tan(fov/2)
   */
  sph_gl *gl = context(300, 240);
  sph_image img = image_new(300, 240);
  sph_view v = front_view(0, 40.0, 5.0);
  const float c[3] = {0, 0, 0};
  const unsigned char col[3] = {40, 90, 220};
  draw(gl, &v, 1, c, 0.5f, col, NULL, &img);
  double a = asin(0.5 / 5.0);
  double rad = 120.0 * tan(a) / tan(20.0 * deg);
  check_disc(&img, 150.0, 120.0, rad);
  ck_assert_int_gt(luminance(px(&img, 150, 120)),
                   rim_max(&img, 150.0, 120.0, rad) + 20);
  sph_gl_destroy(gl);
  free(img.rgba);
}
END_TEST

START_TEST(large_sphere) {
  /* 400 px radius, beyond the 255 px point-sprite limit */
  sph_gl *gl = context(1000, 1000);
  sph_image img = image_new(1000, 1000);
  sph_view v = front_view(1, 2.5, 5.0);
  const float c[3] = {0, 0, 0};
  const unsigned char col[3] = {90, 200, 90};
  draw(gl, &v, 1, c, 1.0f, col, NULL, &img);
  check_disc(&img, 500.0, 500.0, 400.0);
  ck_assert_int_gt(luminance(px(&img, 500, 500)),
                   rim_max(&img, 500.0, 500.0, 400.0) + 60);
  /* the same in perspective: 378 px */
  v = front_view(0, 60.0, 2.5);
  draw(gl, &v, 1, c, 1.0f, col, NULL, &img);
  double rad = 500.0 * tan(asin(1.0 / 2.5)) / tan(30.0 * deg);
  ck_assert(rad > 370.0);
  check_disc(&img, 500.0, 500.0, rad);
  sph_gl_destroy(gl);
  free(img.rgba);
}
END_TEST

START_TEST(occlusion_any_order) {
  /* red at z = 0, blue nearer the eye at z = 0.5, overlapping around x = 0 */
  const float near_far[6] = {0.2f, 0.0f, 0.5f, -0.2f, 0.0f, 0.0f};
  const float far_near[6] = {-0.2f, 0.0f, 0.0f, 0.2f, 0.0f, 0.5f};
  const unsigned char blue_red[6] = {30, 60, 230, 230, 40, 30};
  const unsigned char red_blue[6] = {230, 40, 30, 30, 60, 230};
  sph_gl *gl = context(200, 200);
  sph_image a = image_new(200, 200), b = image_new(200, 200);
  for (int ortho = 0; ortho <= 1; ++ortho) {
    sph_view v = ortho ? front_view(1, 2.0, 5.0) : front_view(0, 30.0, 5.0);
    draw(gl, &v, 2, near_far, 0.5f, blue_red, NULL, &a);
    draw(gl, &v, 2, far_near, 0.5f, red_blue, NULL, &b);
    /* blue wins the overlap (x = 0 and a little left of it) */
    int blue = 0;
    for (int x = 88; x <= 112; ++x) {
      const unsigned char *p = px(&a, x, 100), *q = px(&b, x, 100);
      blue += p[2] > p[0] + 80 && q[2] > q[0] + 80;
    }
    ck_assert_msg(blue == 25, "ortho %d: blue in %d of 25", ortho, blue);
    /* red shows left of the blue sphere */
    double o[3];
    const double left[3] = {-0.55, 0.0, 0.0};
    ck_assert(sph_view_project(&v, 200, 200, left, o));
    const unsigned char *r = px(&a, (int)o[0], (int)o[1]);
    ck_assert(r[0] > r[2] + 80);
    /* the draw order does not change a byte */
    ck_assert(memcmp(a.rgba, b.rgba, (size_t)200 * 200 * 4) == 0);
  }
  sph_gl_destroy(gl);
  free(a.rgba);
  free(b.rgba);
}
END_TEST

START_TEST(layers_paint_over) {
  /* layer 0: a flat grey sphere nearer the eye (z = 0.5) than layer 1's
   * shaded red one (z = 0), overlapping around x = 0; the later layer
   * covers the earlier one whatever their depths */
  const float grey_c[3] = {-0.2f, 0.0f, 0.5f}, red_c[3] = {0.2f, 0.0f, 0.0f};
  const unsigned char grey[3] = {200, 201, 202}, red[3] = {230, 40, 30};
  sph_gl *gl = context(200, 200);
  sph_image img = image_new(200, 200);
  sph_view v = front_view(1, 2.0, 5.0);
  sph_gl_layer layers[2] = {{1, grey_c, 0.5f, grey, NULL, 1, NULL, NULL},
                            {1, red_c, 0.5f, red, NULL, 0, NULL, NULL}};
  sph_error err;
  ck_assert_int_eq(sph_gl_draw_layers(gl, &v, layers, 2, &img, &err), SPH_OK);
  int red_px = 0;
  for (int x = 88; x <= 112; ++x) {
    const unsigned char *p = px(&img, x, 100);
    red_px += p[0] > p[2] + 80;
  }
  ck_assert_msg(red_px == 25, "red in %d of 25 overlap pixels", red_px);
  /* the flat layer keeps its exact colour where it shows (x = -0.55) */
  double o[3];
  const double left[3] = {-0.55, 0.0, 0.0};
  ck_assert(sph_view_project(&v, 200, 200, left, o));
  const unsigned char *g = px(&img, (int)o[0], (int)o[1]);
  ck_assert(g[0] == 200 && g[1] == 201 && g[2] == 202);
  /* one layer is sph_gl_draw_spheres, byte for byte */
  sph_image one = image_new(200, 200);
  draw(gl, &v, 1, red_c, 0.5f, red, NULL, &one);
  ck_assert_int_eq(sph_gl_draw_layers(gl, &v, layers + 1, 1, &img, &err),
                   SPH_OK);
  ck_assert(memcmp(one.rgba, img.rgba, (size_t)200 * 200 * 4) == 0);
  sph_gl_destroy(gl);
  free(img.rgba);
  free(one.rgba);
}
END_TEST

START_TEST(clip_plane) {
  sph_gl *gl = context(200, 200);
  sph_image img = image_new(200, 200);
  const unsigned char col[6] = {230, 40, 30, 30, 60, 230};
  for (int ortho = 0; ortho <= 1; ++ortho) {
    sph_view v = ortho ? front_view(1, 2.0, 5.0) : front_view(0, 30.0, 5.0);
    /* red in front of blue on the axis; cutting z > 0 away shows blue */
    const float axis[6] = {0, 0, 1, 0, 0, -1};
    const double keep_back[4] = {0, 0, -1, 0};
    draw(gl, &v, 2, axis, 0.4f, col, NULL, &img);
    const unsigned char *p = px(&img, 100, 100);
    ck_assert(p[0] > p[2] + 80);
    draw(gl, &v, 2, axis, 0.4f, col, keep_back, &img);
    ck_assert(p[2] > p[0] + 80);
    /* side by side: keeping x >= 0 removes the left sphere only */
    const float side[6] = {-0.5f, 0, 0, 0.5f, 0, 0};
    const double keep_right[4] = {1, 0, 0, 0};
    double l[3], r[3];
    const double lw[3] = {-0.5, 0, 0}, rw[3] = {0.5, 0, 0};
    ck_assert(sph_view_project(&v, 200, 200, lw, l));
    ck_assert(sph_view_project(&v, 200, 200, rw, r));
    draw(gl, &v, 2, side, 0.3f, col, keep_right, &img);
    ck_assert(is_background(px(&img, (int)l[0], (int)l[1])));
    p = px(&img, (int)r[0], (int)r[1]);
    ck_assert(!is_background(p) && p[2] > p[0] + 80);
  }
  sph_gl_destroy(gl);
  free(img.rgba);
}
END_TEST

/* n^3 lattice in [0, 1]^3 coloured by height (blue low, red high). */
static void lattice(int n, float *xyz, unsigned char *rgb) {
  size_t a = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k, ++a) {
        float t = (float)j / (float)(n - 1);
        xyz[3 * a + 0] = (float)i / (float)(n - 1);
        xyz[3 * a + 1] = t;
        xyz[3 * a + 2] = (float)k / (float)(n - 1);
        rgb[3 * a + 0] = (unsigned char)(40 + 200 * t);
        rgb[3 * a + 1] = (unsigned char)(90 + 80 * (1 - fabsf(2 * t - 1)));
        rgb[3 * a + 2] = (unsigned char)(240 - 200 * t);
      }
}

/* Binary PPM of the image (RGB, top row first). */
static void write_ppm(const char *path, const sph_image *img) {
  FILE *f = fopen(path, "wb");
  ck_assert_ptr_nonnull(f);
  fprintf(f, "P6\n%d %d\n255\n", img->width, img->height);
  for (size_t i = 0; i < (size_t)img->width * img->height; ++i)
    fwrite(img->rgba + 4 * i, 1, 3, f);
  ck_assert_int_eq(fclose(f), 0);
}

START_TEST(repeatable_and_demo) {
  enum { N = 20, W = 800, H = 600 };
  static float xyz[3 * N * N * N];
  static unsigned char rgb[3 * N * N * N];
  lattice(N, xyz, rgb);
  const float r = 0.5f / (N - 1) * 0.95f;
  const double lo[3] = {-r, -r, -r}, hi[3] = {1 + r, 1 + r, 1 + r};
  sph_view v;
  sph_view_fit(lo, hi, 35.0, 25.0, 1.0, 0, 3, W, H, &v);
  sph_image a = image_new(W, H), b = image_new(W, H);
  /* twice in one context, once in a fresh one: the same bytes */
  sph_gl *gl = context(W, H);
  draw(gl, &v, (size_t)N * N * N, xyz, r, rgb, NULL, &a);
  draw(gl, &v, 1, xyz, r, rgb, NULL, &b);
  draw(gl, &v, (size_t)N * N * N, xyz, r, rgb, NULL, &b);
  ck_assert(memcmp(a.rgba, b.rgba, (size_t)W * H * 4) == 0);
  sph_gl_destroy(gl);
  gl = context(W, H);
  memset(b.rgba, 0, (size_t)W * H * 4);
  draw(gl, &v, (size_t)N * N * N, xyz, r, rgb, NULL, &b);
  ck_assert(memcmp(a.rgba, b.rgba, (size_t)W * H * 4) == 0);
  write_ppm(SPH_BINARY_DIR "/gl_demo_lattice.ppm", &a);
  /* the fitted camera shows every sphere whole: the frame's border is clear */
  int border = 0;
  for (int x = 0; x < W; ++x)
    border += !is_background(px(&a, x, 0)) + !is_background(px(&a, x, H - 1));
  for (int y = 0; y < H; ++y)
    border += !is_background(px(&a, 0, y)) + !is_background(px(&a, W - 1, y));
  ck_assert_int_eq(border, 0);
  /* the cutaway too: keep x + z <= 1.2 */
  const double plane[4] = {-1, 0, -1, 1.2};
  draw(gl, &v, (size_t)N * N * N, xyz, r, rgb, plane, &b);
  write_ppm(SPH_BINARY_DIR "/gl_demo_cutaway.ppm", &b);
  sph_gl_destroy(gl);
  free(a.rgba);
  free(b.rgba);
}
END_TEST

START_TEST(fit_frames_box) {
  const double boxes[2][2][3] = {{{-1, 0, 3}, {2, 0.5, 7}},
                                 {{0, 0, 0}, {0.02, 0.1, 0.02}}};
  const int sizes[2][2] = {{640, 360}, {300, 500}};
  const double angles[5][2] = {
      {0, 0}, {35, 25}, {-120, 60}, {200, -40}, {10, 90}};
  for (int bi = 0; bi < 2; ++bi)
    for (int si = 0; si < 2; ++si)
      for (int ai = 0; ai < 5; ++ai)
        for (int mode = 0; mode < 3; ++mode) {
          /* mode 0 perspective, 1 ortho, 2 plane view */
          const double *lo = boxes[bi][0], *hi = boxes[bi][1];
          int w = sizes[si][0], h = sizes[si][1];
          sph_view v;
          sph_view_fit(lo, hi, angles[ai][0], angles[ai][1], 1.0, mode == 1,
                       mode == 2 ? 2 : 3, w, h, &v);
          ck_assert_int_eq(sph_view_check(&v, NULL), SPH_OK);
          double fill = 0.0;
          for (int i = 0; i < 8; ++i) {
            const double p[3] = {i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1],
                                 i & 4 ? hi[2] : lo[2]};
            double o[3];
            ck_assert(sph_view_project(&v, w, h, p, o));
            ck_assert_msg(o[0] > 0 && o[0] < w && o[1] > 0 && o[1] < h,
                          "box %d size %d angle %d mode %d: corner %d at %g,%g",
                          bi, si, ai, mode, i, o[0], o[1]);
            ck_assert(o[2] > 0.0 && o[2] < 1.0);
            fill = fmax(fill, fmax(fabs(o[0] / w - 0.5), fabs(o[1] / h - 0.5)));
          }
          /* tight: some corner within 10 % of the frame edge */
          ck_assert_msg(fill > 0.4, "loose fit %g", fill);
          /* zoom 2 halves the view about the centre */
          sph_view z;
          sph_view_fit(lo, hi, angles[ai][0], angles[ai][1], 2.0, mode == 1,
                       mode == 2 ? 2 : 3, w, h, &z);
          ck_assert(memcmp(z.eye, v.eye, sizeof v.eye) == 0);
        }
  /* the direction convention: azimuth 90 looks along -X, elevation 90 down */
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  sph_view v;
  sph_view_fit(lo, hi, 90.0, 0.0, 1.0, 0, 3, 100, 100, &v);
  ck_assert(v.eye[0] > 1.0 && fabs(v.eye[1] - 0.5) < 1e-12 &&
            fabs(v.eye[2] - 0.5) < 1e-12);
  sph_view_fit(lo, hi, 0.0, 90.0, 1.0, 0, 3, 100, 100, &v);
  ck_assert(v.eye[1] > 1.0 && fabs(v.eye[0] - 0.5) < 1e-12);
  sph_view_fit(lo, hi, 70.0, 30.0, 1.0, 1, 2, 100, 100, &v);
  ck_assert(v.ortho && v.eye[2] > 1.0 && fabs(v.eye[0] - 0.5) < 1e-12);
  ck_assert(fabs(v.up[1] - 1.0) < 1e-12);
}
END_TEST

START_TEST(arguments) {
  sph_gl *gl = context(64, 48);
  sph_image img = image_new(64, 48), wrong = image_new(48, 64);
  sph_view v = front_view(1, 2.0, 5.0);
  const float c[3] = {0, 0, 0};
  const unsigned char col[3] = {1, 2, 3};
  sph_error err;
  /* image size, radius, camera */
  ck_assert_int_eq(
      sph_gl_draw_spheres(gl, &v, 1, c, 0.5f, col, NULL, &wrong, &err),
      SPH_ERR_ARG);
  ck_assert_int_eq(
      sph_gl_draw_spheres(gl, &v, 1, c, 0.0f, col, NULL, &img, &err),
      SPH_ERR_ARG);
  sph_view bad = v;
  bad.eye[2] = 0.0;
  ck_assert_int_eq(
      sph_gl_draw_spheres(gl, &bad, 1, c, 0.5f, col, NULL, &img, &err),
      SPH_ERR_ARG);
  bad = v;
  bad.up[1] = 0.0, bad.up[2] = 1.0;
  ck_assert_int_eq(
      sph_gl_draw_spheres(gl, &bad, 1, c, 0.5f, col, NULL, &img, &err),
      SPH_ERR_ARG);
  const float nan_xyz[6] = {0, 0, 0, 1, NAN, 0};
  const unsigned char two[6] = {1, 2, 3, 4, 5, 6};
  ck_assert_int_eq(
      sph_gl_draw_spheres(gl, &v, 2, nan_xyz, 0.5f, two, NULL, &img, &err),
      SPH_ERR_NUMERIC);
  /* no spheres: background only */
  draw(gl, &v, 0, NULL, 0.0f, NULL, NULL, &img);
  int bg = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x)
      bg += is_background(px(&img, x, y));
  ck_assert_int_eq(bg, 64 * 48);
  /* a bad size */
  sph_gl *none = NULL;
  ck_assert_int_eq(sph_gl_create(0, 10, &none, &err), SPH_ERR_RANGE);
  ck_assert_ptr_null(none);
  ck_assert_int_eq(sph_gl_create(100000, 10, &none, &err), SPH_ERR_RANGE);
  ck_assert_ptr_null(none);
  /* the driver that crashes OSMesa is refused with a clear message */
  ck_assert_int_eq(setenv("GALLIUM_DRIVER", "swrast", 1), 0);
  ck_assert_int_eq(sph_gl_create(10, 10, &none, &err), SPH_ERR_UNSUPPORTED);
  ck_assert_ptr_null(none);
  ck_assert_ptr_nonnull(strstr(err.message, "swrast"));
  ck_assert_int_eq(setenv("GALLIUM_DRIVER", "llvmpipe", 1), 0);
  sph_gl_destroy(gl);
  free(img.rgba);
  free(wrong.rgba);
}
END_TEST

int main(void) {
  Suite *s = suite_create("gl");
  TCase *tc = tcase_create("gl");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, one_sphere_ortho);
  tcase_add_test(tc, radius_factor_per_sphere);
  tcase_add_test(tc, one_sphere_perspective);
  tcase_add_test(tc, large_sphere);
  tcase_add_test(tc, occlusion_any_order);
  tcase_add_test(tc, layers_paint_over);
  tcase_add_test(tc, clip_plane);
  tcase_add_test(tc, repeatable_and_demo);
  tcase_add_test(tc, fit_frames_box);
  tcase_add_test(tc, arguments);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
