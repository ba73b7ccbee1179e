/* The PNG sink's one colour scale and one camera per run (png_sink.c
 * describes the sink): every frame's snapshot (the drawn particles'
 * positions, radius factors and colour values; over MPI ranks their ids
 * and reference positions too) is appended to a scratch file,
 * frames/.<scene>.frames[.pR], with the range and camera it was drawn with.
 * Frames are drawn during the run with the range and camera known so far
 * (both only ever widen); when the run closes (at its end, or stopped by a
 * signal or sph_run_close), the run-wide range and camera are final and
 * every frame drawn with another one is drawn again from its record, so
 * every frame of the run, and its mp4, shares one colour bar and one view.
 * The scratch file is removed then (and by destroy after a failure); its
 * size is the frames' particles times 24 bytes (3 floats, 1 float, 1
 * double), on disk, never in memory: reading it back uses the sink's own
 * snapshot buffers. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "render/png_sink_impl.h"

/* What a record holds before its arrays. */
typedef struct png_record {
  int32_t index, drawn; /* drawn: 0 for a frame not drawn yet (resume) */
  double time, lo, hi, vmin, vmax;
  double box_lo[3], box_hi[3];
  sph_view view;
  uint64_t m;
} png_record;

sph_status sph_png_store_open(png_sink *p, int resume_frames, sph_error *err) {
  if (p->domain)
    snprintf(p->store_path, sizeof p->store_path, "%s/.%s.frames.p%d", p->dir,
             p->name, p->rank);
  else
    snprintf(p->store_path, sizeof p->store_path, "%s/.%s.frames", p->dir,
             p->name);
  /* resuming: the stopped run's file, when it is one (never a link) */
  int fd = resume_frames > 0
               ? open(p->store_path, O_RDWR | O_NOFOLLOW | O_CLOEXEC)
               : -1;
  struct stat st;
  if (fd >= 0 && (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))) {
    close(fd);
    fd = -1;
  }
  if (fd < 0) { /* a killed run's file is replaced */
    unlink(p->store_path);
    fd = open(p->store_path, O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
              0600);
  }
  if (fd >= 0)
    p->store = fdopen(fd, "r+b");
  if (!p->store) {
    int e = errno;
    if (fd >= 0)
      close(fd);
    p->store_path[0] = '\0';
    return sph_error_at(err, SPH_ERR_IO, p->dir, 0, 0, NULL,
                        "cannot create the frames' scratch file: %s",
                        strerror(e));
  }
  return SPH_OK;
}

/* fwrite/fread of n items or an error naming the scratch file */
static sph_status store_io(png_sink *p, void *buf, size_t size, size_t n,
                           int writing, sph_error *err) {
  if (n == 0)
    return SPH_OK;
  size_t got =
      writing ? fwrite(buf, size, n, p->store) : fread(buf, size, n, p->store);
  if (got != n)
    return sph_error_at(err, SPH_ERR_IO, p->store_path, 0, 0, NULL,
                        "cannot %s the frames' scratch file",
                        writing ? "write" : "read");
  return SPH_OK;
}

/* A record's arrays, in the order the sink's buffers hold them. */
static sph_status store_arrays(png_sink *p, png_frame *fr, size_t m,
                               int writing, sph_error *err) {
  SPH_TRY(store_io(p, fr->xyz, sizeof *fr->xyz, 3 * m, writing, err));
  if (fr->scale)
    SPH_TRY(store_io(p, fr->scale, sizeof *fr->scale, m, writing, err));
  SPH_TRY(store_io(p, fr->value, sizeof *fr->value, m, writing, err));
  if (fr->key)
    SPH_TRY(store_io(p, fr->key, sizeof *fr->key, m, writing, err));
  if (p->domain && p->ghost)
    SPH_TRY(
        store_io(p, p->ghost_xyz, sizeof *p->ghost_xyz, 3 * m, writing, err));
  return SPH_OK;
}

sph_status sph_png_store_put(png_sink *p, const png_frame *fr, int drawn,
                             sph_error *err) {
  if (!p->store)
    return SPH_OK;
  png_record r;
  memset(&r, 0, sizeof r);
  r.index = fr->index;
  r.drawn = drawn;
  r.time = fr->time;
  r.lo = fr->lo;
  r.hi = fr->hi;
  r.vmin = fr->vmin;
  r.vmax = fr->vmax;
  memcpy(r.box_lo, fr->box_lo, sizeof r.box_lo);
  memcpy(r.box_hi, fr->box_hi, sizeof r.box_hi);
  r.view = fr->view;
  r.m = fr->m;
  SPH_TRY(store_io(p, &r, sizeof r, 1, 1, err));
  SPH_TRY(store_arrays(p, (png_frame *)fr, fr->m, 1, err));
  p->nrec++;
  /* on disk before the run goes on: a killed run's resume reads it */
  if (fflush(p->store) != 0)
    return sph_error_at(err, SPH_ERR_IO, p->store_path, 0, 0, NULL,
                        "cannot write the frames' scratch file: %s",
                        strerror(errno));
  return SPH_OK;
}

/* The run-wide range as the frames show it (a field that never varied:
 * centre +- 1, or [0, 1]). */
void sph_png_final_range(const png_sink *p, double *lo, double *hi) {
  int diverging = isfinite(p->centre);
  double c0 = diverging ? p->centre : 0.0;
  *lo = p->have_range ? p->lo : (diverging ? c0 - 1.0 : 0.0);
  *hi = p->have_range ? p->hi : (diverging ? c0 + 1.0 : 1.0);
}

/* One frame drawn (over MPI ranks: collectively). */
static sph_status store_draw(png_sink *p, const png_frame *fr, sph_error *err) {
  return p->domain ? sph_png_render_ranks(p, fr, err)
                   : sph_png_render(p, fr, err);
}

/* Skips the arrays of a record of m particles. */
static sph_status store_skip(png_sink *p, uint64_t m, sph_error *err) {
  const png_frame *fr = &p->slot[0];
  long bytes =
      (long)m * (long)(3 * sizeof *fr->xyz + sizeof *fr->value +
                       (fr->scale ? sizeof *fr->scale : 0) +
                       (fr->key ? sizeof *fr->key : 0) +
                       (p->domain && p->ghost ? 3 * sizeof *p->ghost_xyz : 0));
  if (fseek(p->store, bytes, SEEK_CUR) != 0)
    return sph_error_at(err, SPH_ERR_IO, p->store_path, 0, 0, NULL,
                        "cannot read the frames' scratch file back");
  return SPH_OK;
}

static sph_status store_rewind(png_sink *p, sph_error *err) {
  if (fflush(p->store) != 0 || fseek(p->store, 0, SEEK_SET) != 0)
    return sph_error_at(err, SPH_ERR_IO, p->store_path, 0, 0, NULL,
                        "cannot read the frames' scratch file back");
  return SPH_OK;
}

int sph_png_store_resume(png_sink *p, int frames, sph_error *err) {
  if (!p->store)
    return 0;
  png_frame *fr = &p->slot[0];
  png_record r;
  int n = 0;
  long end = 0;
  if (store_rewind(p, err) != SPH_OK)
    return 0;
  while (n < frames && fread(&r, sizeof r, 1, p->store) == 1 && r.index == n &&
         r.m <= (p->domain ? p->cap : p->nkeep) &&
         store_arrays(p, fr, (size_t)r.m, 0, err) == SPH_OK) {
    for (size_t i = 0; i < r.m; ++i)
      sph_png_hist_add(p, fr->value[i]);
    sph_png_range_update(p, r.vmin, r.vmax);
    if (p->follow)
      sph_png_follow(p, r.box_lo, r.box_hi);
    end = ftell(p->store);
    ++n;
  }
  int whole = n == frames;
  if (p->domain) /* every rank's file */
    whole = sph_domain_min(p->domain, whole);
  if (!whole) { /* not the records this resume needs: start afresh */
    memset(p->hist, 0, p->hist ? PNG_HIST_BINS * sizeof *p->hist : 0);
    p->run_min = INFINITY;
    p->run_max = -INFINITY;
    p->run_amax = 0.0;
    p->have_range = p->mode == PNG_RANGE_FIXED;
    p->have_box = 0;
    end = 0;
    n = 0;
  }
  /* the records after them (frames the resumed run writes again) dropped */
  if (fflush(p->store) != 0 || ftruncate(fileno(p->store), end) != 0 ||
      fseek(p->store, end, SEEK_SET) != 0)
    return 0;
  p->nrec = p->forced = (size_t)n;
  return whole;
}

/* The least envelope of the half widths h[0 .. n) (stride 6) that
 * changes by at most the factor 1 + r from one frame to the next and
 * never falls below h: max over j of h[j] / (1 + r)^|i - j|. */
static void envelope(double *h, size_t n, double r) {
  for (size_t i = 1; i < n; ++i)
    h[6 * i] = fmax(h[6 * i], h[6 * (i - 1)] / (1.0 + r));
  for (size_t i = n - 1; i-- > 0;)
    h[6 * i] = fmax(h[6 * i], h[6 * (i + 1)] / (1.0 + r));
}

static double diagonal(const double *lo, const double *hi) {
  double d = 0.0;
  for (int k = 0; k < 3; ++k)
    d += (hi[k] - lo[k]) * (hi[k] - lo[k]);
  return sqrt(d);
}

/* follow: every frame's box from the records (p->boxes, lo and hi), and
 * whether the bodies travel: the run's union of boxes more than 1.3 times
 * the smallest frame's box (diagonals; the rings parting, a falling body).
 * Then each frame is framed on its own box's centre with half widths
 * widened to an envelope that changes by at most 5 % a frame, so the view
 * follows smoothly and the bodies' scale on screen changes by at most 5 %
 * a frame; otherwise every frame shares the fit of the union (p->view). */
static sph_status store_boxes(png_sink *p, int *travel, sph_error *err) {
  *travel = 0;
  size_t n = p->nrec;
  if (!p->follow || n < 2)
    return SPH_OK;
  p->boxes = malloc(6 * n * sizeof *p->boxes);
  if (!p->boxes)
    return sph_error_set(err, SPH_ERR_NOMEM, "png sink: frame boxes");
  SPH_TRY(store_rewind(p, err));
  png_record r;
  double least = INFINITY;
  for (size_t i = 0; i < n; ++i) {
    SPH_TRY(store_io(p, &r, sizeof r, 1, 0, err));
    SPH_TRY(store_skip(p, r.m, err));
    memcpy(p->boxes + 6 * i, r.box_lo, sizeof r.box_lo);
    memcpy(p->boxes + 6 * i + 3, r.box_hi, sizeof r.box_hi);
    if (!(r.box_lo[0] <= r.box_hi[0]))
      return SPH_OK; /* a frame with nothing drawn: the union's fit */
    least = fmin(least, diagonal(r.box_lo, r.box_hi));
  }
  if (!(diagonal(p->box_lo, p->box_hi) > 1.3 * least))
    return SPH_OK;
  *travel = 1;
  for (size_t i = 0; i < n; ++i) /* centres and half widths */
    for (int k = 0; k < 3; ++k) {
      double *b = p->boxes + 6 * i;
      double c = 0.5 * (b[k] + b[3 + k]), h = 0.5 * (b[3 + k] - b[k]);
      b[k] = c;
      b[3 + k] = h;
    }
  for (int k = 0; k < 3; ++k)
    envelope(p->boxes + 3 + k, n, 0.05);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      double *b = p->boxes + 6 * i, c = b[k], h = b[3 + k];
      b[k] = c - h;
      b[3 + k] = c + h;
    }
  return SPH_OK;
}

/* Every record drawn with another range or camera than the run's final
 * ones is drawn again with them (collective over MPI ranks: the records'
 * headers are the same on every rank). */
static sph_status store_redraw(png_sink *p, sph_error *err) {
  double lo, hi;
  sph_png_final_range(p, &lo, &hi);
  int travel;
  SPH_TRY(store_boxes(p, &travel, err));
  png_frame *fr = &p->slot[0];
  SPH_TRY(store_rewind(p, err));
  png_record r;
  for (size_t i = 0; fread(&r, sizeof r, 1, p->store) == 1; ++i) {
    if (r.m > (p->domain ? p->cap : p->nkeep))
      return sph_error_at(err, SPH_ERR_IO, p->store_path, 0, 0, NULL,
                          "damaged frames' scratch file");
    sph_view view = p->view;
    if (travel && i < p->nrec)
      sph_png_fit_box(p, p->boxes + 6 * i, p->boxes + 6 * i + 3, &view);
    if (i >= p->forced && r.drawn && r.lo == lo && r.hi == hi &&
        !memcmp(&r.view, &view, sizeof r.view)) {
      SPH_TRY(store_skip(p, r.m, err));
      continue;
    }
    SPH_TRY(store_arrays(p, fr, (size_t)r.m, 0, err));
    fr->m = (size_t)r.m;
    fr->index = r.index;
    fr->time = r.time;
    fr->lo = lo;
    fr->hi = hi;
    fr->vmin = r.vmin;
    fr->vmax = r.vmax;
    fr->clamped_low = p->run_min < lo;
    fr->clamped_high = p->run_max > hi;
    fr->view = view;
    SPH_TRY(store_draw(p, fr, err));
    p->redrawn++;
  }
  if (ferror(p->store))
    return sph_error_at(err, SPH_ERR_IO, p->store_path, 0, 0, NULL,
                        "cannot read the frames' scratch file back");
  return SPH_OK;
}

sph_status sph_png_store_finish(png_sink *p, int keep, sph_error *err) {
  if (!p->store)
    return SPH_OK;
  double t0 = sph_wtime();
  sph_status st = SPH_OK;
  if (!p->gl) /* the render thread has ended: the context is made here */
    st = sph_png_renderer_create(p, err);
  if (st == SPH_OK)
    st = store_redraw(p, err);
  if (p->domain)
    st = sph_domain_agree(p->domain, st, err);
  p->redraw_seconds += sph_wtime() - t0;
  if (keep && st == SPH_OK) { /* a stopped run's, for --resume */
    fclose(p->store);
    p->store = NULL;
    p->store_path[0] = '\0';
  }
  sph_png_store_remove(p);
  return st;
}

void sph_png_store_remove(png_sink *p) {
  free(p->boxes);
  p->boxes = NULL;
  if (p->store)
    fclose(p->store);
  p->store = NULL;
  if (p->store_path[0])
    unlink(p->store_path);
  p->store_path[0] = '\0';
}
