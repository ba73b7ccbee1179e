/* The frames of one run share one colour scale and one camera (issue 38):
 * the colour bar's strip (the right fifth of the frame, which the layout
 * keeps for the bar and its labels) is the same, pixel for pixel, in every
 * frame of a run; the camera's scale (the rings' extent on screen over
 * their extent in the .vtp files) changes by at most 7 % between
 * consecutive frames as the rings collide and part (the follow camera of
 * before refitted in jumps of 14 and 21 %), the rings fill most of the
 * frame and never reach the bar's strip; and a run stopped by a signal
 * leaves frames sharing one bar too, as does its --resume. */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gl_impl.h"
#include "io/vtk_read.h"
#include "render/image.h"

#define W 320
#define H 180

static char dir[] = "/tmp/sph_frames_run_XXXXXX";

/* sph run of a shipped scene with overrides into dir/tag. */
static void run_scene(const char *scene, const char *tag, const char *sets) {
  char cmd[2048];
  snprintf(cmd, sizeof cmd,
           "OMP_NUM_THREADS=1 %s/sph run %s/scenes/%s.yaml --out %s/%s "
           "--quiet --threads 1 --set output.png.width=%d --set "
           "output.png.height=%d --set output.png.mp4=false %s > /dev/null",
           SPH_BINARY_DIR, SPH_SOURCE_DIR, scene, dir, tag, W, H, sets);
  ck_assert_int_eq(system(cmd), 0);
}

/* Frame k's particles' extent in x and y (metres), from its .vtp. */
static void world_extent(const char *tag, const char *scene, int k,
                         double ext[2]) {
  char path[512], line[4096];
  snprintf(path, sizeof path, "%s/%s/%s_%04d.vtp", dir, tag, scene, k);
  FILE *f = fopen(path, "r");
  ck_assert_ptr_nonnull(f);
  size_t n = 0;
  while (!n && fgets(line, sizeof line, f)) {
    const char *at = strstr(line, "NumberOfPoints=\"");
    if (at)
      n = strtoul(at + 16, NULL, 10);
  }
  fclose(f);
  ck_assert(n > 0);
  double *x = malloc(3 * n * sizeof *x), t;
  ck_assert_ptr_nonnull(x);
  sph_error err;
  ck_assert_msg(sph_vtp_read(path, n, x, NULL, 1, NULL, &t, &err) == SPH_OK,
                "%s", err.message);
  for (int c = 0; c < 2; ++c) {
    double lo = INFINITY, hi = -INFINITY;
    for (size_t a = 0; a < n; ++a) {
      lo = fmin(lo, x[3 * a + c]);
      hi = fmax(hi, x[3 * a + c]);
    }
    ext[c] = hi - lo;
  }
  free(x);
}

/* Frame k of the run in dir/tag; 0 when there is none. */
static int frame(const char *tag, const char *scene, int k, sph_image *img) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s/frames/%s_%04d.png", dir, tag, scene, k);
  if (access(path, F_OK) != 0)
    return 0;
  sph_error err;
  ck_assert_msg(sph_image_read_png(path, img, &err) == SPH_OK, "%s",
                err.message);
  ck_assert(img->width == W && img->height == H);
  return 1;
}

static const unsigned char *px(const sph_image *img, int x, int y) {
  return img->rgba + ((size_t)y * img->width + x) * 4;
}

/* A particle's pixel on the viridis map (von Mises): coloured, where the
 * background, the label block and the text are grey. */
static int is_particle(const unsigned char *p) {
  int lo = p[0] < p[1] ? p[0] : p[1], hi = p[0] > p[1] ? p[0] : p[1];
  lo = p[2] < lo ? p[2] : lo;
  hi = p[2] > hi ? p[2] : hi;
  return hi - lo > 16;
}

/* Pixels that differ in the bar's strip, x >= 0.8 W. */
static long bar_changes(const sph_image *a, const sph_image *b) {
  long n = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 4 * W / 5; x < W; ++x)
      n += memcmp(px(a, x, y), px(b, x, y), 3) != 0;
  return n;
}

/* Every frame's bar strip equals frame 0's; returns the frame count. */
static int assert_one_bar(const char *tag, const char *scene) {
  sph_image first, img;
  ck_assert(frame(tag, scene, 0, &first));
  int k = 1;
  for (; frame(tag, scene, k, &img); ++k) {
    long n = bar_changes(&first, &img);
    sph_image_destroy(&img);
    ck_assert_msg(n == 0,
                  "%s: frame %d's colour bar differs from frame 0's "
                  "in %ld pixels",
                  tag, k, n);
  }
  sph_image_destroy(&first);
  return k;
}

/* The particles' extent on screen: the box of the particle pixels left of
 * the bar's strip; and how many lie in the strip below the bar (which spans
 * 0.2 H .. 0.8 H, its labels beside it): none may. */
static void extent(const sph_image *img, int box[4], long *in_strip) {
  box[0] = box[1] = W;
  box[2] = box[3] = -1;
  *in_strip = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (!is_particle(px(img, x, y)))
        continue;
      if (x >= 4 * W / 5 - 2) {
        *in_strip += y > 0.9 * H;
        continue;
      }
      box[0] = x < box[0] ? x : box[0];
      box[1] = y < box[1] ? y : box[1];
      box[2] = x > box[2] ? x : box[2];
      box[3] = y > box[3] ? y : box[3];
    }
}

START_TEST(twisting_column_one_bar) {
  /* 11 frames of the twisting column: the pressure grows from 0 (frame 0
   * shows the run's scale, not 0..1) */
  run_scene("twisting_column", "column",
            "--set 'bodies.0.particles.count=[3,13,3]' --set time.end=0.1 "
            "--set output.every=0.01");
  ck_assert_int_eq(assert_one_bar("column", "twisting_column"), 11);
}
END_TEST

START_TEST(rings_steady_camera) {
  /* the rings at twice the shipped spacing from 0 to 0.03 s (they meet at
   * 0.003 s and part at 0.012 s), a frame every 0.001 s */
  run_scene("colliding_rings", "rings",
            "--set bodies.0.particles.spacing=0.002 --set "
            "bodies.1.particles.spacing=0.002 --set output.every=0.001");
  int frames = assert_one_bar("rings", "colliding_rings");
  ck_assert_int_eq(frames, 31);
  double prev_s[2] = {0.0, 0.0}, worst = 0.0;
  int at = 0;
  for (int k = 0; k < frames; ++k) {
    sph_image img;
    ck_assert(frame("rings", "colliding_rings", k, &img));
    int box[4];
    long strip;
    extent(&img, box, &strip);
    sph_image_destroy(&img);
    ck_assert_msg(strip == 0, "frame %d: %ld particle pixels under the bar", k,
                  strip);
    int w = box[2] - box[0] + 1, h = box[3] - box[1] + 1;
    /* the rings fill most of the frame's free part (left of the bar,
     * below the label block: 41 px at this size) across or up */
    ck_assert_msg(w > 0.6 * (4 * W / 5) || h > 0.6 * (H - 41),
                  "frame %d: rings %d x %d px", k, w, h);
    ck_assert_msg(box[0] > 0 && box[1] > 0 && box[3] < H - 1,
                  "frame %d: rings at the frame's edge (%d, %d)..(%d, %d)", k,
                  box[0], box[1], box[2], box[3]);
    /* the camera's scale: pixels per metre across and up (the rings'
     * own deformation cancels) */
    double ext[2];
    world_extent("rings", "colliding_rings", k, ext);
    double sx = (double)w / ext[0], sy = (double)h / ext[1];
    if (k > 0) {
      double c = fmax(fabs(sx / prev_s[0] - 1.0), fabs(sy / prev_s[1] - 1.0));
      if (c > worst) {
        worst = c;
        at = k;
      }
    }
    prev_s[0] = sx;
    prev_s[1] = sy;
  }
  /* the smooth follow changes the scale by at most 5 % a frame; a sphere's
   * edge pixel on either side of 120 px or more adds 2 % */
  ck_assert_msg(worst <= 0.07,
                "the camera's scale changed by %.1f %% at frame %d",
                100.0 * worst, at);
}
END_TEST

START_TEST(stopped_run_one_bar) {
  /* SIGINT once two frames are drawn: the run stops between steps, its
   * frames so far drawn again with the range and camera of the part run */
  char cmd[2048];
  snprintf(cmd, sizeof cmd,
           "OMP_NUM_THREADS=1 %s/sph run %s/scenes/twisting_column.yaml "
           "--out %s/stop --quiet --threads 1 --set output.png.width=%d "
           "--set output.png.height=%d --set output.png.mp4=false --set "
           "output.vtk=false --set 'bodies.0.particles.count=[5,25,5]' "
           "--set output.every=0.005 > /dev/null 2>&1 & pid=$!; "
           "while [ \"$(ls %s/stop/frames 2>/dev/null | grep -c png)\" -lt 2 "
           "]; do kill -0 $pid 2>/dev/null || break; sleep 0.05; done; "
           "kill -INT $pid 2>/dev/null; wait $pid; exit 0",
           SPH_BINARY_DIR, SPH_SOURCE_DIR, dir, W, H, dir);
  ck_assert_int_eq(system(cmd), 0);
  int frames = assert_one_bar("stop", "twisting_column");
  ck_assert(frames >= 2);
  /* the scratch file kept for --resume, which draws every frame again with
   * the whole run's range and camera, then removes it */
  char scratch[400];
  snprintf(scratch, sizeof scratch, "%s/stop/frames/.twisting_column.frames",
           dir);
  ck_assert_msg(access(scratch, F_OK) == 0, "%s not kept", scratch);
  snprintf(cmd, sizeof cmd,
           "OMP_NUM_THREADS=1 %s/sph run %s/scenes/twisting_column.yaml "
           "--resume %s/stop --quiet --threads 1 --set output.png.width=%d "
           "--set output.png.height=%d --set output.png.mp4=false --set "
           "output.vtk=false --set 'bodies.0.particles.count=[5,25,5]' "
           "--set output.every=0.005 > /dev/null",
           SPH_BINARY_DIR, SPH_SOURCE_DIR, dir, W, H);
  ck_assert_int_eq(system(cmd), 0);
  ck_assert_int_eq(assert_one_bar("stop", "twisting_column"), 61);
  ck_assert_msg(access(scratch, F_OK) != 0, "%s left behind", scratch);
}
END_TEST

int main(void) {
  if (!mkdtemp(dir))
    return EXIT_FAILURE;
  Suite *s = suite_create("frames_run");
  TCase *tc = tcase_create("frames_run");
  tcase_set_timeout(tc, 600);
  tcase_add_test(tc, twisting_column_one_bar);
  tcase_add_test(tc, rings_steady_camera);
  tcase_add_test(tc, stopped_run_one_bar);
  suite_add_tcase(s, tc);
  int rc = sph_test_run(s);
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  if (system(cmd) != 0)
    rc = EXIT_FAILURE;
  return rc;
}
