/* PNG frame sink: every output time, the particles as lit spheres (OSMesa,
 * gl.c) coloured by the scene's `output.png.color` field, with a colour bar,
 * the field name and units, the scene name and the time composited on the
 * CPU (colorbar.c, text.c), written to frames/<scene>_NNNN.png.
 *
 * Colour: the field chooses the map unless `colormap` is given: pressure
 * (signed about 0) and J (about 1) the diverging cool-to-warm map centred
 * on that value, every other field (von Mises, density, vector and tensor
 * magnitudes) viridis over its own range. Range policy: `robust` (the
 * default) per frame, the 1st to 99th percentile of the frame's values
 * (centre +- the 99th percentile of |f - centre| for a diverging map), so a
 * few extreme particles (clamp corners, a punch edge) or an early transient
 * do not wash the other frames out; `fixed [min, max]` as given;
 * `symmetric` centre +- max |f - centre| and `auto` [min, max] grow-only: a
 * frame widens the range when its values exceed it and never narrows it. A
 * run-wide `global` range needs every frame first; in a run it behaves as
 * `auto`. NaN values get the map's own NaN colour. The
 * camera frames the bodies' initial bounding box, enlarged by 10 % on each
 * side for the motion, unless the scene gives a position (then the clip
 * range and ortho height are fitted to that box seen from there).
 *
 * Cutaways: `clip` keeps the particles with n . x <= at (current position,
 * the GL clip plane, whole spheres); `cut: half` keeps, per body, the
 * particles whose reference position lies behind the body's reference
 * centroid along the axis closest to the view direction, so the cut face
 * looks at the camera.
 * `ghost` paints the reference configuration as a grey outlined silhouette
 * under the current state. The block's keys, defaults and value checks are
 * the sink's own schema (png_schema.c, read when the scene loads);
 * sph_png_check validates the picture they give before a run.
 * Created only when the scene has a `png` block.
 *
 * Threading: `write` runs on the simulation thread only as long as it takes
 * to copy the kept particles' positions and colour values into one of two
 * snapshots allocated at `open` and to advance the range (in frame order,
 * so the colours never depend on timing); a render thread owned by the sink
 * makes the one OSMesa context current, draws, composites and writes the
 * frame. One frame is in flight: `write` waits only while the frame before
 * is still being rendered; `flush` and `close` wait for every frame handed
 * over. The render thread's first error (naming the frame's file) is
 * returned by the next write, flush or close. sph_png_sink_sync_ops
 * (sph/render.h) renders on the calling thread instead. */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gl_impl.h"
#include "io/vtk_read.h"
#include "overlay_impl.h"
#include "parallel/composite.h"
#include "parallel/domain.h"
#include "render/image.h"
#include "render/png_schema.h"
#include "render/render.h"
#include "scene/geometry.h"

/* One frame as the simulation thread hands it to the renderer. */
typedef struct png_frame {
  size_t m;      /* the kept particles (over ranks: this rank's) */
  uint32_t *key; /* over ranks: their particle ids (the serial draw order) */
  float *xyz;    /* the kept particles' current positions, in index order */
  float *scale;  /* their radius factors (J^(1/d)), or NULL without J */
  double *value; /* their colour values (NaN: none) */
  double lo, hi; /* colour range of this frame */
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
  int follow;          /* refit the camera to the current bodies */
  int time_decimals;   /* of the time label: those of the output interval */
  int dim;             /* 2 or 3: the sphere radius factor is J^(1/dim) */
  int axes;            /* draw the axes triad */
  int scale_bar;       /* draw the scale bar */
  double fit_lo[3], fit_hi[3]; /* the box the camera frames */
  const sph_scene *scene;
  int field, ncomp;
  int have_range, mode; /* png_range */
  double centre;        /* diverging maps: the value at the middle */
  double lo, hi;
  double *work; /* robust: the frame's finite values (n) */
  png_frame slot[2];
  int next; /* the slot the next write fills */
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

/* The k-th smallest of v[0..n) (Hoare's selection; v is reordered). */
static double select_kth(double *v, size_t n, size_t k) {
  size_t lo = 0, hi = n - 1;
  while (lo < hi) {
    double pivot = v[lo + (hi - lo) / 2];
    size_t i = lo, j = hi;
    while (i <= j) {
      while (v[i] < pivot)
        ++i;
      while (v[j] > pivot)
        --j;
      if (i <= j) {
        double t = v[i];
        v[i] = v[j];
        v[j] = t;
        ++i;
        if (j == 0)
          break;
        --j;
      }
    }
    if (k <= j)
      hi = j;
    else if (k >= i)
      lo = i;
    else
      break;
  }
  return v[k];
}

double sph_png_field_centre(int field) {
  return field == SPH_FIELD_PRESSURE   ? 0.0
         : field == SPH_FIELD_JACOBIAN ? 1.0
                                       : NAN;
}

double sph_png_value(const double *f, int nc, size_t a) {
  if (nc == 1)
    return f[a];
  double s = 0.0;
  for (int c = 0; c < nc; ++c)
    s += f[(size_t)nc * a + c] * f[(size_t)nc * a + c];
  return sqrt(s);
}

static double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* r = f x up, normalised; 0 when they are parallel */
static int right_of(const double f[3], const double up[3], double r[3]) {
  r[0] = f[1] * up[2] - f[2] * up[1];
  r[1] = f[2] * up[0] - f[0] * up[2];
  r[2] = f[0] * up[1] - f[1] * up[0];
  double rl = sqrt(dot3(r, r));
  if (!(rl > 0.0))
    return 0;
  for (int k = 0; k < 3; ++k)
    r[k] /= rl;
  return 1;
}

/* Share of the frame kept free of particles for the colour bar (right) and
 * the label block (top) when the camera is fitted. */
#define PNG_BAR_SHARE 0.2
#define PNG_LABEL_SHARE 0.12

/* A fitted camera framing [lo, hi] in the part of the frame left of the
 * colour bar and below the label block (same scale as sph_view_fit's, the
 * view moved so the box sits in the middle of that part). */
static void png_fit(const sph_scene *s, const double lo[3], const double hi[3],
                    sph_view *v) {
  const sph_png_output *o = &s->output.png;
  const sph_camera *c = &o->camera;
  const double deg = 3.14159265358979323846 / 180.0;
  int W = o->width, H = o->height;
  int we = (int)((1.0 - PNG_BAR_SHARE) * W),
      he = (int)((1.0 - PNG_LABEL_SHARE) * H);
  sph_view_fit(lo, hi, c->given ? c->azimuth : 30.0,
               c->given ? c->elevation : 20.0, c->given ? c->zoom : 1.0,
               c->given ? c->orthographic : 0, s->dimension, we, he, v);
  double f[3], r[3], dist = 0.0;
  for (int k = 0; k < 3; ++k) {
    f[k] = v->target[k] - v->eye[k];
    dist += f[k] * f[k];
  }
  dist = sqrt(dist);
  if (!(dist > 0.0))
    return;
  /* the whole frame at the fitted scale */
  double wpp; /* world units per pixel at the target */
  if (v->ortho) {
    v->ortho_height *= (double)H / he;
    wpp = v->ortho_height / H;
  } else {
    double t = tan(0.5 * v->fovy_deg * deg) * H / he;
    v->fovy_deg = 2.0 * atan(t) / deg;
    wpp = 2.0 * dist * t / H;
  }
  /* move the camera right and up: the box to the left and down */
  if (!right_of(f, v->up, r))
    return;
  double right = 0.5 * (W - we) * wpp, up = 0.5 * (H - he) * wpp;
  for (int k = 0; k < 3; ++k) {
    double d = right * r[k] + up * v->up[k];
    v->eye[k] += d;
    v->target[k] += d;
  }
}

/* [lo, hi] padded for the motion: half a spacing and 10 % of each side */
static void png_pad(double dp, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; ++k) {
    double pad = 0.5 * dp + 0.1 * (hi[k] - lo[k]);
    lo[k] -= pad;
    hi[k] += pad;
  }
}

/* The frame's camera: a fit of the initial bodies' box (padded for the
 * motion, returned in lo, hi), or the scene's position/target/up with the
 * clip range and ortho height fitted to that box. */
static void png_view(const sph_sim *sim, sph_view *v, double lo[3],
                     double hi[3]) {
  const sph_scene *s = sim->scene;
  const sph_png_output *o = &s->output.png;
  const sph_camera *c = &o->camera;
  for (int k = 0; k < 3; ++k) {
    lo[k] = INFINITY;
    hi[k] = -INFINITY;
  }
  const double *X = sim->ps->field[SPH_FIELD_POSITION0];
  for (size_t a = 0; a < sim->ps->n; ++a)
    for (int k = 0; k < 3; ++k) {
      lo[k] = fmin(lo[k], X[3 * a + k]);
      hi[k] = fmax(hi[k], X[3 * a + k]);
    }
  sph_domain_minmax(sim->domain, lo, hi, 3); /* over the ranks */
  png_pad(sim->dp, lo, hi);
  if (!(c->given && c->has_position)) {
    png_fit(s, lo, hi, v);
    return;
  }
  sph_view_fit(lo, hi, c->azimuth, c->elevation, c->zoom, c->orthographic,
               s->dimension, o->width, o->height, v);
  memcpy(v->eye, c->position, sizeof c->position);
  memcpy(v->target, c->target, sizeof c->target);
  memcpy(v->up, c->up, sizeof c->up);
  /* basis of the given camera; a degenerate one is left to sph_view_check */
  double f[3], r[3], u[3];
  for (int k = 0; k < 3; ++k)
    f[k] = v->target[k] - v->eye[k];
  double fl = sqrt(dot3(f, f));
  if (!(fl > 0.0))
    return;
  for (int k = 0; k < 3; ++k)
    f[k] /= fl;
  if (!right_of(f, v->up, r))
    return;
  u[0] = r[1] * f[2] - r[2] * f[1];
  u[1] = r[2] * f[0] - r[0] * f[2];
  u[2] = r[0] * f[1] - r[1] * f[0];
  /* depth range and half height of the box's corners seen from the eye */
  double dmin = INFINITY, dmax = -INFINITY, half = 0.0;
  double aspect = (double)o->width / o->height;
  for (int i = 0; i < 8; ++i) {
    double q[3] = {i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1],
                   i & 4 ? hi[2] : lo[2]};
    double e[3] = {q[0] - v->eye[0], q[1] - v->eye[1], q[2] - v->eye[2]};
    double t[3] = {q[0] - v->target[0], q[1] - v->target[1],
                   q[2] - v->target[2]};
    dmin = fmin(dmin, dot3(e, f));
    dmax = fmax(dmax, dot3(e, f));
    half = fmax(half, fmax(fabs(dot3(t, u)), fabs(dot3(t, r)) / aspect));
  }
  /* only what lies in front of the eye, in either projection */
  double pad = 0.05 * (dmax - dmin) + sim->dp;
  if (v->ortho && half > 0.0)
    v->ortho_height = 2.0 * 1.05 * half / (c->zoom > 0.0 ? c->zoom : 1.0);
  if (dmax + pad > 0.0) {
    v->far_clip = dmax + pad;
    v->near_clip = fmax(dmin - pad, v->ortho ? 0.0 : 1e-3 * v->far_clip);
  }
}

/* cut: half: per body, the sums of the reference positions and the
 * particle count (*c, 4 per body; over MPI ranks summed in rank order, the
 * centroid then equal to the serial one to round-off, far inside the
 * keeping tolerance), the coordinate axis closest to the view direction
 * and its sign; *c NULL without a cut. */
static sph_status cut_setup(const sph_sim *sim, const sph_view *v, double **c,
                            int *axis, double *sign, sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_particles *ps = sim->ps;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  *c = NULL;
  if (!s->output.png.cut_half)
    return SPH_OK;
  size_t nb = s->nbodies ? s->nbodies : 1;
  double *cs = calloc(4 * nb, sizeof *cs);
  if (!cs)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  for (size_t a = 0; a < ps->n; ++a) {
    double *cb = cs + 4 * ps->body[a];
    for (int k = 0; k < 3; ++k)
      cb[k] += X[3 * a + k];
    cb[3] += 1.0;
  }
  for (size_t b = 0; sim->domain && b < nb; ++b)
    sph_domain_sum(sim->domain, cs + 4 * b, 4);
  *axis = 0;
  double f[3];
  for (int k = 0; k < 3; ++k) {
    f[k] = v->target[k] - v->eye[k];
    *axis = fabs(f[k]) > fabs(f[*axis]) ? k : *axis;
  }
  *sign = f[*axis] < 0.0 ? -1.0 : 1.0;
  *c = cs;
  return SPH_OK;
}

/* Whether the cut keeps particle a (reference positions X, bodies body):
 * it lies behind its body's reference centroid (a flat cut face on lattice
 * bodies, looking at the camera); every particle without a cut. */
static int cut_keeps(const double *c, int axis, double sign, double dp,
                     const double *X, const int32_t *body, size_t a) {
  if (!c)
    return 1;
  const double *cb = c + 4 * body[a];
  return sign * (X[3 * a + axis] - cb[axis] / cb[3]) >= -1e-6 * dp;
}

/* keep[a] for each particle of sim (collective over MPI ranks). */
static sph_status cut_mask(const sph_sim *sim, const sph_view *v,
                           unsigned char *keep, sph_error *err) {
  const sph_particles *ps = sim->ps;
  double *c, sign = 1.0;
  int axis = 0;
  SPH_TRY(cut_setup(sim, v, &c, &axis, &sign, err));
  for (size_t a = 0; a < ps->n; ++a)
    keep[a] = (unsigned char)cut_keeps(
        c, axis, sign, sim->dp, ps->field[SPH_FIELD_POSITION0], ps->body, a);
  free(c);
  return SPH_OK;
}

sph_status sph_png_check(const sph_sim *sim, sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_png_output *o = &s->output.png;
  if (!o->enabled)
    return SPH_OK;
  const sph_particles *ps = sim->ps;
  const sph_node *cam = sph_png_schema_node(s->root, "camera");
  char msg[1024];
  sph_view v;
  double box[2][3];
  png_view(sim, &v, box[0], box[1]);
  sph_error verr;
  if (sph_view_check(&v, &verr) != SPH_OK) {
    snprintf(msg, sizeof msg, "unusable camera (%s)", verr.message);
    return sph_png_schema_error(cam, err, msg);
  }
  /* an eye inside a body would see the particles from within */
  for (size_t b = 0; s->dimension == 3 && b < s->nbodies; ++b) {
    double eye[3];
    sph_body_local(&s->bodies[b], v.eye, eye);
    if (sph_shape_distance(&s->bodies[b].shape, 3, eye) < 0.0) {
      const sph_node *pos = cam ? sph_node_child(cam, "position") : NULL;
      snprintf(msg, sizeof msg,
               "the camera at (%g, %g, %g) is inside body '%s'; place it "
               "outside every body",
               v.eye[0], v.eye[1], v.eye[2], s->bodies[b].name);
      return sph_png_schema_error(pos ? pos : cam, err, msg);
    }
  }
  /* something left after the cutaways, and something of it in view */
  unsigned char *keep = malloc(ps->n ? ps->n : 1);
  if (!keep)
    return sph_error_set(err, SPH_ERR_NOMEM, "png check");
  sph_status st = cut_mask(sim, &v, keep, err);
  const double *X = ps->field[SPH_FIELD_POSITION0];
  size_t kept = 0, seen = 0;
  for (size_t a = 0; st == SPH_OK && a < ps->n && !seen; ++a) {
    if (!keep[a] || (o->clip && dot3(o->clip_normal, X + 3 * a) > o->clip_at))
      continue;
    ++kept;
    double w[3];
    seen += sph_view_project(&v, o->width, o->height, X + 3 * a, w) &&
            w[0] >= 0.0 && w[0] < o->width && w[1] >= 0.0 && w[1] < o->height &&
            w[2] >= 0.0 && w[2] <= 1.0;
  }
  free(keep);
  if (st != SPH_OK)
    return st;
  uint64_t counts[2] = {kept, seen}; /* over MPI ranks */
  sph_composite_sum_u64(sim->domain, counts, 2);
  kept = (size_t)counts[0];
  seen = (size_t)counts[1];
  size_t N = sph_domain_particles(sim->domain, ps);
  if (N > 0 && kept == 0) {
    snprintf(msg, sizeof msg, "the clip plane keeps none of the %zu particles",
             N);
    return sph_png_schema_error(sph_png_schema_node(s->root, "clip"), err, msg);
  }
  if (kept > 0 && seen == 0) {
    snprintf(msg, sizeof msg,
             "the camera at (%g, %g, %g) looking at (%g, %g, %g) sees none "
             "of the %zu particles; aim it at the bodies",
             v.eye[0], v.eye[1], v.eye[2], v.target[0], v.target[1],
             v.target[2], kept);
    return sph_png_schema_error(cam, err, msg);
  }
  return SPH_OK;
}

/* The reference outline (ghost): a flat light grey silhouette of spheres of
 * radius 0.72 dp (closing the lattice gaps) over one of 0.84 dp in a darker
 * grey, which leaves a rim around the reference shape. */
static const unsigned char ghost_fill[3] = {222, 222, 226};
static const unsigned char ghost_rim[3] = {168, 170, 178};
#define GHOST_FILL 0.72
#define GHOST_RIM 0.84

/* The colours of the frame's kept particles and its three layers: the
 * outline's rim and fill (ghost), then the particles. */
static void png_layers(png_sink *p, const png_frame *fr,
                       sph_gl_layer layers[3]) {
  size_t m = fr->m;
  double lo = fr->lo, hi = fr->hi;
  for (size_t i = 0; i < m; ++i) {
    double v = fr->value[i];
    if (isfinite(v))
      sph_colormap_eval(p->map, (v - lo) / (hi - lo), p->rgb + 3 * i);
    else
      sph_colormap_nan(p->map, p->rgb + 3 * i);
  }
  double dp = p->dp;
  const double *plane = p->clip ? p->plane : NULL;
  size_t ng = p->ghost ? m : 0;
  layers[0] = (sph_gl_layer){
      ng,   p->ghost_xyz, (float)(GHOST_RIM * dp), p->ghost_rim, plane, 1,
      NULL, fr->key};
  layers[1] = (sph_gl_layer){
      ng,   p->ghost_xyz, (float)(GHOST_FILL * dp), p->ghost_fill, plane, 1,
      NULL, fr->key};
  layers[2] = (sph_gl_layer){m,     fr->xyz, (float)(0.5 * dp), p->rgb,
                             plane, 0,       fr->scale,         fr->key};
}

static sph_status png_overlay_write(png_sink *p, const png_frame *fr,
                                    const char *path, sph_error *err);

/* Renders one snapshot into frames/<scene>_NNNN.png: colours, the sphere
 * pass, the overlay, the file (temporary name, then renamed). Errors name
 * the file. Runs on the render thread (or the caller's without one). */
static sph_status png_render(png_sink *p, const png_frame *fr, sph_error *err) {
  char path[1300];
  snprintf(path, sizeof path, "%s/%s_%04d.png", p->dir, p->name, fr->index);
  sph_gl_layer layers[3];
  png_layers(p, fr, layers);
  sph_error gerr;
  sph_status st =
      sph_gl_draw_layers(p->gl, &fr->view, layers, 3, &p->img, &gerr);
  if (st != SPH_OK)
    return sph_error_at(err, st, path, 0, 0, NULL, "%s", gerr.message);
  return png_overlay_write(p, fr, path, err);
}

/* The same over MPI ranks (collective, on the simulation thread): each rank
 * draws its kept particles tagged with their ids, the images are
 * composited by depth onto rank 0 (sph_composite_reduce), which draws the
 * overlay and writes the file. */
static sph_status png_render_ranks(png_sink *p, const png_frame *fr,
                                   sph_error *err) {
  char path[1300];
  snprintf(path, sizeof path, "%s/%s_%04d.png", p->dir, p->name, fr->index);
  sph_gl_layer layers[3];
  png_layers(p, fr, layers);
  sph_error gerr;
  const sph_composite_px *px = NULL;
  sph_status st = sph_gl_draw_tagged(p->gl, &fr->view, layers, 3, &px, &gerr);
  if (st != SPH_OK)
    sph_error_at(err, st, path, 0, 0, NULL, "%s", gerr.message);
  SPH_TRY(sph_domain_agree(p->domain, st, err));
  size_t npix = (size_t)p->width * (size_t)p->height;
  SPH_TRY(sph_composite_reduce(p->domain, px, npix, p->cpx, err));
  if (p->rank != 0)
    return SPH_OK;
  for (size_t i = 0; i < npix; ++i)
    memcpy(p->img.rgba + 4 * i, &p->cpx[i].rgba, 4);
  return png_overlay_write(p, fr, path, err);
}

/* The overlay over the drawn frame in p->img (colour bar at the right,
 * label block at the top left, axes, scale bar), then the file. */
static sph_status png_overlay_write(png_sink *p, const png_frame *fr,
                                    const char *path, sph_error *err) {
  double lo = fr->lo, hi = fr->hi;
  int H = p->img.height, W = p->img.width;
  char label[256];
  sph_colorbar cb = {.map = p->map,
                     .min = lo,
                     .max = hi,
                     .title = p->title,
                     .clamped_low = fr->clamped_low,
                     .clamped_high = fr->clamped_high,
                     .x = W - W / 8,
                     .y = H / 5,
                     .width = W / 48 > 8 ? W / 48 : 8,
                     .height = 3 * H / 5};
  int fit = W - (W / 64 > 4 ? W / 64 : 4) -
            sph_colorbar_extent(&p->img, p->text, &cb);
  cb.x = fit < cb.x ? fit : cb.x; /* labels inside small frames */
  sph_colorbar_draw(&p->img, p->text, &cb);
  snprintf(label, sizeof label, "%s\nt = %.*f s", p->name, p->time_decimals,
           fr->time);
  sph_overlay_label(&p->img, p->text, W / 64, H / 36, label);
  if (p->axes) { /* the world axes on screen: (right, up) components */
    const sph_view *v = &fr->view;
    double f[3], r[3], u[3], dir[3][2];
    for (int k = 0; k < 3; ++k)
      f[k] = v->target[k] - v->eye[k];
    if (right_of(f, v->up, r)) {
      u[0] = r[1] * f[2] - r[2] * f[1];
      u[1] = r[2] * f[0] - r[0] * f[2];
      u[2] = r[0] * f[1] - r[1] * f[0];
      double ul = sqrt(dot3(u, u));
      for (int k = 0; k < 3; ++k) {
        dir[k][0] = r[k];
        dir[k][1] = ul > 0.0 ? u[k] / ul : 0.0;
      }
      int len = H / 14 > 8 ? H / 14 : 8;
      sph_overlay_axes(&p->img, p->text, W / 32 + len, H - H / 14 - len / 2,
                       len, dir);
    }
  }
  if (p->scale_bar) { /* metres per pixel at the camera's target */
    const sph_view *v = &fr->view;
    double d[3] = {v->target[0] - v->eye[0], v->target[1] - v->eye[1],
                   v->target[2] - v->eye[2]};
    double mpp = v->ortho
                     ? v->ortho_height / H
                     : 2.0 * sqrt(dot3(d, d)) *
                           tan(0.5 * v->fovy_deg * 3.14159265358979 / 180) / H;
    sph_overlay_scale_bar(&p->img, p->text, W / 5, H - H / 14, mpp);
  }
  return sph_image_write_png(path, &p->img, err);
}

/* The renderer's GL context and font, made on the thread that renders. */
static sph_status png_renderer_create(png_sink *p, sph_error *err) {
  SPH_TRY(sph_gl_create(p->width, p->height, &p->gl, err));
  return sph_text_create(NULL, &p->text, err);
}

static void png_renderer_destroy(png_sink *p) {
  sph_gl_destroy(p->gl);
  sph_text_destroy(p->text);
  p->gl = NULL;
  p->text = NULL;
}

/* Render thread: creates the renderer, then writes each frame handed over
 * until told to quit; the context is made, used and destroyed here. */
static void *png_thread(void *arg) {
  png_sink *p = arg;
  sph_error err;
  sph_status st = png_renderer_create(p, &err);
  pthread_mutex_lock(&p->mu);
  p->ready = 1;
  p->status = st;
  if (st != SPH_OK)
    p->error = err;
  pthread_cond_broadcast(&p->cv);
  while (st == SPH_OK) {
    while (!p->queued && !p->quit)
      pthread_cond_wait(&p->cv, &p->mu);
    if (!p->queued)
      break;
    png_frame *fr = p->queued;
    pthread_mutex_unlock(&p->mu);
    /* the frame, outside the lock */
    double t0 = sph_wtime();
    sph_status fst = png_render(p, fr, &err);
    double dt = sph_wtime() - t0;
    pthread_mutex_lock(&p->mu);
    p->busy += dt;
    if (fst != SPH_OK && p->status == SPH_OK) {
      p->status = fst;
      p->error = err;
    }
    p->queued = NULL;
    pthread_cond_broadcast(&p->cv);
  }
  pthread_mutex_unlock(&p->mu);
  png_renderer_destroy(p);
  return NULL;
}

/* Waits until every frame handed over is written; returns (and forgets) the
 * render thread's first unreported error. */
static sph_status png_wait(png_sink *p, sph_error *err) {
  if (!p->started)
    return SPH_OK;
  pthread_mutex_lock(&p->mu);
  while (p->queued || !p->ready)
    pthread_cond_wait(&p->cv, &p->mu);
  sph_status st = p->status;
  if (st != SPH_OK && err)
    *err = p->error;
  p->status = SPH_OK;
  pthread_mutex_unlock(&p->mu);
  return st;
}

/* Lets the render thread finish the frame in flight, then ends it. */
static void png_stop(png_sink *p) {
  if (!p->started)
    return;
  pthread_mutex_lock(&p->mu);
  p->quit = 1;
  pthread_cond_broadcast(&p->cv);
  pthread_mutex_unlock(&p->mu);
  pthread_join(p->thread, NULL);
  p->started = 0;
}

/* The frames folder, the buffers a rank needs and the colour policy. */
static sph_status png_setup_buffers(png_sink *p, const sph_sim *sim,
                                    const char *dir, sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_png_output *o = &s->output.png;
  snprintf(p->dir, sizeof p->dir, "%s/frames", dir);
  snprintf(p->name, sizeof p->name, "%s", s->name);
  if (mkdir(p->dir, 0777) != 0 && errno != EEXIST)
    return sph_error_at(err, SPH_ERR_IO, p->dir, 0, 0, NULL,
                        "cannot create the frames folder: %s", strerror(errno));
  struct stat ls; /* no frame written through a link (issue 36) */
  if (lstat(p->dir, &ls) != 0 || !S_ISDIR(ls.st_mode))
    return sph_error_at(err, SPH_ERR_IO, p->dir, 0, 0, NULL,
                        "not a folder (a symbolic link?); sph does not write "
                        "through links: remove it");
  /* over MPI ranks: room for the most particles a rank may hold */
  p->domain = sim->domain;
  p->rank = sph_domain_rank(sim->domain);
  p->cap = sph_domain_capacity(sim->domain, sim->ps);
  if (p->domain && sph_domain_particles(p->domain, sim->ps) > UINT32_MAX)
    return sph_error_set(err, SPH_ERR_RANGE,
                         "png sink: frames over MPI ranks draw at most %lu "
                         "particles",
                         (unsigned long)UINT32_MAX);
  size_t n = p->cap ? p->cap : 1;
  p->keep = malloc(n);
  if (!p->keep)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  p->width = o->width;
  p->height = o->height;
  p->dp = sim->dp;
  if (p->rank == 0) /* the frame rank 0 writes */
    SPH_TRY(sph_image_create(&p->img, o->width, o->height, err));
  if (p->domain) {
    size_t npix = (size_t)o->width * (size_t)o->height;
    p->cpx = p->rank == 0 ? malloc(npix * sizeof *p->cpx) : NULL;
    p->order = malloc(2 * n * sizeof *p->order);
    if ((p->rank == 0 && !p->cpx) || !p->order)
      return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  }
  /* field, range policy and map */
  sph_field f = (sph_field)o->color_field;
  p->field = f;
  p->ncomp = sph_field_components(f);
  p->mode = !strcmp(o->range_mode, "fixed")       ? PNG_RANGE_FIXED
            : !strcmp(o->range_mode, "symmetric") ? PNG_RANGE_SYMMETRIC
            : !strcmp(o->range_mode, "robust")    ? PNG_RANGE_ROBUST
                                                  : PNG_RANGE_AUTO;
  if (p->mode == PNG_RANGE_FIXED) {
    p->lo = o->range[0];
    p->hi = o->range[1];
    p->have_range = 1;
  }
  /* signed fields about their natural centre, the rest one-sided */
  p->centre = sph_png_field_centre(f);
  if (p->ncomp > 1)
    p->centre = NAN;
  if (p->mode == PNG_RANGE_SYMMETRIC && !isfinite(p->centre))
    p->centre = 0.0;
  int diverging = isfinite(p->centre);
  if (p->mode == PNG_RANGE_FIXED)
    diverging = p->ncomp == 1 && p->lo < (diverging ? p->centre : 0.0) &&
                p->hi > (diverging ? p->centre : 0.0);
  p->map = diverging ? SPH_CMAP_COOL_WARM : SPH_CMAP_VIRIDIS;
  if (o->colormap[0])
    p->map =
        !strcmp(o->colormap, "viridis") ? SPH_CMAP_VIRIDIS : SPH_CMAP_COOL_WARM;
  if (!isfinite(p->centre) && p->map == SPH_CMAP_COOL_WARM)
    p->centre = 0.0;
  if (p->map == SPH_CMAP_VIRIDIS)
    p->centre = NAN;
  p->work = malloc(n * sizeof *p->work);
  if (!p->work)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  const char *unit = sph_field_unit(f);
  snprintf(p->title, sizeof p->title, "%s%s%s%s%s", sph_field_name(f),
           p->ncomp > 1 ? " magnitude" : "", unit && *unit ? " [" : "",
           unit ? unit : "", unit && *unit ? "]" : "");
  return SPH_OK;
}

/* Allocates and fills everything but the renderer; over MPI ranks every
 * rank fails when one does before the reductions (collective). */
static sph_status png_setup(png_sink *p, const sph_sim *sim, const char *dir,
                            sph_error *err) {
  sph_status st = png_setup_buffers(p, sim, dir, err);
  SPH_TRY(sph_domain_agree(sim->domain, st, err));
  const sph_scene *s = sim->scene;
  const sph_png_output *o = &s->output.png;
  size_t n = p->cap ? p->cap : 1;
  /* camera, cutaways and the reference outline */
  png_view(sim, &p->view, p->fit_lo, p->fit_hi);
  SPH_TRY(sph_view_check(&p->view, err));
  p->scene = sim->scene;
  p->axes = o->axes;
  p->scale_bar = o->scale_bar;
  p->follow = o->camera.follow && !o->camera.has_position;
  /* the fewest decimals that write every output time exactly (0.005 -> 3,
   * 0.0025 -> 4, 2e-6 -> 6), at least one */
  double every = sim->scene->output.every;
  p->time_decimals = 1;
  while (p->time_decimals < 12) {
    double q = every * pow(10.0, p->time_decimals);
    if (fabs(q - nearbyint(q)) <= 1e-6 * q)
      break;
    p->time_decimals++;
  }
  SPH_TRY(cut_setup(sim, &p->view, &p->cut_c, &p->cut_axis, &p->cut_sign, err));
  const double *X = sim->ps->field[SPH_FIELD_POSITION0];
  for (size_t a = 0; a < sim->ps->n; ++a) {
    p->keep[a] = (unsigned char)cut_keeps(p->cut_c, p->cut_axis, p->cut_sign,
                                          p->dp, X, sim->ps->body, a);
    p->nkeep += p->keep[a];
  }
  p->clip = o->clip;
  p->ghost = o->ghost;
  for (int k = 0; k < 3; ++k)
    p->plane[k] = -o->clip_normal[k];
  p->plane[3] = o->clip_at;
  /* the snapshots and the colours of the kept particles (over ranks: of
   * every particle a rank may hold) */
  size_t m = p->domain ? n : p->nkeep ? p->nkeep : 1;
  p->rgb = malloc(3 * m);
  if (!p->rgb)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  p->dim = sim->scene->dimension;
  int with_j = sim->ps->field[SPH_FIELD_JACOBIAN] != NULL;
  for (int i = 0; i < 2; ++i) {
    p->slot[i].xyz = malloc(3 * m * sizeof *p->slot[i].xyz);
    p->slot[i].value = malloc(m * sizeof *p->slot[i].value);
    p->slot[i].scale = with_j ? malloc(m * sizeof *p->slot[i].scale) : NULL;
    p->slot[i].key = p->domain ? malloc(m * sizeof *p->slot[i].key) : NULL;
    if (!p->slot[i].xyz || !p->slot[i].value || (with_j && !p->slot[i].scale) ||
        (p->domain && !p->slot[i].key))
      return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  }
  if (o->ghost) {
    p->ghost_xyz = malloc(3 * m * sizeof *p->ghost_xyz);
    p->ghost_rim = malloc(3 * m);
    p->ghost_fill = malloc(3 * m);
    if (!p->ghost_xyz || !p->ghost_rim || !p->ghost_fill)
      return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
    for (size_t g = 0; g < m; ++g) /* over ranks: set at every frame */
      for (int k = 0; k < 3; ++k) {
        p->ghost_rim[3 * g + k] = ghost_rim[k];
        p->ghost_fill[3 * g + k] = ghost_fill[k];
      }
    size_t g = 0;
    for (size_t a = 0; !p->domain && a < sim->ps->n; ++a) {
      if (!p->keep[a])
        continue;
      for (int k = 0; k < 3; ++k)
        p->ghost_xyz[3 * g + k] = (float)X[3 * a + k];
      ++g;
    }
  }
  return SPH_OK;
}

static void png_replay(png_sink *p, const sph_sim *sim, const char *dir,
                       int frames);

static sph_status png_open_as(sph_sink *sink, const sph_sim *sim,
                              const char *dir, int threaded, sph_error *err) {
  png_sink *p = calloc(1, sizeof *p);
  if (!p)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  sink->data = p;
  sink->thread_seconds = 0.0;
  p->threaded = threaded && !sim->domain; /* collectives: one thread */
  threaded = p->threaded;
  sph_status st = png_setup(p, sim, dir, err);
  SPH_TRY(sph_domain_agree(sim->domain, st, err)); /* before the replay's */
  png_replay(p, sim, dir, sink->resume_frames);
  if (!threaded)
    return png_renderer_create(p, err);
  /* the render thread, which makes the GL context current on itself */
  if (pthread_mutex_init(&p->mu, NULL) != 0)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink: no mutex");
  if (pthread_cond_init(&p->cv, NULL) != 0) {
    pthread_mutex_destroy(&p->mu);
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink: no condition variable");
  }
  p->locks_made = 1;
  int rc = pthread_create(&p->thread, NULL, png_thread, p);
  if (rc != 0)
    return sph_error_set(err, SPH_ERR_NOMEM,
                         "png sink: cannot start the render thread: %s",
                         strerror(rc));
  p->started = 1;
  return png_wait(p, err);
}

static sph_status png_open(sph_sink *sink, const sph_sim *sim, const char *dir,
                           sph_error *err) {
  return png_open_as(sink, sim, dir, 1, err);
}

static sph_status png_open_sync(sph_sink *sink, const sph_sim *sim,
                                const char *dir, sph_error *err) {
  return png_open_as(sink, sim, dir, 0, err);
}

/* a render thread only where a core is left for it */
static sph_status png_open_auto(sph_sink *sink, const sph_sim *sim,
                                const char *dir, sph_error *err) {
  long cores = sysconf(_SC_NPROCESSORS_ONLN);
  return png_open_as(sink, sim, dir, sim->threads < cores, err);
}

/* The box of m positions (lo > hi when m is 0). */
static void png_box(const float *xyz, size_t m, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; ++k) {
    lo[k] = INFINITY;
    hi[k] = -INFINITY;
  }
  for (size_t i = 0; i < m; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = fmin(lo[k], xyz[3 * i + k]);
      hi[k] = fmax(hi[k], xyz[3 * i + k]);
    }
}

/* Follow camera: refit when a drawn particle leaves the framed box [lo, hi]
 * of the drawn particles, or when the bodies have shrunk to under half of
 * it along every axis (hysteresis: the view holds still while the motion
 * stays inside). Nothing for an empty box. */
static void png_follow(png_sink *p, const double box_lo[3],
                       const double box_hi[3]) {
  if (!(box_lo[0] <= box_hi[0]))
    return;
  double lo[3], hi[3];
  memcpy(lo, box_lo, sizeof lo);
  memcpy(hi, box_hi, sizeof hi);
  int outside = 0, small = 1;
  for (int k = 0; k < 3; ++k) {
    double fit = p->fit_hi[k] - p->fit_lo[k];
    outside |= lo[k] < p->fit_lo[k] || hi[k] > p->fit_hi[k];
    if (fit > 4.0 * p->dp)
      small &= hi[k] - lo[k] < 0.5 * fit;
  }
  if (!outside && !small)
    return;
  png_pad(p->dp, lo, hi);
  memcpy(p->fit_lo, lo, sizeof lo);
  memcpy(p->fit_hi, hi, sizeof hi);
  png_fit(p->scene, lo, hi, &p->view);
}

/* auto and symmetric: a frame widens the range when its values exceed it */
static void png_grow_range(png_sink *p, double vmin, double vmax, double amax) {
  if (p->mode == PNG_RANGE_FIXED || p->mode == PNG_RANGE_ROBUST ||
      !(vmax > vmin))
    return;
  double c0 = isfinite(p->centre) ? p->centre : 0.0;
  int sym = p->mode == PNG_RANGE_SYMMETRIC;
  double lo_f = sym ? c0 - amax : vmin, hi_f = sym ? c0 + amax : vmax;
  p->lo = p->have_range ? fmin(p->lo, lo_f) : lo_f;
  p->hi = p->have_range ? fmax(p->hi, hi_f) : hi_f;
  p->have_range = 1;
}

/* A resumed run's frames continue the camera and the grow-only range of
 * the frames already written: both are replayed from their .vtp files
 * (the positions and, for a grow-only range, the colour field), so the
 * frames equal an uninterrupted run's. Without the files (vtk off, or the
 * field not among output.fields) they restart from the first frame's. */
static void png_replay(png_sink *p, const sph_sim *sim, const char *dir,
                       int frames) {
  int grow = p->mode == PNG_RANGE_AUTO || p->mode == PNG_RANGE_SYMMETRIC;
  if (frames <= 0 || !(p->follow || grow) || !sim->scene->output.vtk)
    return;
  /* over MPI ranks each rank reads its own pieces, which hold the
   * particles it owns now only when they do not migrate */
  if (sph_domain_migrates(p->domain))
    return;
  const sph_particles *ps = sim->ps;
  size_t n = ps->n, m = 0;
  double *x = malloc(3 * (n ? n : 1) * sizeof *x);
  double *v = malloc((size_t)p->ncomp * (n ? n : 1) * sizeof *v);
  float *xyz = malloc(3 * (p->nkeep ? p->nkeep : 1) * sizeof *xyz);
  double c0 = isfinite(p->centre) ? p->centre : 0.0;
  for (int i = 0; x && v && xyz && i < frames; ++i) {
    char path[1300];
    double t;
    sph_error err;
    if (p->domain)
      snprintf(path, sizeof path, "%s/%s_%04d_p%d.vtp", dir, sim->scene->name,
               i, p->rank);
    else
      snprintf(path, sizeof path, "%s/%s_%04d.vtp", dir, sim->scene->name, i);
    int ok = sph_vtp_read(path, n, x,
                          grow ? sph_field_name((sph_field)p->field) : NULL,
                          p->ncomp, v, &t, &err) == SPH_OK;
    if (!sph_domain_min(p->domain, ok)) /* every rank's piece */
      break;
    double vmin = INFINITY, vmax = -INFINITY, amax = 0.0;
    m = 0;
    for (size_t j = 0; j < n; ++j) {
      if (grow) {
        double val = sph_png_value(v, p->ncomp, j);
        if (isfinite(val)) {
          vmin = fmin(vmin, val);
          vmax = fmax(vmax, val);
          amax = fmax(amax, fabs(val - c0));
        }
      }
      if (!p->keep[sph_particles_slot(ps, j)])
        continue;
      for (int c = 0; c < 3; ++c)
        xyz[3 * m + c] = (float)x[3 * j + c];
      ++m;
    }
    double lo[5], hi[5]; /* the drawn box, the value range, over the ranks */
    png_box(xyz, m, lo, hi);
    lo[3] = vmin, hi[3] = vmax, lo[4] = 0.0, hi[4] = amax;
    sph_domain_minmax(p->domain, lo, hi, 5);
    if (grow)
      png_grow_range(p, lo[3], hi[3], hi[4]);
    if (p->follow)
      png_follow(p, lo, hi);
  }
  free(x);
  free(v);
  free(xyz);
}

/* The k[i]-th smallest of the frame's nf finite values, i < nk: those in
 * p->work (nlocal of them; over MPI ranks every rank's). */
static void png_kth(png_sink *p, size_t nlocal, size_t nf, const uint64_t *k,
                    int nk, double *out) {
  if (p->domain) {
    sph_composite_select(p->domain, p->work, nlocal, k, nk, out);
    return;
  }
  for (int i = 0; i < nk; ++i)
    out[i] = select_kth(p->work, nf, (size_t)k[i]);
}

/* The frame's colour range from its values' least, greatest and largest
 * distance from the centre and its nf finite values (p->work: nlocal of
 * them), as the range policy says, and the bar's end arrows. */
static void png_colour_range(png_sink *p, png_frame *s, double vmin,
                             double vmax, double amax, size_t nlocal,
                             size_t nf) {
  double c0 = isfinite(p->centre) ? p->centre : 0.0;
  int diverging = isfinite(p->centre);
  if (p->mode == PNG_RANGE_ROBUST && vmax > vmin) {
    uint64_t k[2] = {(uint64_t)floor(0.01 * (double)(nf - 1) + 0.5),
                     (uint64_t)floor(0.99 * (double)(nf - 1) + 0.5)};
    double lo_f, hi_f;
    if (diverging) {
      for (size_t i = 0; i < nlocal; ++i)
        p->work[i] = fabs(p->work[i] - c0);
      double w;
      png_kth(p, nlocal, nf, k + 1, 1, &w);
      w = w > 0.0 ? w : amax;
      lo_f = c0 - w;
      hi_f = c0 + w;
    } else {
      double q[2];
      png_kth(p, nlocal, nf, k, 2, q);
      lo_f = q[0];
      hi_f = q[1];
      if (!(hi_f > lo_f)) {
        lo_f = vmin;
        hi_f = vmax;
      }
    }
    p->lo = lo_f;
    p->hi = hi_f;
    p->have_range = 1;
  } else {
    png_grow_range(p, vmin, vmax, amax);
  }
  s->lo = p->have_range ? p->lo : (diverging ? c0 - 1.0 : 0.0);
  s->hi = p->have_range ? p->hi : (diverging ? c0 + 1.0 : 1.0);
  /* some finite value outside the range: the bar's end arrows */
  s->clamped_low = vmin < s->lo;
  s->clamped_high = vmax > s->hi;
}

/* Particle a's position, radius factor and colour value as the m-th drawn
 * sphere of snapshot s. */
static void png_take(const png_sink *p, const sph_particles *ps, size_t a,
                     double v, png_frame *s, size_t m) {
  const double *x = ps->field[SPH_FIELD_POSITION];
  const double *J = ps->field[SPH_FIELD_JACOBIAN];
  for (int c = 0; c < 3; ++c)
    s->xyz[3 * m + c] = (float)x[3 * a + c];
  if (s->scale && J) { /* the sphere of the particle's volume V0 J */
    double f = p->dim == 3 ? cbrt(J[a]) : sqrt(fmax(J[a], 0.0));
    s->scale[m] = (float)(f > 0.5 ? (f < 2.0 ? f : 2.0) : 0.5);
  } else if (s->scale) {
    s->scale[m] = 1.0f;
  }
  s->value[m] = v;
}

/* A finite colour value v into the frame's least, greatest, largest
 * distance from the centre c0 and the values p->work (nf of them). */
static void png_count(png_sink *p, double v, double c0, double *vmin,
                      double *vmax, double *amax, size_t *nf) {
  if (!isfinite(v))
    return;
  *vmin = fmin(*vmin, v);
  *vmax = fmax(*vmax, v);
  *amax = fmax(*amax, fabs(v - c0));
  p->work[(*nf)++] = v;
}

/* A non-finite position fails here, as the sphere pass would, so the
 * frame is not written. */
static sph_status png_finite(const png_frame *s, size_t m, sph_error *err) {
  for (size_t i = 0; i < 3 * m; ++i)
    if (!isfinite(s->xyz[i]))
      return sph_error_set(err, SPH_ERR_NUMERIC,
                           "render: sphere %zu has a non-finite centre", i / 3);
  return SPH_OK;
}

/* Copies what frame fr needs into snapshot s and advances the range (frame
 * order, on the simulation thread). */
static sph_status png_snapshot(png_sink *p, const sph_frame *fr, png_frame *s,
                               sph_error *err) {
  const double *field = fr->ps->field[p->field];
  size_t n = fr->ps->n, m = 0;
  int nc = p->ncomp;
  double vmin = INFINITY, vmax = -INFINITY, amax = 0.0;
  double c0 = isfinite(p->centre) ? p->centre : 0.0;
  size_t nf = 0;
  for (size_t j = 0; j < n; ++j) { /* creation order, as the VTK files */
    size_t a = sph_particles_slot(fr->ps, j);
    double v = field ? sph_png_value(field, nc, a) : NAN;
    png_count(p, v, c0, &vmin, &vmax, &amax, &nf);
    if (!p->keep[a])
      continue;
    png_take(p, fr->ps, a, v, s, m++);
  }
  SPH_TRY(png_finite(s, m, err));
  if (p->follow) {
    double lo[3], hi[3];
    png_box(s->xyz, m, lo, hi);
    png_follow(p, lo, hi);
  }
  s->view = p->view;
  s->m = m;
  png_colour_range(p, s, vmin, vmax, amax, nf, nf);
  s->time = fr->time;
  s->index = fr->index;
  return SPH_OK;
}

static int cmp_first_i64(const void *pa, const void *pb) {
  int64_t a = *(const int64_t *)pa, b = *(const int64_t *)pb;
  return (a > b) - (a < b);
}

/* The same over MPI ranks (collective): this rank's particles in the
 * serial draw order (by id) with their ids as keys, the cut evaluated on
 * them (they migrate), the box, value range, counts and percentiles
 * reduced over the ranks. */
static sph_status png_snapshot_ranks(png_sink *p, const sph_frame *fr,
                                     png_frame *s, sph_error *err) {
  const sph_particles *ps = fr->ps;
  const double *field = ps->field[p->field];
  const double *X = ps->field[SPH_FIELD_POSITION0];
  size_t n = ps->n, m = 0, nf = 0;
  int nc = p->ncomp;
  double vmin = INFINITY, vmax = -INFINITY, amax = 0.0;
  double c0 = isfinite(p->centre) ? p->centre : 0.0;
  for (size_t a = 0; a < n; ++a) {
    p->order[2 * a] = ps->id[a];
    p->order[2 * a + 1] = (int64_t)a;
  }
  qsort(p->order, n, 2 * sizeof *p->order, cmp_first_i64);
  for (size_t i = 0; i < n; ++i) {
    size_t a = (size_t)p->order[2 * i + 1];
    double v = field ? sph_png_value(field, nc, a) : NAN;
    png_count(p, v, c0, &vmin, &vmax, &amax, &nf);
    if (!cut_keeps(p->cut_c, p->cut_axis, p->cut_sign, p->dp, X, ps->body, a))
      continue;
    s->key[m] = (uint32_t)ps->id[a];
    for (int k = 0; p->ghost && k < 3; ++k)
      p->ghost_xyz[3 * m + k] = (float)X[3 * a + k];
    png_take(p, ps, a, v, s, m++);
  }
  SPH_TRY(sph_domain_agree(p->domain, png_finite(s, m, err), err));
  double lo[5], hi[5]; /* the drawn box, the value range, over the ranks */
  png_box(s->xyz, m, lo, hi);
  lo[3] = vmin, hi[3] = vmax, lo[4] = 0.0, hi[4] = amax;
  sph_domain_minmax(p->domain, lo, hi, 5);
  uint64_t all = nf;
  sph_composite_sum_u64(p->domain, &all, 1);
  if (p->follow)
    png_follow(p, lo, hi);
  s->view = p->view;
  s->m = m;
  png_colour_range(p, s, lo[3], hi[3], hi[4], nf, (size_t)all);
  s->time = fr->time;
  s->index = fr->index;
  return SPH_OK;
}

static sph_status png_write(sph_sink *sink, const sph_frame *fr,
                            sph_error *err) {
  png_sink *p = sink->data;
  png_frame *s = &p->slot[p->next];
  if (p->domain) { /* over MPI ranks: composited on this thread */
    SPH_TRY(png_snapshot_ranks(p, fr, s, err));
    return png_render_ranks(p, s, err);
  }
  SPH_TRY(png_snapshot(p, fr, s, err));
  if (!p->threaded)
    return png_render(p, s, err);
  /* the frame before is done (or failed): hand this one over */
  SPH_TRY(png_wait(p, err));
  pthread_mutex_lock(&p->mu);
  p->queued = s;
  pthread_cond_broadcast(&p->cv);
  pthread_mutex_unlock(&p->mu);
  p->next ^= 1;
  return SPH_OK;
}

static sph_status png_flush(sph_sink *sink, sph_error *err) {
  return png_wait(sink->data, err);
}

static sph_status png_close(sph_sink *sink, sph_error *err) {
  png_sink *p = sink->data;
  sph_status st = png_wait(p, err);
  png_stop(p);
  sink->thread_seconds = p->busy;
  return st;
}

static void png_destroy(sph_sink *sink) {
  png_sink *p = sink->data;
  if (!p)
    return;
  png_stop(p);
  if (p->locks_made) {
    pthread_cond_destroy(&p->cv);
    pthread_mutex_destroy(&p->mu);
  }
  sink->thread_seconds = p->busy;
  png_renderer_destroy(p);
  sph_image_destroy(&p->img);
  free(p->rgb);
  free(p->keep);
  free(p->work);
  free(p->cut_c);
  free(p->order);
  free(p->cpx);
  for (int i = 0; i < 2; ++i) {
    free(p->slot[i].key);
    free(p->slot[i].xyz);
    free(p->slot[i].value);
    free(p->slot[i].scale);
  }
  free(p->ghost_xyz);
  free(p->ghost_rim);
  free(p->ghost_fill);
  free(p);
  sink->data = NULL;
}

static int png_enabled(const sph_scene *scene) {
  return scene->output.png.enabled;
}

const sph_sink_ops sph_png_sink_ops = {
    .name = "png",
    .enabled = png_enabled,
    .distributed = 1,
    .open = png_open_auto,
    .write = png_write,
    .flush = png_flush,
    .close = png_close,
    .destroy = png_destroy,
};

const sph_sink_ops sph_png_sink_thread_ops = {
    .name = "png",
    .enabled = png_enabled,
    .distributed = 1,
    .open = png_open,
    .write = png_write,
    .flush = png_flush,
    .close = png_close,
    .destroy = png_destroy,
};

const sph_sink_ops sph_png_sink_sync_ops = {
    .name = "png",
    .enabled = png_enabled,
    .distributed = 1,
    .open = png_open_sync,
    .write = png_write,
    .flush = png_flush,
    .close = png_close,
    .destroy = png_destroy,
};
