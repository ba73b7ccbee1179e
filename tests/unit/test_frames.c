/* Frames of sph run with the png cutaways: a block seen along -Z (ortho)
 * rendered whole, with `clip` (the image differs, every pixel beyond the
 * plane is background, the kept side is unchanged), with `cut: half` seen
 * obliquely (differs, fewer particle pixels) and with `ghost` after a rigid
 * translation (the reference silhouette appears where the block was). */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gl_impl.h"
#include "render/image.h"

#define W 320
#define H 240

/* The spheres' radius: that of the particle's volume, dp = 0.2 m */
#define R (0.2 * 0.6203504908994)

static char dir[] = "/tmp/sph_frames_XXXXXX";

/* Runs the block scene with extra png keys and velocity; reads frame 1. */
static void render(const char *tag, const char *png_keys, double vx,
                   sph_image *img) {
  char scene[200], cmd[2048], path[300];
  snprintf(scene, sizeof scene, "%s/%s.yaml", dir, tag);
  FILE *f = fopen(scene, "w");
  ck_assert_ptr_nonnull(f);
  fprintf(f,
          "name: block\ndimension: 3\nmethod: {name: tl-jst}\n"
          "materials: {m: {density: 1000, youngs_modulus: 1e6, "
          "poisson_ratio: 0.3}}\nbodies:\n  - {name: b, material: m, shape: "
          "{box: {min: [0, 0, 0], max: [1, 1, 1]}}, particles: {count: [6, 6, "
          "6]}, initial_velocity: {uniform: [%g, 0, 0]}}\n"
          "time: {end: 0.02}\noutput:\n  every: 0.02\n  vtk: false\n"
          "  png: {width: %d, height: %d, mp4: false%s}\n",
          vx, W, H, png_keys);
  fclose(f);
  snprintf(cmd, sizeof cmd,
           "%s/sph run %s --out %s/%s --quiet --threads 1 > /dev/null",
           SPH_BINARY_DIR, scene, dir, tag);
  ck_assert_int_eq(system(cmd), 0);
  snprintf(path, sizeof path, "%s/%s/frames/block_0001.png", dir, tag);
  sph_error err;
  ck_assert_msg(sph_image_read_png(path, img, &err) == SPH_OK, "%s",
                err.message);
  ck_assert(img->width == W && img->height == H);
}

static const unsigned char *px(const sph_image *img, int x, int y) {
  return img->rgba + ((size_t)y * img->width + x) * 4;
}

static int is_background(const unsigned char *p) {
  return p[0] == SPH_GL_BACKGROUND && p[1] == SPH_GL_BACKGROUND &&
         p[2] == SPH_GL_BACKGROUND;
}

/* The particle area: below the label block, left of the colour bar. */
static int in_scene(int x, int y) { return y > H / 5 && x < W - W / 8 - 40; }

/* Leftmost and rightmost columns with particle pixels; their count. */
static long extent(const sph_image *img, int *x0, int *x1) {
  long count = 0;
  *x0 = W;
  *x1 = -1;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if (in_scene(x, y) && !is_background(px(img, x, y))) {
        count++;
        *x0 = x < *x0 ? x : *x0;
        *x1 = x > *x1 ? x : *x1;
      }
  return count;
}

static int differ(const sph_image *a, const sph_image *b) {
  sph_imgdiff_result r;
  sph_error err;
  ck_assert_int_eq(sph_image_diff(a, b, NULL, &r, NULL, &err), SPH_OK);
  return !r.passed;
}

static const char *front = ", camera: {azimuth: 0, elevation: 0, zoom: 0.6}";

START_TEST(clip_plane) {
  sph_image whole, clipped;
  render("whole", front, 0.0, &whole);
  char keys[256];
  snprintf(keys, sizeof keys, "%s, clip: {normal: [1, 0, 0], at: 0.5}", front);
  render("clipped", keys, 0.0, &clipped);
  ck_assert(differ(&whole, &clipped));
  int a0, a1, b0, b1;
  long na = extent(&whole, &a0, &a1);
  extent(&clipped, &b0, &b1);
  ck_assert_msg(na > 1000 && a1 - a0 > 60, "block: %ld px, %d..%d", na, a0, a1);
  /* x in [-R, 1 + R] spans a0..a1; the kept spheres (centres 0, 0.2, 0.4)
   * end at x = 0.4 + R */
  double scale = (a1 + 1 - a0) / (1.0 + 2.0 * R);
  int plane = (int)(a0 + (0.4 + 2.0 * R) * scale + 1.5);
  long beyond = 0;
  for (int y = 0; y < H; ++y)
    for (int x = plane; x < W; ++x)
      beyond += in_scene(x, y) && !is_background(px(&clipped, x, y));
  ck_assert_msg(beyond == 0, "%ld particle pixels beyond column %d", beyond,
                plane);
  ck_assert_msg(b0 == a0 && b1 < plane && b1 > a0 + 0.5 * scale,
                "clipped block spans %d..%d, whole %d..%d", b0, b1, a0, a1);
  /* the kept side looks as before */
  long changed = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < (int)(a0 + 0.4 * scale); ++x)
      changed += in_scene(x, y) &&
                 memcmp(px(&whole, x, y), px(&clipped, x, y), 3) != 0;
  ck_assert_int_eq(changed, 0);
  sph_image_destroy(&whole);
  sph_image_destroy(&clipped);
}
END_TEST

START_TEST(cut_half) {
  sph_image whole, cut;
  /* follow: false, so both frames share the initial bodies' fit */
  const char *oblique =
      ", camera: {azimuth: 30, elevation: 20, zoom: 0.6, follow: false}";
  render("oblique", oblique, 0.0, &whole);
  char keys[256];
  snprintf(keys, sizeof keys, "%s, cut: half", oblique);
  render("cut", keys, 0.0, &cut);
  ck_assert(differ(&whole, &cut));
  int a0, a1, b0, b1;
  long na = extent(&whole, &a0, &a1), nb = extent(&cut, &b0, &b1);
  ck_assert_msg(nb > na / 3 && nb < na * 9 / 10, "cut %ld px, whole %ld px", nb,
                na);
  sph_image_destroy(&whole);
  sph_image_destroy(&cut);
}
END_TEST

/* pixels that differ between two frames in the part right of 0.8 W that
 * the layout keeps for the colour bar and its labels */
static long bar_strip_changes(const sph_image *a, const sph_image *b) {
  long n = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 4 * W / 5; x < W; ++x)
      n += memcmp(px(a, x, y), px(b, x, y), 3) != 0;
  return n;
}

START_TEST(follow_camera_keeps_the_bar_clear) {
  /* 150 m/s for 0.02 s: the block travels three times its width; the
   * follow camera (default) keeps it whole and left of the colour bar */
  sph_image followed, fixed, still;
  render("follow", "", 150.0, &followed);
  render("still", "", 0.0, &still);
  int x0, x1;
  long n = 0;
  x0 = W, x1 = -1;
  for (int y = H / 5; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if (!is_background(px(&followed, x, y)) && x < 4 * W / 5) {
        n++;
        x0 = x < x0 ? x : x0;
        x1 = x > x1 ? x : x1;
      }
  ck_assert_msg(n > 1000 && x0 > 0, "followed: %ld px from column %d", n, x0);
  /* the bar strip holds the overlay only: as in the frame of the block at
   * rest (the same zero pressure, so the same bar and labels) */
  ck_assert_int_eq(bar_strip_changes(&followed, &still), 0);
  /* the same run with the camera held on the start: the block has left
   * the free part of the frame */
  render("fixed", ", camera: {follow: false}", 150.0, &fixed);
  long left = 0;
  for (int y = H / 5; y < H; ++y)
    for (int x = 0; x < 4 * W / 5; ++x)
      left += !is_background(px(&fixed, x, y));
  ck_assert_msg(left < n / 2, "held camera: %ld px in the free part", left);
  sph_image_destroy(&followed);
  sph_image_destroy(&fixed);
  sph_image_destroy(&still);
}
END_TEST

START_TEST(axes_triad) {
  /* axes: true adds the world axes in the bottom-left corner and changes
   * nothing else: X red, Y green there; the rest of the frame as without */
  sph_image plain, axes;
  render("noaxes", "", 0.0, &plain);
  render("axes", ", axes: true", 0.0, &axes);
  long outside = 0, red = 0, green = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const unsigned char *a = px(&axes, x, y), *b = px(&plain, x, y);
      int corner = x < W / 4 && y > H / 2;
      if (!corner)
        outside += memcmp(a, b, 3) != 0;
      else if (memcmp(a, b, 3)) {
        red += a[0] > 150 && a[1] < 90 && a[2] < 90;
        green += a[1] > 110 && a[0] < 90 && a[2] < 90;
      }
    }
  ck_assert_int_eq(outside, 0);
  ck_assert_msg(red > 10 && green > 10, "triad: %ld red, %ld green pixels", red,
                green);
  sph_image_destroy(&plain);
  sph_image_destroy(&axes);
}
END_TEST

START_TEST(scale_bar_length) {
  /* the bar is a nice length (1, 2 or 5 x 10^k m) at the frame's scale:
   * the block's 1 + 2 R m (centres 0..1, spheres of radius R) spans
   * a0..a1 in the same front ortho view */
  sph_image plain, bar;
  char keys[256];
  snprintf(keys, sizeof keys, "%s, scale_bar: true", front);
  render("plainbar", front, 0.0, &plain);
  render("bar", keys, 0.0, &bar);
  int a0, a1;
  extent(&plain, &a0, &a1);
  double px_per_m = (a1 + 1 - a0) / (1.0 + 2.0 * R);
  /* the longest black run of a row in the bottom band */
  int longest = 0;
  for (int y = H - H / 7; y < H; ++y) {
    int run = 0;
    for (int x = 0; x < W; ++x) {
      const unsigned char *p = px(&bar, x, y);
      run = p[0] < 40 && p[1] < 40 && p[2] < 40 ? run + 1 : 0;
      longest = run > longest ? run : longest;
    }
  }
  double metres = longest / px_per_m;
  double mant = metres / pow(10.0, floor(log10(metres)));
  ck_assert_msg(fabs(mant - 1.0) < 0.05 || fabs(mant - 2.0) < 0.1 ||
                    fabs(mant - 5.0) < 0.25 || fabs(mant - 10.0) < 0.5,
                "bar of %d px is %g m at %g px/m", longest, metres, px_per_m);
  sph_image_destroy(&plain);
  sph_image_destroy(&bar);
}
END_TEST

START_TEST(ghost_outline) {
  /* 10 m/s for 0.02 s: the block moves one spacing (0.2 m) to the right */
  sph_image plain, ghost;
  render("moved", front, 10.0, &plain);
  char keys[256];
  snprintf(keys, sizeof keys, "%s, ghost: true", front);
  render("ghost", keys, 10.0, &ghost);
  ck_assert(differ(&plain, &ghost));
  int a0, a1, b0, b1;
  extent(&plain, &a0, &a1);
  extent(&ghost, &b0, &b1);
  ck_assert_msg(b0 < a0 - 5 && b1 <= a1 + 1, "ghost %d..%d, block %d..%d", b0,
                b1, a0, a1);
  /* where the block was and is no more: grey, unshaded, never background */
  long grey = 0, other = 0;
  for (int y = 0; y < H; ++y)
    for (int x = b0 + 4; x < a0 - 1; ++x) {
      if (!in_scene(x, y) || is_background(px(&plain, x, y)))
        continue;
      other++;
    }
  for (int y = H / 3; y < 2 * H / 3; ++y)
    for (int x = b0 + 4; x < a0 - 1; ++x) {
      const unsigned char *p = px(&ghost, x, y);
      grey += p[0] == 222 && p[1] == 222 && p[2] == 226;
    }
  ck_assert_msg(other == 0 && grey > 50,
                "left of the block: %ld grey px, %ld "
                "particle px without ghost",
                grey, other);
  sph_image_destroy(&plain);
  sph_image_destroy(&ghost);
}
END_TEST

int main(void) {
  if (!mkdtemp(dir))
    return EXIT_FAILURE;
  Suite *s = suite_create("frames");
  TCase *tc = tcase_create("frames");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, clip_plane);
  tcase_add_test(tc, cut_half);
  tcase_add_test(tc, ghost_outline);
  tcase_add_test(tc, follow_camera_keeps_the_bar_clear);
  tcase_add_test(tc, axes_triad);
  tcase_add_test(tc, scale_bar_length);
  suite_add_tcase(s, tc);
  int rc = sph_test_run(s);
  char cmd[256];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  if (system(cmd) != 0)
    rc = EXIT_FAILURE;
  return rc;
}
