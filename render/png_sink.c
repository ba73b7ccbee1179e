/* PNG frame sink: every output time, the particles as lit spheres (OSMesa,
 * gl.c) coloured by the scene's `output.png.color` field, with a colour bar,
 * the field name and units, the scene name and the time composited on the
 * CPU (colorbar.c, text.c), written to frames/<scene>_NNNN.png.
 *
 * Colour: scalar fields with a signed range use the diverging cool-to-warm
 * map, other fields (and vector/tensor magnitudes) viridis. Range policy:
 * `fixed [min, max]` as given; `symmetric` +-max|f| and `auto` [min, max]
 * grow-only: a frame widens the range when its values exceed it and never
 * narrows it, so colours change only while the field grows (a true
 * run-wide `global` range needs a second pass over the frames and is not
 * done: it behaves as `auto`). NaN values get the map's own NaN colour. The
 * camera frames the bodies' initial bounding box, enlarged by 10 % on each
 * side for the motion, unless the scene gives a position. Created only when
 * the scene has a `png` block. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "gl_impl.h"
#include "overlay_impl.h"
#include "sph/image.h"
#include "sph/render.h"

typedef struct png_sink {
  sph_gl *gl;
  sph_text *text;
  sph_image img;
  sph_view view;
  char dir[1024], name[128];
  float *xyz;
  unsigned char *rgb;
  double *value;
  sph_colormap_kind map;
  int have_range, symmetric, fixed;
  double lo, hi;
} png_sink;

/* Scalar value of particle a: the field itself or its magnitude. */
static double particle_value(const double *f, int nc, size_t a) {
  if (nc == 1)
    return f[a];
  double s = 0.0;
  for (int c = 0; c < nc; ++c)
    s += f[(size_t)nc * a + c] * f[(size_t)nc * a + c];
  return sqrt(s);
}

static sph_status png_open(sph_sink *sink, const sph_sim *sim, const char *dir,
                           sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_png_output *o = &s->output.png;
  png_sink *p = calloc(1, sizeof *p);
  if (!p)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  sink->data = p;
  snprintf(p->dir, sizeof p->dir, "%s/frames", dir);
  snprintf(p->name, sizeof p->name, "%s", s->name);
  if (mkdir(p->dir, 0777) != 0 && errno != EEXIST)
    return sph_error_at(err, SPH_ERR_IO, p->dir, 0, 0, NULL,
                        "cannot create the frames folder: %s", strerror(errno));
  size_t n = sim->ps->n ? sim->ps->n : 1;
  p->xyz = malloc(3 * n * sizeof *p->xyz);
  p->rgb = malloc(3 * n);
  p->value = malloc(n * sizeof *p->value);
  if (!p->xyz || !p->rgb || !p->value)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  SPH_TRY(sph_image_create(&p->img, o->width, o->height, err));
  SPH_TRY(sph_gl_create(o->width, o->height, &p->gl, err));
  SPH_TRY(sph_text_create(NULL, &p->text, err));
  /* range policy and map */
  sph_field f = (sph_field)o->color_field;
  p->fixed = !strcmp(o->range_mode, "fixed");
  p->symmetric = !strcmp(o->range_mode, "symmetric");
  if (p->fixed) {
    p->lo = o->range[0];
    p->hi = o->range[1];
    p->have_range = 1;
  }
  int signed_field = sph_field_components(f) == 1 &&
                     (p->symmetric || (p->fixed && p->lo < 0.0 && p->hi > 0.0));
  p->map = signed_field ? SPH_CMAP_COOL_WARM : SPH_CMAP_VIRIDIS;
  /* camera: the scene's, or a fit of the initial bounding box */
  const sph_camera *c = &o->camera;
  double lo[3] = {INFINITY, INFINITY, INFINITY};
  double hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  const double *X = sim->ps->field[SPH_FIELD_POSITION0];
  for (size_t a = 0; a < sim->ps->n; ++a)
    for (int k = 0; k < 3; ++k) {
      lo[k] = fmin(lo[k], X[3 * a + k]);
      hi[k] = fmax(hi[k], X[3 * a + k]);
    }
  for (int k = 0; k < 3; ++k) {
    double pad = 0.5 * sim->dp + 0.1 * (hi[k] - lo[k]);
    lo[k] -= pad;
    hi[k] += pad;
  }
  sph_view_fit(lo, hi, c->given ? c->azimuth : 30.0,
               c->given ? c->elevation : 20.0, c->given ? c->zoom : 1.0,
               c->given ? c->orthographic : 0, s->dimension, o->width,
               o->height, &p->view);
  if (c->given && c->has_position) {
    memcpy(p->view.eye, c->position, sizeof c->position);
    memcpy(p->view.target, c->target, sizeof c->target);
    memcpy(p->view.up, c->up, sizeof c->up);
  }
  return sph_view_check(&p->view, err);
}

static sph_status png_write(sph_sink *sink, const sph_frame *fr,
                            sph_error *err) {
  png_sink *p = sink->data;
  const sph_scene *s = fr->sim->scene;
  const sph_png_output *o = &s->output.png;
  sph_field f = (sph_field)o->color_field;
  const double *field = fr->ps->field[f];
  const double *x = fr->ps->field[SPH_FIELD_POSITION];
  size_t n = fr->ps->n;
  int nc = sph_field_components(f);
  double vmin = INFINITY, vmax = -INFINITY, amax = 0.0;
  for (size_t a = 0; a < n; ++a) {
    double v = field ? particle_value(field, nc, a) : NAN;
    p->value[a] = v;
    if (isfinite(v)) {
      vmin = fmin(vmin, v);
      vmax = fmax(vmax, v);
      amax = fmax(amax, fabs(v));
    }
    for (int c = 0; c < 3; ++c)
      p->xyz[3 * a + c] = (float)x[3 * a + c];
  }
  /* grow-only range from the frames with a varying field */
  if (!p->fixed && vmax > vmin) {
    double lo_f = p->symmetric ? -amax : vmin,
           hi_f = p->symmetric ? amax : vmax;
    p->lo = p->have_range ? fmin(p->lo, lo_f) : lo_f;
    p->hi = p->have_range ? fmax(p->hi, hi_f) : hi_f;
    p->have_range = 1;
  }
  double lo = p->have_range ? p->lo : -1.0, hi = p->have_range ? p->hi : 1.0;
  int clamped_low = 0, clamped_high = 0;
  for (size_t a = 0; a < n; ++a) {
    double v = p->value[a];
    if (!isfinite(v)) {
      sph_colormap_nan(p->map, p->rgb + 3 * a);
      continue;
    }
    clamped_low |= v < lo;
    clamped_high |= v > hi;
    sph_colormap_eval(p->map, (v - lo) / (hi - lo), p->rgb + 3 * a);
  }
  float radius = (float)(0.5 * fr->sim->dp);
  SPH_TRY(sph_gl_draw_spheres(p->gl, &p->view, n, p->xyz, radius, p->rgb, NULL,
                              &p->img, err));
  /* overlay: colour bar at the right, label block at the top left */
  int H = p->img.height, W = p->img.width;
  char title[96], label[256];
  const char *unit = sph_field_unit(f);
  snprintf(title, sizeof title, "%s%s%s%s%s", sph_field_name(f),
           nc > 1 ? " magnitude" : "", unit && *unit ? " [" : "",
           unit ? unit : "", unit && *unit ? "]" : "");
  sph_colorbar cb = {.map = p->map,
                     .min = lo,
                     .max = hi,
                     .title = title,
                     .clamped_low = clamped_low,
                     .clamped_high = clamped_high,
                     .x = W - W / 8,
                     .y = H / 5,
                     .width = W / 48 > 8 ? W / 48 : 8,
                     .height = 3 * H / 5};
  sph_colorbar_draw(&p->img, p->text, &cb);
  snprintf(label, sizeof label, "%s\nt = %.5f s", p->name, fr->time);
  sph_overlay_label(&p->img, p->text, W / 64, H / 36, label);
  char path[1300];
  snprintf(path, sizeof path, "%s/%s_%04d.png", p->dir, p->name, fr->index);
  return sph_image_write_png(path, &p->img, err);
}

static sph_status png_close(sph_sink *sink, sph_error *err) { return SPH_OK; }

static void png_destroy(sph_sink *sink) {
  png_sink *p = sink->data;
  if (!p)
    return;
  sph_gl_destroy(p->gl);
  sph_text_destroy(p->text);
  sph_image_destroy(&p->img);
  free(p->xyz);
  free(p->rgb);
  free(p->value);
  free(p);
  sink->data = NULL;
}

const sph_sink_ops sph_png_sink_ops = {
    .name = "png",
    .open = png_open,
    .write = png_write,
    .close = png_close,
    .destroy = png_destroy,
};
