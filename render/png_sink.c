/* PNG frame sink: every output time, the particles as lit spheres (OSMesa,
 * gl.c) coloured by the scene's `output.png.color` field, with a colour bar,
 * the field name and units, the scene name and the time composited on the
 * CPU (colorbar.c, text.c), written to frames/<scene>_NNNN.png.
 *
 * Colour: the field chooses the map unless `colormap` is given: pressure
 * (signed about 0) and J (about 1) the diverging cool-to-warm map centred
 * on that value, every other field (von Mises, density, vector and tensor
 * magnitudes) viridis over its own range. One range for the whole run
 * (png_store.c draws again, at close, every frame drawn with a range or
 * camera that changed later): `robust` (the default) the 1st to 99th
 * percentile of every value the run draws, pooled over its frames (a
 * histogram of 65536 bins, 0.8 % wide; centre +- the 99th percentile of
 * |f - centre| for a diverging map), so neither a few extreme particles
 * (clamp corners, a punch edge) nor a few frames (an impact's transient) set
 * it; `auto` the least and greatest value of the run, `symmetric` centre
 * +- the largest distance from it, `global` as `auto`; `fixed [min, max]`
 * as given. NaN values get the map's own NaN colour. Camera: with `follow`
 * (the default of a fitted camera) the fit of the union of every frame's
 * drawn particles over the run (the bodies' extent, padded by a sphere's
 * radius and 2 %), orthographic unless `projection: perspective`; without
 * it the fit of the bodies' initial bounding box enlarged by 10 % on each
 * side for the motion; a scene's position gives the view itself (then the
 * clip range and ortho height are fitted to that box seen from there).
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
 * snapshots allocated at `open`, to advance the range and camera (in frame
 * order, so the frames never depend on timing) and to append the snapshot
 * to the frames' scratch file; a render thread owned by the sink makes the
 * one OSMesa context current, draws, composites and writes the frame. A
 * frame is handed over only when the render thread is idle, so the run
 * never waits for one; `close` draws the frames not drawn yet and those
 * drawn with a range or camera that later widened, on the caller's thread.
 * The render thread's first error (naming the frame's file) is returned by
 * the next write, flush or close. sph_png_sink_sync_ops (sph/render.h)
 * renders on the calling thread instead, sph_png_sink_batch_ops only at
 * close (sph render).
 *
 * This file: the sink's set-up, open, write, close and ops tables; the
 * camera and cutaways are in png_camera.c, the snapshots and colour range
 * in png_frame.c, drawing and the render thread in png_draw.c, the scratch
 * file and the redraw in png_store.c (shared state: png_sink_impl.h). */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "render/png_sink_impl.h"

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
  p->run_min = INFINITY;
  p->run_max = -INFINITY;
  p->run_amax = 0.0;
  if (p->mode == PNG_RANGE_ROBUST) {
    p->hist = calloc(PNG_HIST_BINS, sizeof *p->hist);
    p->hist_all = p->domain ? calloc(PNG_HIST_BINS, sizeof *p->hist_all) : NULL;
    if (!p->hist || (p->domain && !p->hist_all))
      return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  }
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
  sph_png_view(sim, &p->view, p->fit_lo, p->fit_hi);
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
  SPH_TRY(sph_png_cut_setup(sim, &p->view, &p->cut_c, &p->cut_axis,
                            &p->cut_sign, err));
  const double *X = sim->ps->field[SPH_FIELD_POSITION0];
  for (size_t a = 0; a < sim->ps->n; ++a) {
    p->keep[a] = (unsigned char)sph_png_cut_keeps(
        p->cut_c, p->cut_axis, p->cut_sign, p->dp, X, sim->ps->body, a);
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
        p->ghost_rim[3 * g + k] = sph_png_ghost_rim[k];
        p->ghost_fill[3 * g + k] = sph_png_ghost_fill[k];
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

static sph_status png_open_as(sph_sink *sink, const sph_sim *sim,
                              const char *dir, int threaded, int deferred,
                              sph_error *err) {
  png_sink *p = calloc(1, sizeof *p);
  if (!p)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink");
  sink->data = p;
  sink->thread_seconds = 0.0;
  p->threaded = threaded && !deferred && !sim->domain; /* collectives */
  p->deferred = deferred;
  threaded = p->threaded;
  sph_status st = png_setup(p, sim, dir, err);
  if (st == SPH_OK)
    st = sph_png_store_open(p, sink->resume_frames, err);
  SPH_TRY(sph_domain_agree(sim->domain, st, err)); /* before the replay's */
  st = sph_png_replay(p, sim, dir, sink->resume_frames, err);
  SPH_TRY(sph_domain_agree(sim->domain, st, err));
  if (!threaded)
    return sph_png_renderer_create(p, err);
  /* the render thread, which makes the GL context current on itself */
  if (pthread_mutex_init(&p->mu, NULL) != 0)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink: no mutex");
  if (pthread_cond_init(&p->cv, NULL) != 0) {
    pthread_mutex_destroy(&p->mu);
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink: no condition variable");
  }
  p->locks_made = 1;
  int rc = pthread_create(&p->thread, NULL, sph_png_thread, p);
  if (rc != 0)
    return sph_error_set(err, SPH_ERR_NOMEM,
                         "png sink: cannot start the render thread: %s",
                         strerror(rc));
  p->started = 1;
  return sph_png_wait(p, err);
}

static sph_status png_open(sph_sink *sink, const sph_sim *sim, const char *dir,
                           sph_error *err) {
  return png_open_as(sink, sim, dir, 1, 0, err);
}

static sph_status png_open_sync(sph_sink *sink, const sph_sim *sim,
                                const char *dir, sph_error *err) {
  return png_open_as(sink, sim, dir, 0, 0, err);
}

static sph_status png_open_batch(sph_sink *sink, const sph_sim *sim,
                                 const char *dir, sph_error *err) {
  return png_open_as(sink, sim, dir, 0, 1, err);
}

/* a render thread only where a core is left for it */
static sph_status png_open_auto(sph_sink *sink, const sph_sim *sim,
                                const char *dir, sph_error *err) {
  long cores = sysconf(_SC_NPROCESSORS_ONLN);
  return png_open_as(sink, sim, dir, sim->threads < cores, 0, err);
}

static sph_status png_write(sph_sink *sink, const sph_frame *fr,
                            sph_error *err) {
  png_sink *p = sink->data;
  png_frame *s = &p->slot[p->next];
  if (p->domain) { /* over MPI ranks: composited on this thread */
    SPH_TRY(sph_png_snapshot_ranks(p, fr, s, err));
    return sph_png_emit(p, s, err);
  }
  SPH_TRY(sph_png_snapshot(p, fr, s, err));
  if (!p->threaded)
    return sph_png_emit(p, s, err);
  /* handed over only when the render thread is idle: the run never waits
   * for a frame; one not drawn now is drawn at close */
  pthread_mutex_lock(&p->mu);
  int idle = p->ready && !p->queued;
  sph_status st = p->status;
  if (st != SPH_OK && err)
    *err = p->error;
  p->status = SPH_OK;
  pthread_mutex_unlock(&p->mu);
  SPH_TRY(st);
  SPH_TRY(sph_png_store_put(p, s, idle, err));
  if (!idle)
    return SPH_OK;
  pthread_mutex_lock(&p->mu);
  p->queued = s;
  pthread_cond_broadcast(&p->cv);
  pthread_mutex_unlock(&p->mu);
  p->next ^= 1;
  return SPH_OK;
}

static sph_status png_flush(sph_sink *sink, sph_error *err) {
  return sph_png_wait(sink->data, err);
}

/* every frame handed over written, then those drawn with another range
 * or camera than the run's final ones drawn again (png_store.c) */
static sph_status png_close(sph_sink *sink, sph_error *err) {
  png_sink *p = sink->data;
  sph_status st = sph_png_wait(p, err);
  sph_png_stop(p);
  if (st == SPH_OK)
    st = sph_png_store_finish(p, sink->stopping, err);
  sink->thread_seconds = p->busy;
  return st;
}

static void png_destroy(sph_sink *sink) {
  png_sink *p = sink->data;
  if (!p)
    return;
  sph_png_stop(p);
  if (p->locks_made) {
    pthread_cond_destroy(&p->cv);
    pthread_mutex_destroy(&p->mu);
  }
  sink->thread_seconds = p->busy;
  sph_png_store_remove(p);
  sph_png_renderer_destroy(p);
  sph_image_destroy(&p->img);
  free(p->rgb);
  free(p->keep);
  free(p->hist);
  free(p->hist_all);
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

const sph_sink_ops sph_png_sink_batch_ops = {
    .name = "png",
    .enabled = png_enabled,
    .distributed = 1,
    .open = png_open_batch,
    .write = png_write,
    .flush = png_flush,
    .close = png_close,
    .destroy = png_destroy,
};
