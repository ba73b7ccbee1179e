/* sph render RUN: the frames of a finished run drawn again from its .vtp
 * files with the renderer and options of `output.png`, without running the
 * simulation: the run's scene_used.yaml gives the particles, the camera and
 * the png block, --field/--range/--width/--height/--set change them, and
 * each data set of the .pvd becomes one frame in OUT/frames (the same file
 * names as `sph run`). `--range global` is the range over every frame. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/app_impl.h"
#include "io/sink.h"
#include "io/vtk_read.h"
#include "render/render.h"
#include "scene/scene.h"
#include "solver/sim.h"

static const char *const render_usage =
    "usage: sph render RUN_DIR|RUN_DIR/<scene>.pvd [--field F] "
    "[--range robust|auto|symmetric|global|MIN,MAX]\n"
    "                  [--width W] [--height H] [--set output.png.KEY=V]... "
    "[--out DIR] [--mp4]\n"
    "  draw a finished run's frames again from its .vtp files (default "
    "OUT: RUN_DIR/render)\n";

#define RENDER_MAX_SETS (SPH_MAX_SETS - 8)

typedef struct render_args {
  const char *run, *out, *field, *range;
  int width, height, mp4;
  const char *sets[SPH_MAX_SETS];
  size_t nsets;
} render_args;

static int render_option(void *ctx, int id, const char *val) {
  render_args *a = ctx;
  switch (id) {
  case SPH_OPT_OUT:
    a->out = val;
    return SPH_EXIT_OK;
  case SPH_OPT_FIELD:
    a->field = val;
    return SPH_EXIT_OK;
  case SPH_OPT_RANGE:
    a->range = val;
    return SPH_EXIT_OK;
  case SPH_OPT_WIDTH:
    return sph_app_count("render", "--width", val, 16384, &a->width);
  case SPH_OPT_HEIGHT:
    return sph_app_count("render", "--height", val, 16384, &a->height);
  case SPH_OPT_MP4:
    a->mp4 = 1;
    return SPH_EXIT_OK;
  case SPH_OPT_SET:
    if (a->nsets >= RENDER_MAX_SETS) {
      fprintf(stderr, "sph render: more than %d --set options\n",
              RENDER_MAX_SETS);
      return SPH_EXIT_USAGE;
    }
    a->sets[a->nsets++] = val;
    return SPH_EXIT_OK;
  default:
    return SPH_EXIT_USAGE;
  }
}

static int render_operand(void *ctx, const char *arg) {
  render_args *a = ctx;
  if (a->run) {
    fprintf(stderr, "sph render: more than one run given (%s, %s)\n", a->run,
            arg);
    return SPH_EXIT_USAGE;
  }
  a->run = arg;
  return SPH_EXIT_OK;
}

/* The run's folder and .pvd from RUN (a folder, or its .pvd). */
static int run_paths(const char *run, char *dir, size_t dsize, char *pvd,
                     size_t psize, const char *scene_name) {
  size_t len = strlen(run);
  if (len > 4 && !strcmp(run + len - 4, ".pvd")) {
    snprintf(pvd, psize, "%s", run);
    const char *slash = strrchr(run, '/');
    if (slash)
      snprintf(dir, dsize, "%.*s", (int)(slash - run), run);
    else
      snprintf(dir, dsize, ".");
    return 0;
  }
  snprintf(dir, dsize, "%s", run);
  if (scene_name)
    snprintf(pvd, psize, "%s/%s.pvd", run, scene_name);
  return 0;
}

/* --range and --field as scene overrides; the png block switched on */
static int add_overrides(render_args *a, char buf[4][96], int png_on) {
  size_t k = 0;
  const char *extra[4];
  if (!png_on)
    extra[k++] = "output.png={}";
  if (a->field) {
    snprintf(buf[0], sizeof buf[0], "output.png.color=%s", a->field);
    extra[k++] = buf[0];
  }
  if (a->range && strcmp(a->range, "global")) {
    if (strchr(a->range, ','))
      snprintf(buf[1], sizeof buf[1], "output.png.range=[%s]", a->range);
    else
      snprintf(buf[1], sizeof buf[1], "output.png.range=%s", a->range);
    extra[k++] = buf[1];
  }
  if (a->width) {
    snprintf(buf[2], sizeof buf[2], "output.png.width=%d", a->width);
    extra[k++] = buf[2];
  }
  if (a->height) {
    snprintf(buf[3], sizeof buf[3], "output.png.height=%d", a->height);
    extra[k++] = buf[3];
  }
  /* the user's --set come last and win */
  memmove(a->sets + k, a->sets, a->nsets * sizeof *a->sets);
  memcpy(a->sets, extra, k * sizeof *extra);
  a->nsets += k;
  return 0;
}

typedef struct render_job {
  sph_scene *scene;
  sph_particles *ps;
  sph_pvd pvd;
  char dir[1024], out[1100];
  /* a run over MPI ranks: particle k of the pieces is particle order[k]
   * (NULL: the files' order is the particles') and room to place them */
  size_t *order;
  double *scratch;
} render_job;

static sph_status vtp_path(const render_job *j, int i, char *path, size_t n,
                           sph_error *err) {
  if ((size_t)snprintf(path, n, "%s/%s", j->dir, j->pvd.file[i]) >= n)
    return sph_error_set(err, SPH_ERR_ARG, "path too long: %s/%s", j->dir,
                         j->pvd.file[i]);
  return SPH_OK;
}

static const double *sort_x;
static int cmp_point(const void *pa, const void *pb) {
  const double *a = sort_x + 3 * *(const size_t *)pa,
               *b = sort_x + 3 * *(const size_t *)pb;
  for (int c = 0; c < 3; ++c)
    if (a[c] != b[c])
      return a[c] < b[c] ? -1 : 1;
  return 0;
}

/* positions sorted: idx of n points of x */
static void sort_points(const double *x, size_t *idx, size_t n) {
  for (size_t k = 0; k < n; ++k)
    idx[k] = k;
  sort_x = x;
  qsort(idx, n, sizeof *idx, cmp_point);
}

/* A run over MPI ranks without particle_id lists each rank's particles in
 * its pieces: frame 0's positions, the particles' initial ones, say which
 * is which (the points sorted both ways must be equal, one by one, and
 * distinct); otherwise the files' order is kept. */
static sph_status piece_order(render_job *j, sph_error *err) {
  size_t n = j->ps->n, len = strlen(j->pvd.file[0]);
  if (n == 0 || len < 5 || strcmp(j->pvd.file[0] + len - 5, ".pvtp"))
    return SPH_OK;
  char path[1400];
  double t;
  SPH_TRY(vtp_path(j, 0, path, sizeof path, err));
  double *x = malloc(3 * n * sizeof *x);
  size_t *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
  j->order = malloc(n * sizeof *j->order);
  j->scratch = malloc(3 * n * sizeof *j->scratch);
  if (!x || !a || !b || !j->order || !j->scratch) {
    free(x), free(a), free(b);
    return sph_error_set(err, SPH_ERR_NOMEM, "reading %s", path);
  }
  sph_status st = sph_vtp_read(path, n, x, NULL, 1, NULL, &t, err);
  const double *X = j->ps->field[SPH_FIELD_POSITION0];
  int ok = st == SPH_OK && X, moved = 0;
  if (ok) {
    sort_points(x, a, n);
    sort_points(X, b, n);
  }
  for (size_t k = 0; ok && k < n; ++k) {
    ok = !memcmp(x + 3 * a[k], X + 3 * b[k], 3 * sizeof *x) &&
         (k == 0 || memcmp(x + 3 * a[k], x + 3 * a[k - 1], 3 * sizeof *x));
    j->order[a[k]] = b[k];
    moved |= a[k] != b[k];
  }
  if (!ok || !moved) { /* the files' order */
    free(j->order);
    j->order = NULL;
  }
  free(x), free(a), free(b);
  return st;
}

/* frame i's points and field `name` (nc components) in the particles'
 * order */
static sph_status read_frame(render_job *j, int i, const char *name, int nc,
                             double *values, double *t, sph_error *err) {
  char path[1400];
  size_t n = j->ps->n;
  double *x = j->ps->field[SPH_FIELD_POSITION];
  SPH_TRY(vtp_path(j, i, path, sizeof path, err));
  SPH_TRY(sph_vtp_read(path, n, x, name, nc, values, t, err));
  if (!j->order)
    return SPH_OK;
  for (int pass = 0; pass < (name ? 2 : 1); ++pass) {
    double *v = pass ? values : x;
    size_t w = pass ? (size_t)nc : 3;
    memcpy(j->scratch, v, w * n * sizeof *v);
    for (size_t k = 0; k < n; ++k)
      memcpy(v + w * j->order[k], j->scratch + w * k, w * sizeof *v);
  }
  return SPH_OK;
}

/* the range over every frame (centred like the map: pressure about 0, J
 * about 1) */
static sph_status global_range(render_job *j, int field, sph_error *err) {
  sph_particles *ps = j->ps;
  int nc = sph_field_components((sph_field)field);
  double c = nc == 1 ? sph_png_field_centre(field) : NAN;
  double lo = INFINITY, hi = -INFINITY, amax = 0.0, t;
  for (int i = 0; i < j->pvd.count; ++i) {
    SPH_TRY(read_frame(j, i, sph_field_name((sph_field)field), nc,
                       ps->field[field], &t, err));
    for (size_t a = 0; a < ps->n; ++a) {
      double v = sph_png_value(ps->field[field], nc, a);
      if (!isfinite(v))
        continue;
      lo = fmin(lo, v);
      hi = fmax(hi, v);
      if (isfinite(c))
        amax = fmax(amax, fabs(v - c));
    }
  }
  sph_png_output *o = &j->scene->output.png;
  if (isfinite(c) && amax > 0.0) {
    lo = c - amax;
    hi = c + amax;
  }
  if (!(hi > lo)) { /* a field that never varies */
    lo = isfinite(lo) ? lo - 1.0 : -1.0;
    hi = lo + 2.0;
  }
  snprintf(o->range_mode, sizeof o->range_mode, "fixed");
  o->range[0] = lo;
  o->range[1] = hi;
  return SPH_OK;
}

/* every data set of the .pvd through the png sink */
static sph_status render_frames(render_job *j, int *frames, sph_error *err) {
  sph_scene *s = j->scene;
  sph_particles *ps = j->ps;
  int field = s->output.png.color_field;
  int nc = sph_field_components((sph_field)field);
  sph_sim sim = {0};
  sim.scene = s;
  sim.ps = ps;
  sim.dp = sph_scene_min_spacing(s);
  sim.threads = 1;
  SPH_TRY(sph_png_check(&sim, err));
  sph_sink sink = {.ops = &sph_png_sink_batch_ops};
  sph_status st = sink.ops->open(&sink, &sim, j->out, err);
  for (int i = 0; st == SPH_OK && i < j->pvd.count; ++i) {
    double t;
    st = read_frame(j, i, sph_field_name((sph_field)field), nc,
                    ps->field[field], &t, err);
    /* J sizes the spheres as in the run (the sink's V0 J) */
    if (st == SPH_OK && ps->field[SPH_FIELD_JACOBIAN] &&
        field != SPH_FIELD_JACOBIAN)
      st = read_frame(j, i, "J", 1, ps->field[SPH_FIELD_JACOBIAN], &t, err);
    sph_frame fr = {.time = isfinite(t) ? t : j->pvd.time[i],
                    .index = i,
                    .sim = &sim,
                    .ps = ps};
    if (st == SPH_OK)
      st = sink.ops->write(&sink, &fr, err);
    if (st == SPH_OK)
      *frames = i + 1;
  }
  sph_error cerr;
  sph_status cst = sink.ops->close(&sink, &cerr);
  if (st == SPH_OK && cst != SPH_OK) {
    st = cst;
    *err = cerr;
  }
  sink.ops->destroy(&sink);
  return st;
}

/* after a failure: the frames written, and the folders when they are
 * empty (the output folder only when this render made it) */
static void remove_frames(const render_job *j, int frames, int made) {
  char path[1400];
  for (int i = 0; i < frames; ++i) {
    snprintf(path, sizeof path, "%s/frames/%s_%04d.png", j->out, j->scene->name,
             i);
    remove(path);
  }
  snprintf(path, sizeof path, "%s/frames", j->out);
  rmdir(path);
  if (made)
    rmdir(j->out);
}

static sph_status render_run(render_args *a, int *frames, sph_error *err) {
  render_job j;
  memset(&j, 0, sizeof j);
  char scene_path[1100], pvd[1100] = "";
  run_paths(a->run, j.dir, sizeof j.dir, pvd, sizeof pvd, NULL);
  snprintf(scene_path, sizeof scene_path, "%s/scene_used.yaml", j.dir);
  /* first the run's own scene, to know its name and png block */
  sph_scene *first = NULL;
  sph_status st = sph_scene_load(&first, scene_path, NULL, 0, err);
  if (st != SPH_OK)
    return st;
  if (!pvd[0])
    run_paths(a->run, j.dir, sizeof j.dir, pvd, sizeof pvd, first->name);
  char buf[4][96];
  add_overrides(a, buf, first->output.png.enabled);
  sph_scene_destroy(first);
  st = sph_scene_load(&j.scene, scene_path, a->sets, a->nsets, err);
  if (st == SPH_OK && !j.scene->output.png.enabled)
    st = sph_error_set(err, SPH_ERR_ARG, "output.png is off");
  if (st == SPH_OK) /* the particles and frames fit, as sph run checks */
    st = sph_sim_check_memory(j.scene, err);
  if (st == SPH_OK)
    st = sph_pvd_read(pvd, &j.pvd, err);
  if (st == SPH_OK)
    st = sph_scene_build_particles(j.scene, &j.ps, err);
  int field = st == SPH_OK ? j.scene->output.png.color_field : 0;
  if (st == SPH_OK)
    st = sph_particles_require(j.ps, SPH_FIELD_POSITION, err);
  if (st == SPH_OK)
    st = sph_particles_require(j.ps, (sph_field)field, err);
  if (st == SPH_OK && j.pvd.count > 0)
    st = piece_order(&j, err);
  /* the files' J, when they hold it, sizes the spheres as the run did */
  if (st == SPH_OK && j.pvd.count > 0) {
    double t;
    sph_error jerr;
    if (sph_particles_require(j.ps, SPH_FIELD_JACOBIAN, &jerr) == SPH_OK &&
        read_frame(&j, 0, "J", 1, j.ps->field[SPH_FIELD_JACOBIAN], &t, &jerr) !=
            SPH_OK) {
      free(j.ps->field[SPH_FIELD_JACOBIAN]);
      j.ps->field[SPH_FIELD_JACOBIAN] = NULL;
    }
  }
  if (st == SPH_OK && a->range && !strcmp(a->range, "global"))
    st = global_range(&j, field, err);
  struct stat before;
  int made = 0; /* the output folder is ours: removed again on failure */
  if (st == SPH_OK) {
    if (a->out)
      snprintf(j.out, sizeof j.out, "%s", a->out);
    else
      snprintf(j.out, sizeof j.out, "%s/render", j.dir);
    made = stat(j.out, &before) != 0;
    st = sph_run_output_dir(j.out, err);
  }
  if (st == SPH_OK)
    st = render_frames(&j, frames, err);
  if (st != SPH_OK && j.out[0]) /* nothing left behind (issue 36) */
    remove_frames(&j, *frames, made);
  if (st == SPH_OK &&
      (a->mp4 == 1 || (a->mp4 < 0 && j.scene->output.png.mp4))) {
    sph_mp4_info info = {0};
    sph_error merr;
    sph_status mst = sph_mp4_assemble(j.out, j.scene->name, *frames,
                                      j.scene->output.png.fps, &info, &merr);
    if (mst == SPH_OK)
      printf("mp4: %s (%d frames, %.1f s at %g fps, %s)\n", info.path,
             info.frames, info.frames / info.fps, info.fps, info.codec);
    else if (mst == SPH_ERR_UNSUPPORTED)
      printf("mp4 skipped: ffmpeg not found\n");
    else {
      st = mst;
      *err = merr;
    }
  }
  if (st == SPH_OK)
    printf("rendered %d frames of %s into %s/frames\n", *frames, pvd, j.out);
  sph_pvd_destroy(&j.pvd);
  free(j.order);
  free(j.scratch);
  sph_particles_destroy(j.ps);
  sph_scene_destroy(j.scene);
  return st;
}

int sph_cmd_render(int argc, char **argv) {
  static const int allowed[] = {
      SPH_OPT_OUT,    SPH_OPT_FIELD, SPH_OPT_RANGE, SPH_OPT_WIDTH,
      SPH_OPT_HEIGHT, SPH_OPT_MP4,   SPH_OPT_SET,   0};
  const sph_app_command cmd = {"render", render_usage, allowed, render_option,
                               render_operand};
  render_args a = {0};
  a.mp4 = -1; /* the scene's own mp4 setting unless --mp4 */
  int rc = sph_app_getopt(&cmd, argc, argv, &a);
  if (rc == SPH_APP_HELP)
    return SPH_EXIT_OK;
  if (rc != SPH_EXIT_OK)
    return rc;
  if (!a.run) {
    fprintf(stderr, "sph render: no run folder given\n%s", render_usage);
    return SPH_EXIT_USAGE;
  }
  sph_error err;
  sph_error_clear(&err);
  int frames = 0;
  sph_status st = render_run(&a, &frames, &err);
  if (st == SPH_OK)
    return SPH_EXIT_OK;
  sph_app_print_error(&err);
  /* a missing or damaged .vtp or .pvd is bad input, as is an output
   * folder that cannot be made or written in */
  return st == SPH_ERR_NOMEM ? SPH_EXIT_IO : SPH_EXIT_USAGE;
}
