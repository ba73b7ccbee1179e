/* Private to the PNG frame sink (render/png_sink.c and the files it is
 * split into: png_camera.c, png_frame.c, png_draw.c): the sink's state, one
 * frame as handed to the renderer, and the functions they share. */
#ifndef SPH_PNG_SINK_IMPL_H
#define SPH_PNG_SINK_IMPL_H

#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "gl_impl.h"
#include "overlay_impl.h"
#include "parallel/composite.h"
#include "parallel/domain.h"
#include "render/image.h"
#include "render/render.h"

/* Bins of the robust range's histogram (png_frame.c: hist_bin). */
#define PNG_HIST_BINS 65536u

/* One frame as the simulation thread hands it to the renderer. */
typedef struct png_frame {
  size_t m;      /* the kept particles (over ranks: this rank's) */
  uint32_t *key; /* over ranks: their particle ids (the serial draw order) */
  float *xyz;    /* the kept particles' current positions, in index order */
  float *scale;  /* their radius factors (J^(1/d)), or NULL without J */
  double *value; /* their colour values (NaN: none) */
  double lo, hi; /* colour range of this frame */
  double vmin, vmax; /* its finite values' extremes (over ranks: all) */
  double box_lo[3], box_hi[3]; /* the drawn particles' box (over ranks) */
  int clamped_low, clamped_high;
  sph_view view; /* the camera of this frame (follow) */
  double time;
  int index;
} png_frame;

typedef struct png_sink {
  /* fixed at open; read by both threads */
  sph_view view;
  char dir[1024], name[128], title[96];
  int width, height;
  sph_colormap_kind map;
  double dp;
  size_t nkeep;                          /* particles drawn (cut) */
  int clip, ghost;                       /* cutaway and outline flags */
  double plane[4];                       /* clip: -n, at */
  float *ghost_xyz;                      /* reference positions, kept ones */
  unsigned char *ghost_rim, *ghost_fill; /* their colours */
  /* simulation thread: field, range policy, the two snapshots */
  unsigned char *keep; /* cut: the particles drawn */
  int follow;          /* frame the bodies' extent over the whole run */
  int have_box;        /* follow: box_lo, box_hi hold some frame's box */
  double box_lo[3], box_hi[3]; /* follow: the drawn boxes' union so far */
  int time_decimals; /* of the time label: those of the output interval */
  int dim;           /* 2 or 3: the sphere radius factor is J^(1/dim) */
  int axes;          /* draw the axes triad */
  int scale_bar;     /* draw the scale bar */
  double fit_lo[3], fit_hi[3]; /* the box the camera frames */
  const sph_scene *scene;
  int field, ncomp;
  int have_range, mode; /* png_range */
  double centre;        /* diverging maps: the value at the middle */
  double lo, hi;        /* the run's range so far (grow-only) */
  double run_min, run_max, run_amax; /* the run's extremes so far */
  uint64_t *hist;     /* robust: the run's values (PNG_HIST_BINS bins) */
  uint64_t *hist_all; /* robust over MPI ranks: the sum over the ranks */
  png_frame slot[2];
  int next; /* the slot the next write fills */
  /* the frames' scratch file (png_store.c): drawn again at close */
  FILE *store;
  char store_path[1200];
  int deferred;          /* frames drawn only at close (sph render) */
  int redrawn;           /* frames drawn again at close */
  size_t nrec;           /* frames recorded */
  size_t forced;         /* the first records, taken back on resume: drawn
                            again at close whatever their range */
  double *boxes;         /* close, follow: every frame's box, then view's */
  double redraw_seconds; /* wall seconds close spent drawing them */
  /* renderer: only the render thread (or, without one, the caller) */
  sph_gl *gl;
  sph_text *text;
  sph_image img;
  unsigned char *rgb;
  /* hand-over between the threads, under mu */
  int threaded, locks_made, started;
  /* over MPI ranks (sort-last): each rank draws its particles, the tagged
   * images are composited onto rank 0, which writes the frame */
  sph_domain *domain; /* NULL: a serial run */
  int rank;
  size_t cap;            /* particles a rank may hold */
  double *cut_c;         /* cut: per body sums of X (3) and count */
  int cut_axis;          /* cut: the axis closest to the view */
  double cut_sign;       /* cut: its direction */
  int64_t *order;        /* (id, index) of each owned particle */
  sph_composite_px *cpx; /* rank 0: the composite */
  pthread_t thread;
  pthread_mutex_t mu;
  pthread_cond_t cv;
  int ready, quit;   /* renderer created (or failed); thread to exit */
  png_frame *queued; /* handed over and not yet written; NULL when idle */
  sph_status status; /* first unreported renderer error, and its record */
  sph_error error;
  double busy; /* render thread wall seconds spent on frames */
} png_sink;

typedef enum png_range {
  PNG_RANGE_ROBUST,
  PNG_RANGE_AUTO,
  PNG_RANGE_SYMMETRIC,
  PNG_RANGE_FIXED
} png_range;

static inline double png_dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* r = f x up, normalised; 0 when they are parallel */
static inline int png_right_of(const double f[3], const double up[3],
                               double r[3]) {
  r[0] = f[1] * up[2] - f[2] * up[1];
  r[1] = f[2] * up[0] - f[0] * up[2];
  r[2] = f[0] * up[1] - f[1] * up[0];
  double rl = sqrt(png_dot3(r, r));
  if (!(rl > 0.0))
    return 0;
  for (int k = 0; k < 3; ++k)
    r[k] /= rl;
  return 1;
}

/* The reference outline's colours: rim and fill (png_draw.c). */
extern const unsigned char sph_png_ghost_fill[3], sph_png_ghost_rim[3];

/* --- png_camera.c: the camera, the cutaways, the follow camera ---------- */

/* The frame's camera: a fit of the initial bodies' box (padded for the
 * motion, returned in lo, hi), or the scene's position/target/up with the
 * clip range and ortho height fitted to that box. */
void sph_png_view(const sph_sim *sim, sph_view *v, double lo[3], double hi[3]);
/* cut: half: per body sums of the reference positions and counts (*c, NULL
 * without a cut), the axis closest to the view direction and its sign. */
sph_status sph_png_cut_setup(const sph_sim *sim, const sph_view *v, double **c,
                             int *axis, double *sign, sph_error *err);
/* Whether the cut keeps particle a; every particle without a cut. */
int sph_png_cut_keeps(const double *c, int axis, double sign, double dp,
                      const double *X, const int32_t *body, size_t a);
/* The box of m positions (lo > hi when m is 0). */
void sph_png_box(const float *xyz, size_t m, double lo[3], double hi[3]);
/* The fitted camera framing the drawn box [lo, hi] (padded by a sphere's
 * radius and 2 % of each side). */
void sph_png_fit_box(const png_sink *p, const double lo[3], const double hi[3],
                     sph_view *v);
/* Follow camera: the drawn box [lo, hi] joins the run's union of boxes;
 * p->view is refitted to the union when it grew. */
void sph_png_follow(png_sink *p, const double box_lo[3],
                    const double box_hi[3]);

/* --- png_frame.c: snapshots, colour range, a resumed run's replay ------- */

/* A drawn value v joins the run's histogram (robust). */
void sph_png_hist_add(png_sink *p, double v);
/* The run's extremes widened by a frame's [vmin, vmax], the range
 * recomputed (all policies but fixed). */
void sph_png_range_update(png_sink *p, double vmin, double vmax);

/* Copies what frame fr needs into snapshot s and advances the range (frame
 * order, on the simulation thread). */
sph_status sph_png_snapshot(png_sink *p, const sph_frame *fr, png_frame *s,
                            sph_error *err);
/* The same over MPI ranks (collective). */
sph_status sph_png_snapshot_ranks(png_sink *p, const sph_frame *fr,
                                  png_frame *s, sph_error *err);
/* A resumed run's camera and range replayed from its .vtp files, and
 * (serial runs) its earlier frames recorded to be drawn again at close. */
sph_status sph_png_replay(png_sink *p, const sph_sim *sim, const char *dir,
                          int frames, sph_error *err);

/* --- png_draw.c: drawing and writing a frame, the render thread --------- */

/* Renders one snapshot into frames/<scene>_NNNN.png (render thread, or the
 * caller's without one). */
sph_status sph_png_render(png_sink *p, const png_frame *fr, sph_error *err);
/* The same over MPI ranks (collective, composited onto rank 0). */
sph_status sph_png_render_ranks(png_sink *p, const png_frame *fr,
                                sph_error *err);
/* The renderer's GL context and font, made on the thread that renders. */
sph_status sph_png_renderer_create(png_sink *p, sph_error *err);
void sph_png_renderer_destroy(png_sink *p);
/* A snapshot recorded in the scratch file, then drawn (unless deferred). */
sph_status sph_png_emit(png_sink *p, const png_frame *fr, sph_error *err);
/* The render thread's body (arg: the png_sink). */
void *sph_png_thread(void *arg);
/* Waits until every frame handed over is written; returns (and forgets) the
 * render thread's first unreported error. */
sph_status sph_png_wait(png_sink *p, sph_error *err);
/* Lets the render thread finish the frame in flight, then ends it. */
void sph_png_stop(png_sink *p);

/* --- png_store.c: the frames' scratch file, drawn again at close ------- */

/* Creates frames/.<scene>.frames (.pR over MPI ranks), replacing a killed
 * run's; resuming (resume_frames > 0), opens the stopped run's instead. */
sph_status sph_png_store_open(png_sink *p, int resume_frames, sph_error *err);
/* Resuming: the stopped run's records of frames 0 .. frames - 1 taken
 * back (range, camera, to be drawn again at close) and the rest dropped;
 * 0 when the file does not hold them all (then it is emptied). */
int sph_png_store_resume(png_sink *p, int frames, sph_error *err);
/* Appends frame fr (drawn: 0 when it is not drawn yet). */
sph_status sph_png_store_put(png_sink *p, const png_frame *fr, int drawn,
                             sph_error *err);
/* The run-wide colour range the frames show. */
void sph_png_final_range(const png_sink *p, double *lo, double *hi);
/* Draws again (on the calling thread) every frame drawn with another range
 * or camera than the final ones, then removes the file (keep: a stopped
 * run's is kept for --resume) (collective). */
sph_status sph_png_store_finish(png_sink *p, int keep, sph_error *err);
/* Closes and removes the file (after a failure). */
void sph_png_store_remove(png_sink *p);

#endif
