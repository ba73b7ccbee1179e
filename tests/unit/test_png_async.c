/* The PNG sink's render thread (render/png_sink.c): frames handed to it
 * while the simulation keeps stepping, and frames handed over back to back
 * from states that differ (the one before still rendering), are byte for
 * byte the frames the same sink renders on the calling thread (the
 * twisting column at 320 x 240, with the default pressure colours and with
 * clip, ghost and the velocity magnitude on an `auto` range); a frame the
 * render thread cannot write (file size limit as a full disk) comes back
 * as SPH_ERR_IO naming that frame from the next write, flush or close and
 * leaves no file behind; destroy without close finishes the frame in
 * flight. */
#include "test_util.h"

#include <dirent.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "render/render.h"
#include "scene/scene.h"
#include "solver/run.h"
#include "solver/sim.h"

static char dir[] = "/tmp/sph_png_async_XXXXXX";

/* The twisting column, coarse and small-framed, with extra overrides. */
static void make_sim(const char *const *extra, size_t nextra, sph_scene **scene,
                     sph_sim **sim) {
  char path[512];
  snprintf(path, sizeof path, "%s/scenes/twisting_column.yaml", SPH_SOURCE_DIR);
  const char *sets[8] = {"bodies.0.particles.count=[3,13,3]",
                         "output.png.width=320", "output.png.height=240"};
  size_t n = 3;
  for (size_t i = 0; i < nextra && n < 8; ++i)
    sets[n++] = extra[i];
  sph_error err;
  ck_assert_msg(sph_scene_load(scene, path, sets, n, &err) == SPH_OK, "%s",
                err.message);
  ck_assert_msg(sph_sim_create(sim, *scene, &err) == SPH_OK, "%s", err.message);
}

/* Output frame `index` of the current state. */
static sph_frame frame_of(sph_sim *sim, int index) {
  sph_error err;
  ck_assert_msg(sim->method->derive(sim, &err) == SPH_OK, "%s", err.message);
  return (sph_frame){.time = sim->t,
                     .step = sim->steps,
                     .index = index,
                     .sim = sim,
                     .ps = sim->ps};
}

static void open_sink(sph_sink *sink, const sph_sink_ops *ops,
                      const sph_sim *sim, const char *out) {
  *sink = (sph_sink){.ops = ops};
  sph_error err;
  ck_assert_int_eq(mkdir(out, 0777), 0);
  ck_assert_msg(ops->open(sink, sim, out, &err) == SPH_OK, "%s", err.message);
}

/* Whole file into memory; its size in *len. */
/* the default scene's render-thread sink writing to <dir>/<name>; frames
 * gets its frames folder */
static void open_async(sph_sink *sink, const char *name, sph_scene **scene,
                       sph_sim **sim, char *frames, size_t size) {
  char out[256];
  make_sim(NULL, 0, scene, sim);
  snprintf(out, sizeof out, "%s/%s", dir, name);
  snprintf(frames, size, "%s/frames", out);
  open_sink(sink, &sph_png_sink_thread_ops, *sim, out);
}

static unsigned char *slurp(const char *path, long *len) {
  FILE *f = fopen(path, "rb");
  ck_assert_msg(f != NULL, "missing %s", path);
  fseek(f, 0, SEEK_END);
  *len = ftell(f);
  fseek(f, 0, SEEK_SET);
  unsigned char *b = malloc(*len > 0 ? (size_t)*len : 1);
  ck_assert_ptr_nonnull(b);
  ck_assert_int_eq(fread(b, 1, (size_t)*len, f), (size_t)*len);
  fclose(f);
  return b;
}

/* Moves the particles to saved + (shift, 0, 0). */
static void place(sph_sim *sim, const double *saved, double shift) {
  double *x = sim->ps->field[SPH_FIELD_POSITION];
  for (size_t i = 0; i < 3 * sim->ps->n; ++i)
    x[i] = saved[i] + (i % 3 == 0 ? shift : 0.0);
}

static void write_ok(sph_sink *sink, sph_sim *sim, int index) {
  sph_error err;
  sph_frame fr = frame_of(sim, index);
  ck_assert_msg(sink->ops->write(sink, &fr, &err) == SPH_OK, "%s", err.message);
}

/* Steps a sim through `times` output times and writes two frames at each
 * through both sinks: the state, and at once after it the state shifted
 * sideways (no step between), so the threaded sink gets its next frame
 * while the one before may still be rendering; the threaded sink is
 * handed both first. */
static void compare_run(const char *tag, const char *const *extra,
                        size_t nextra, int times) {
  sph_scene *scene;
  sph_sim *sim;
  make_sim(extra, nextra, &scene, &sim);
  char a[256], b[256];
  snprintf(a, sizeof a, "%s/%s_thread", dir, tag);
  snprintf(b, sizeof b, "%s/%s_sync", dir, tag);
  sph_sink async, sync;
  open_sink(&async, &sph_png_sink_thread_ops, sim, a);
  open_sink(&sync, &sph_png_sink_sync_ops, sim, b);
  sph_error err;
  double *saved = malloc(3 * sim->ps->n * sizeof *saved);
  ck_assert_ptr_nonnull(saved);
  int frames = 2 * times;
  for (int k = 0; k < times; ++k) {
    double next = 0.02 * k;
    ck_assert_msg(sph_sim_advance(sim, next, ULONG_MAX, &err) == SPH_OK, "%s",
                  err.message);
    memcpy(saved, sim->ps->field[SPH_FIELD_POSITION],
           3 * sim->ps->n * sizeof *saved);
    write_ok(&async, sim, 2 * k);
    place(sim, saved, 0.25);
    write_ok(&async, sim, 2 * k + 1);
    place(sim, saved, 0.0);
    write_ok(&sync, sim, 2 * k);
    place(sim, saved, 0.25);
    write_ok(&sync, sim, 2 * k + 1);
    place(sim, saved, 0.0);
  }
  free(saved);
  ck_assert_msg(async.ops->close(&async, &err) == SPH_OK, "%s", err.message);
  ck_assert_msg(sync.ops->close(&sync, &err) == SPH_OK, "%s", err.message);
  async.ops->destroy(&async);
  sync.ops->destroy(&sync);
  ck_assert(async.thread_seconds > 0.0);
  ck_assert(sync.thread_seconds == 0.0);
  /* every frame present in both and identical */
  unsigned char *first = NULL, *last = NULL;
  long first_len = 0, last_len = 0;
  for (int k = 0; k < frames; ++k) {
    char pa[400], pb[400];
    snprintf(pa, sizeof pa, "%s/frames/twisting_column_%04d.png", a, k);
    snprintf(pb, sizeof pb, "%s/frames/twisting_column_%04d.png", b, k);
    long la, lb;
    unsigned char *da = slurp(pa, &la), *db = slurp(pb, &lb);
    ck_assert_msg(la == lb && memcmp(da, db, (size_t)la) == 0,
                  "%s: frame %d differs between the threads", tag, k);
    free(db);
    if (k == 0) {
      first = da;
      first_len = la;
    } else if (k == frames - 1) {
      last = da;
      last_len = la;
    } else {
      free(da);
    }
  }
  /* the column moved: equal frames are not equal by accident */
  ck_assert(first_len != last_len ||
            memcmp(first, last, (size_t)first_len) != 0);
  free(first);
  free(last);
  sph_sim_destroy(sim);
  sph_scene_destroy(scene);
}

START_TEST(test_same_bytes_default) { compare_run("default", NULL, 0, 4); }
END_TEST

START_TEST(test_same_bytes_cutaways) {
  const char *extra[] = {"output.png.color=velocity", "output.png.range=auto",
                         "output.png.ghost=true",
                         "output.png.clip={normal: [1, 0, 0], at: 0.2}"};
  compare_run("cutaways", extra, 4, 4);
}
END_TEST

/* Files in d, one name per line in `names` (sorted by readdir order). */
static int list_dir(const char *d, char *names, size_t size) {
  DIR *h = opendir(d);
  ck_assert_ptr_nonnull(h);
  struct dirent *e;
  int n = 0;
  names[0] = '\0';
  while ((e = readdir(h)))
    if (e->d_name[0] != '.') {
      ++n;
      strncat(names, e->d_name, size - strlen(names) - 2);
      strcat(names, "\n");
    }
  closedir(h);
  return n;
}

static void set_file_limit(rlim_t bytes) {
  struct rlimit r;
  ck_assert_int_eq(getrlimit(RLIMIT_FSIZE, &r), 0);
  r.rlim_cur = bytes;
  ck_assert_int_eq(setrlimit(RLIMIT_FSIZE, &r), 0);
}

/* err is an I/O error about frame `index` (or, once the limit is below
 * it, about the frames' scratch file, written at every frame). */
static void assert_frame_error(sph_status st, const sph_error *err, int index) {
  char name[64];
  snprintf(name, sizeof name, "twisting_column_%04d.png", index);
  ck_assert_msg(st == SPH_ERR_IO, "status %s, expected SPH_ERR_IO",
                sph_status_name(st));
  if (index > 1 && strstr(err->file, ".twisting_column.frames"))
    return;
  size_t lf = strlen(err->file), ln = strlen(name);
  ck_assert_msg(lf >= ln && !strcmp(err->file + lf - ln, name),
                "error names '%s', expected frame %d", err->file, index);
  ck_assert(err->message[0] != '\0');
}

START_TEST(test_thread_error) {
  sph_scene *scene;
  sph_sim *sim;
  sph_sink sink;
  char frames[300];
  open_async(&sink, "error", &scene, &sim, frames, sizeof frames);
  sph_error err;
  sph_frame fr = frame_of(sim, 0);
  ck_assert_msg(sink.ops->write(&sink, &fr, &err) == SPH_OK, "%s", err.message);
  ck_assert_msg(sink.ops->flush(&sink, &err) == SPH_OK, "%s", err.message);
  /* later frames outgrow the file size limit (a full disk) */
  struct stat st0;
  char f0[400];
  snprintf(f0, sizeof f0, "%s/twisting_column_0000.png", frames);
  ck_assert_int_eq(stat(f0, &st0), 0);
  struct rlimit saved;
  ck_assert_int_eq(getrlimit(RLIMIT_FSIZE, &saved), 0);
  signal(SIGXFSZ, SIG_IGN);
  set_file_limit((rlim_t)st0.st_size / 2);
  /* reported by flush */
  fr.index = 1;
  ck_assert(sink.ops->write(&sink, &fr, &err) == SPH_OK);
  assert_frame_error(sink.ops->flush(&sink, &err), &err, 1);
  ck_assert(sink.ops->flush(&sink, &err) == SPH_OK); /* reported once */
  /* the next frame's error, the render thread's (frame 2's file) or the
   * scratch file's (written at every write), reported once, by the write
   * or by the flush after it */
  fr.index = 2;
  sph_status st2 = sink.ops->write(&sink, &fr, &err);
  if (st2 == SPH_OK)
    st2 = sink.ops->flush(&sink, &err);
  assert_frame_error(st2, &err, 2);
  ck_assert(sink.ops->flush(&sink, &err) == SPH_OK);
  /* reported by close */
  fr.index = 4;
  sph_status st4 = sink.ops->write(&sink, &fr, &err);
  if (st4 == SPH_OK) {
    assert_frame_error(sink.ops->close(&sink, &err), &err, 4);
  } else { /* the frames' scratch file outgrew the limit first */
    ck_assert_int_eq(st4, SPH_ERR_IO);
    ck_assert_msg(strstr(err.file, ".twisting_column.frames"), "%s", err.file);
  }
  ck_assert_int_eq(setrlimit(RLIMIT_FSIZE, &saved), 0);
  sink.ops->destroy(&sink);
  char scratch[400];
  struct stat sst;
  snprintf(scratch, sizeof scratch, "%s/.twisting_column.frames", frames);
  ck_assert_msg(stat(scratch, &sst) != 0, "%s left behind", scratch);
  /* only the frame written before the limit; no temporary file */
  char names[1024];
  int n = list_dir(frames, names, sizeof names);
  ck_assert_msg(n == 1 && !strcmp(names, "twisting_column_0000.png\n"),
                "frames folder holds:\n%s", names);
  sph_sim_destroy(sim);
  sph_scene_destroy(scene);
}
END_TEST

/* A sink destroyed without close (a run that failed elsewhere) still
 * finishes the frame in flight, whole. */
START_TEST(test_destroy_finishes) {
  sph_scene *scene;
  sph_sim *sim;
  sph_sink sink;
  char frames[300];
  open_async(&sink, "destroy", &scene, &sim, frames, sizeof frames);
  sph_error err;
  for (int k = 0; k < 2; ++k) {
    sph_frame fr = frame_of(sim, k);
    ck_assert_msg(sink.ops->write(&sink, &fr, &err) == SPH_OK, "%s",
                  err.message);
    if (k == 0) /* the render thread idle again: frame 1 is handed over */
      ck_assert(sink.ops->flush(&sink, &err) == SPH_OK);
  }
  sink.ops->destroy(&sink);
  char names[1024];
  int n = list_dir(frames, names, sizeof names);
  ck_assert_msg(n == 2 && strstr(names, "twisting_column_0000.png\n") &&
                    strstr(names, "twisting_column_0001.png\n"),
                "frames folder holds:\n%s", names);
  ck_assert(sink.thread_seconds > 0.0);
  sph_sim_destroy(sim);
  sph_scene_destroy(scene);
}
END_TEST

int main(void) {
  if (!mkdtemp(dir))
    return EXIT_FAILURE;
  Suite *s = suite_create("png_async");
  TCase *tc = tcase_create("png_async");
  tcase_set_timeout(tc, 600);
  tcase_add_test(tc, test_same_bytes_default);
  tcase_add_test(tc, test_same_bytes_cutaways);
  tcase_add_test(tc, test_thread_error);
  tcase_add_test(tc, test_destroy_finishes);
  suite_add_tcase(s, tc);
  int rc = sph_test_run(s);
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  if (system(cmd) != 0)
    rc = EXIT_FAILURE;
  return rc;
}
