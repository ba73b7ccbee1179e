/* The PNG sink's drawing (png_sink.c describes the sink): the layers of a
 * frame, the sphere pass, the composite over MPI ranks, the overlay and the
 * file; the render thread that does it and the hand-over of frames. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "render/png_sink_impl.h"

/* The reference outline (ghost): a flat light grey silhouette of spheres of
 * radius 0.72 dp (closing the lattice gaps) over one of 0.84 dp in a darker
 * grey, which leaves a rim around the reference shape. */
const unsigned char sph_png_ghost_fill[3] = {222, 222, 226};
const unsigned char sph_png_ghost_rim[3] = {168, 170, 178};
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
  /* the sphere (3D) or disc (2D) of the particle's volume dp^d at J = 1:
   * the body looks solid at any spacing, without lattice gaps */
  double r = p->dim == 3 ? cbrt(3.0 / (4.0 * 3.14159265358979323846)) * dp
                         : sqrt(1.0 / 3.14159265358979323846) * dp;
  layers[2] = (sph_gl_layer){m,     fr->xyz, (float)r,  p->rgb,
                             plane, 0,       fr->scale, fr->key};
}

static sph_status png_overlay_write(png_sink *p, const png_frame *fr,
                                    const char *path, sph_error *err);

/* Renders one snapshot into frames/<scene>_NNNN.png: colours, the sphere
 * pass, the overlay, the file (temporary name, then renamed). Errors name
 * the file. Runs on the render thread (or the caller's without one). */
sph_status sph_png_render(png_sink *p, const png_frame *fr, sph_error *err) {
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
sph_status sph_png_render_ranks(png_sink *p, const png_frame *fr,
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
    if (png_right_of(f, v->up, r)) {
      u[0] = r[1] * f[2] - r[2] * f[1];
      u[1] = r[2] * f[0] - r[0] * f[2];
      u[2] = r[0] * f[1] - r[1] * f[0];
      double ul = sqrt(png_dot3(u, u));
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
                     : 2.0 * sqrt(png_dot3(d, d)) *
                           tan(0.5 * v->fovy_deg * 3.14159265358979 / 180) / H;
    sph_overlay_scale_bar(&p->img, p->text, W / 5, H - H / 14, mpp);
  }
  return sph_image_write_png(path, &p->img, err);
}

/* The renderer's GL context and font, made on the thread that renders. */
sph_status sph_png_renderer_create(png_sink *p, sph_error *err) {
  SPH_TRY(sph_gl_create(p->width, p->height, &p->gl, err));
  return sph_text_create(NULL, &p->text, err);
}

void sph_png_renderer_destroy(png_sink *p) {
  sph_gl_destroy(p->gl);
  sph_text_destroy(p->text);
  p->gl = NULL;
  p->text = NULL;
}

/* A snapshot recorded in the scratch file, then drawn (unless deferred). */
sph_status sph_png_emit(png_sink *p, const png_frame *fr, sph_error *err) {
  sph_status st = sph_png_store_put(p, fr, !p->deferred, err);
  SPH_TRY(p->domain ? sph_domain_agree(p->domain, st, err) : st);
  if (p->deferred)
    return SPH_OK;
  return p->domain ? sph_png_render_ranks(p, fr, err)
                   : sph_png_render(p, fr, err);
}

/* Render thread: creates the renderer, then writes each frame handed over
 * until told to quit; the context is made, used and destroyed here. */
void *sph_png_thread(void *arg) {
  png_sink *p = arg;
  sph_error err;
  sph_status st = sph_png_renderer_create(p, &err);
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
    sph_status fst = sph_png_render(p, fr, &err);
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
  sph_png_renderer_destroy(p);
  return NULL;
}

/* Waits until every frame handed over is written; returns (and forgets) the
 * render thread's first unreported error. */
sph_status sph_png_wait(png_sink *p, sph_error *err) {
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
void sph_png_stop(png_sink *p) {
  if (!p->started)
    return;
  pthread_mutex_lock(&p->mu);
  p->quit = 1;
  pthread_cond_broadcast(&p->cv);
  pthread_mutex_unlock(&p->mu);
  pthread_join(p->thread, NULL);
  p->started = 0;
}
