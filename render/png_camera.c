/* The PNG sink's camera and cutaways (png_sink.c describes the sink): the
 * fitted or given camera, the `cut: half` mask, the pre-run check of the
 * png block (sph_png_check) and the follow camera's refit. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/png_schema.h"
#include "render/png_sink_impl.h"
#include "scene/geometry.h"

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
  /* the label block's height (sph_overlay_label: two lines of the
   * overlay's font, its padding, at H / 36): over the share in small
   * frames, whose font does not shrink below 12 px */
  int px = H / 32 < 12 ? 12 : H / 32 > 40 ? 40 : H / 32;
  int label = H / 36 + (int)ceil(2.5 * px) + 2 * (px / 3 < 3 ? 3 : px / 3);
  int top = (int)(PNG_LABEL_SHARE * H);
  int we = (int)((1.0 - PNG_BAR_SHARE) * W),
      he = H - (label > top ? label : top);
  sph_view_fit(lo, hi, c->given ? c->azimuth : 30.0,
               c->given ? c->elevation : 20.0, c->given ? c->zoom : 1.0,
               c->given ? c->orthographic : 1, s->dimension, we, he, v);
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
  if (!png_right_of(f, v->up, r))
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
void sph_png_view(const sph_sim *sim, sph_view *v, double lo[3], double hi[3]) {
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
  double fl = sqrt(png_dot3(f, f));
  if (!(fl > 0.0))
    return;
  for (int k = 0; k < 3; ++k)
    f[k] /= fl;
  if (!png_right_of(f, v->up, r))
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
    dmin = fmin(dmin, png_dot3(e, f));
    dmax = fmax(dmax, png_dot3(e, f));
    half =
        fmax(half, fmax(fabs(png_dot3(t, u)), fabs(png_dot3(t, r)) / aspect));
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
sph_status sph_png_cut_setup(const sph_sim *sim, const sph_view *v, double **c,
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
int sph_png_cut_keeps(const double *c, int axis, double sign, double dp,
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
  SPH_TRY(sph_png_cut_setup(sim, v, &c, &axis, &sign, err));
  for (size_t a = 0; a < ps->n; ++a)
    keep[a] = (unsigned char)sph_png_cut_keeps(
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
  sph_png_view(sim, &v, box[0], box[1]);
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
    if (!keep[a] ||
        (o->clip && png_dot3(o->clip_normal, X + 3 * a) > o->clip_at))
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

/* The box of m positions (lo > hi when m is 0). */
void sph_png_box(const float *xyz, size_t m, double lo[3], double hi[3]) {
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

/* Follow camera: the drawn box [lo, hi] joins the union of every frame's
 * box so far, and the view is the fit of that union padded by a sphere's
 * radius and 2 % of each side (no room for motion: the union holds it).
 * The camera only ever widens, never jumps back; png_store.c draws the
 * frames again with the fit of the whole run's union. Nothing for an
 * empty box. */
void sph_png_follow(png_sink *p, const double box_lo[3],
                    const double box_hi[3]) {
  if (!(box_lo[0] <= box_hi[0]))
    return;
  int grew = !p->have_box;
  for (int k = 0; k < 3; ++k) {
    grew |= box_lo[k] < p->box_lo[k] || box_hi[k] > p->box_hi[k];
    p->box_lo[k] = p->have_box ? fmin(p->box_lo[k], box_lo[k]) : box_lo[k];
    p->box_hi[k] = p->have_box ? fmax(p->box_hi[k], box_hi[k]) : box_hi[k];
  }
  p->have_box = 1;
  if (grew)
    sph_png_fit_box(p, p->box_lo, p->box_hi, &p->view);
}

void sph_png_fit_box(const png_sink *p, const double lo[3], const double hi[3],
                     sph_view *v) {
  double a[3], b[3];
  for (int k = 0; k < 3; ++k) {
    double pad = 0.62 * p->dp + 0.02 * (hi[k] - lo[k]);
    a[k] = lo[k] - pad;
    b[k] = hi[k] + pad;
  }
  png_fit(p->scene, a, b, v);
}
