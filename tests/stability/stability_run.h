/* The stability suites' driver: runs a shipped scene with overrides through
 * the run (src/solver/run.h, writing no files), its output frames every
 * `every` seconds where the verdict observes them as at `sph run`'s output
 * times, and prints one line of the measured indicators. */
#ifndef SPH_STABILITY_RUN_H
#define SPH_STABILITY_RUN_H

#include "test_util.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "scene/scene.h"
#include "solver/run.h"
#include "solver/sim.h"
#include "solver/stability.h"

typedef struct outcome {
  int stable, nan;
  char reason[256];
  double t;         /* time reached (the trip time of an unstable run) */
  double t_tripped; /* NaN when stable */
  sph_indicator first;
  double tripped_at[SPH_INDICATOR_COUNT]; /* NaN: did not trip */
  double cb_mean, cb_max, j_min, e0, e1, e_max;
  double stretch_max; /* largest initially adjacent distance over frames, dp */
  long pairs_over;    /* most pairs beyond stability.fracture_dp */
  double fracture_dp; /* the threshold the run used (0: not judged) */
  double zigzag_max, zigzag_end; /* NaN when never measured */
  double zigzag_threshold;
  int frames;
  double wall; /* seconds */
} outcome;

/* called at every observed frame, after method->derive */
typedef void (*frame_hook)(sph_sim *sim, void *ctx);

typedef struct frames_seen {
  frame_hook hook;
  void *ctx;
  double sum; /* of the checkerboard indicator after the first frame */
  int frames;
} frames_seen;

static inline void on_frame(sph_run *run, const sph_frame *fr, void *ctx) {
  frames_seen *f = ctx;
  if (f->hook)
    f->hook(sph_run_sim(run), f->ctx);
  if (f->frames++ > 0) /* the state at rest has no pressure to judge */
    f->sum += sph_run_verdict(run)->checkerboard;
}

static inline void outcome_fill(outcome *o, const sph_verdict *v,
                                const sph_sim *sim, const frames_seen *f) {
  o->stable = v->stable;
  o->nan = v->nan;
  snprintf(o->reason, sizeof o->reason, "%s", v->reason);
  o->t = sim->t;
  o->t_tripped = v->stable ? NAN : v->t_tripped;
  o->first = v->first;
  memcpy(o->tripped_at, v->tripped_at, sizeof o->tripped_at);
  o->cb_mean = f->frames > 1 ? f->sum / (f->frames - 1) : 0.0;
  o->cb_max = v->checkerboard_max;
  o->j_min = v->J_min;
  o->e0 = v->energy0;
  o->e1 = v->energy_final;
  o->e_max = v->energy_max;
  o->stretch_max = v->fracture_peak_stretch;
  o->pairs_over = v->fracture_peak_over;
  o->fracture_dp = v->fracture_dp;
  o->zigzag_max = v->zigzag_max;
  o->zigzag_end = v->zigzag;
  o->zigzag_threshold = v->zigzag_threshold;
  o->frames = v->frames;
}

/* runs scenes/<name>.yaml with overrides, observing every `every` s, to
 * the end time or, unless keep_going, the first indicator that trips */
static inline outcome run_frames(const char *name, const char *const *sets,
                                 size_t nsets, double every, frame_hook hook,
                                 void *ctx, int keep_going) {
  char path[512];
  snprintf(path, sizeof path, "%s/scenes/%s.yaml", SPH_SOURCE_DIR, name);
  struct timespec w0, w1;
  clock_gettime(CLOCK_MONOTONIC, &w0);
  sph_scene *s;
  sph_run *run;
  sph_error err;
  ck_assert_msg(sph_scene_load(&s, path, sets, nsets, &err) == SPH_OK, "%s",
                err.message);
  frames_seen f = {hook, ctx, 0.0, 0};
  sph_run_options opt = {.no_files = 1};
  sph_run_hooks hooks = {
      .ctx = &f, .frame = on_frame, .every = every, .keep_going = keep_going};
  ck_assert_msg(sph_run_create_hooked(&run, s, &opt, &hooks, &err) == SPH_OK,
                "%s", err.message);
  ck_assert_msg(sph_run_advance(run, sph_scene_end_time(s), &err) == SPH_OK,
                "%s", err.message);
  clock_gettime(CLOCK_MONOTONIC, &w1);
  outcome o = {0};
  outcome_fill(&o, sph_run_verdict(run), sph_run_sim(run), &f);
  o.wall = (double)(w1.tv_sec - w0.tv_sec) + 1e-9 * (w1.tv_nsec - w0.tv_nsec);
  sph_run_destroy(run);
  sph_scene_destroy(s);
  return o;
}

static inline outcome run_case(const char *name, const char *const *sets,
                               size_t nsets, double every, frame_hook hook,
                               void *ctx) {
  return run_frames(name, sets, nsets, every, hook, ctx, 0);
}

/* one line: the verdict, the indicators, then the case's own figures */
static inline void show(const char *label, const outcome *o, const char *fmt,
                        ...) {
  char extra[512] = "";
  if (fmt) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(extra, sizeof extra, fmt, ap);
    va_end(ap);
  }
  printf("%-32s %s t = %.4g  checkerboard mean %.3f max %.3f  J min %.3f  "
         "energy %.4g -> %.4g (max %.4g)  stretch %.3g dp (limit %g)  "
         "zig-zag max %.3f (limit %g)  %.1f s wall%s%s%s%s\n",
         label, o->stable ? "stable  " : "UNSTABLE", o->t, o->cb_mean,
         o->cb_max, o->j_min, o->e0, o->e1, o->e_max, o->stretch_max,
         o->fracture_dp, o->zigzag_max, o->zigzag_threshold, o->wall,
         extra[0] ? "  " : "", extra, o->stable ? "" : "  ", o->reason);
  fflush(stdout);
}

static inline outcome run(const char *name, const char *const *sets,
                          size_t nsets, double every) {
  outcome o = run_case(name, sets, nsets, every, NULL, NULL);
  show(name, &o, NULL);
  return o;
}

/* the particle nearest to (x, y, z) in the reference configuration */
static inline size_t nearest_particle(const sph_particles *ps, double x,
                                      double y, double z) {
  size_t best = 0;
  double d2 = INFINITY;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  for (size_t a = 0; a < ps->n; ++a) {
    double dx = X[3 * a] - x, dy = X[3 * a + 1] - y, dz = X[3 * a + 2] - z;
    double d = dx * dx + dy * dy + dz * dz;
    if (d < d2) {
      d2 = d;
      best = a;
    }
  }
  return best;
}

#endif
