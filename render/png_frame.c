/* The PNG sink's frames on the simulation thread (png_sink.c describes the
 * sink): each frame's snapshot of the kept particles, its statistics and
 * colour range (robust percentiles of the run's histogram, grow-only,
 * fixed), the same over MPI
 * ranks, and a resumed run's replay of the camera and range. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/vtk_read.h"
#include "render/png_sink_impl.h"

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

/* The run's range widened to [lo_f, hi_f] (grow-only). */
static void png_widen(png_sink *p, double lo_f, double hi_f) {
  p->lo = p->have_range ? fmin(p->lo, lo_f) : lo_f;
  p->hi = p->have_range ? fmax(p->hi, hi_f) : hi_f;
  p->have_range = 1;
}

/* auto and symmetric: a frame widens the range when its values exceed it */
static void png_grow_range(png_sink *p, double vmin, double vmax, double amax) {
  if (p->mode == PNG_RANGE_FIXED || p->mode == PNG_RANGE_ROBUST ||
      !(vmax > vmin))
    return;
  double c0 = isfinite(p->centre) ? p->centre : 0.0;
  int sym = p->mode == PNG_RANGE_SYMMETRIC;
  png_widen(p, sym ? c0 - amax : vmin, sym ? c0 + amax : vmax);
}

/* robust: a value's bin in the run's histogram: the top 16 bits of its
 * float in an order-preserving unsigned form (sign, exponent and 7 bits of
 * mantissa: bins 0.8 % wide relative to the value). */
static uint32_t hist_bin(double v) {
  float f = (float)v;
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  u = (u & 0x80000000u) ? ~u : (u | 0x80000000u);
  return u >> 16;
}

/* The least (top 0) or greatest (top 1) value of bin b. */
static double hist_edge(uint32_t b, int top) {
  uint32_t u = (b << 16) | (top ? 0xFFFFu : 0u);
  u = (u & 0x80000000u) ? (u & 0x7FFFFFFFu) : ~u;
  float f;
  memcpy(&f, &u, sizeof f);
  return f;
}

/* The bin holding the k-th smallest of the histogram h's values. */
static uint32_t hist_kth(const uint64_t *h, uint64_t k) {
  uint64_t c = 0;
  for (uint32_t b = 0; b < PNG_HIST_BINS; ++b) {
    c += h[b];
    if (c > k)
      return b;
  }
  return PNG_HIST_BINS - 1;
}

/* robust: the run's range from the histogram of every value drawn so far
 * (over MPI ranks summed), the 1st to 99th percentile (nearest rank, to
 * the bin) within the run's least and greatest value; diverging maps
 * centre +- the 99th percentile of |f - centre|. Pooled over the frames,
 * so neither a few particles (clamp corners, a punch edge) nor a few
 * frames (an impact's transient) set it. */
static void png_robust_range(png_sink *p) {
  const uint64_t *h = p->hist;
  if (p->domain) {
    memcpy(p->hist_all, p->hist, PNG_HIST_BINS * sizeof *p->hist);
    sph_composite_sum_u64(p->domain, p->hist_all, PNG_HIST_BINS);
    h = p->hist_all;
  }
  uint64_t n = 0;
  for (uint32_t b = 0; b < PNG_HIST_BINS; ++b)
    n += h[b];
  if (n == 0 || !(p->run_max > p->run_min))
    return;
  uint64_t k_lo = (uint64_t)floor(0.01 * (double)(n - 1) + 0.5),
           k_hi = (uint64_t)floor(0.99 * (double)(n - 1) + 0.5);
  if (isfinite(p->centre)) {
    double w = fmin(hist_edge(hist_kth(h, k_hi), 1), p->run_amax);
    w = w > 0.0 ? w : p->run_amax;
    p->lo = p->centre - w;
    p->hi = p->centre + w;
  } else {
    p->lo = fmax(hist_edge(hist_kth(h, k_lo), 0), p->run_min);
    p->hi = fmin(hist_edge(hist_kth(h, k_hi), 1), p->run_max);
    if (!(p->hi > p->lo)) {
      p->lo = p->run_min;
      p->hi = p->run_max;
    }
  }
  p->have_range = 1;
}

void sph_png_range_update(png_sink *p, double vmin, double vmax) {
  double c0 = isfinite(p->centre) ? p->centre : 0.0;
  double amax = vmax >= vmin ? fmax(fabs(vmin - c0), fabs(vmax - c0)) : 0.0;
  p->run_min = fmin(p->run_min, vmin);
  p->run_max = fmax(p->run_max, vmax);
  p->run_amax = fmax(p->run_amax, amax);
  if (p->mode == PNG_RANGE_ROBUST)
    png_robust_range(p);
  else
    png_grow_range(p, vmin, vmax, amax);
}

/* The frame's colour range from its values' least and greatest (over MPI
 * ranks: all ranks'), as the range
 * policy says: robust from the histogram of the run's values so far, auto
 * and symmetric the run's extremes so far; the frame is drawn with that
 * range (png_store.c draws it again with the run's final one). */
static void png_colour_range(png_sink *p, png_frame *s, double vmin,
                             double vmax) {
  sph_png_range_update(p, vmin, vmax);
  sph_png_final_range(p, &s->lo, &s->hi);
  s->vmin = vmin;
  s->vmax = vmax;
  /* some finite value of the run outside the range: the bar's end arrows
   * (the same in every frame: the bar is the run's) */
  s->clamped_low = p->run_min < s->lo;
  s->clamped_high = p->run_max > s->hi;
}

/* The sphere of a particle's volume V0 J: J^(1/dim), within [0.5, 2]. */
static float png_radius_factor(int dim, double J) {
  double f = dim == 3 ? cbrt(J) : sqrt(fmax(J, 0.0));
  return (float)(f > 0.5 ? (f < 2.0 ? f : 2.0) : 0.5);
}

/* Particle a's position, radius factor and colour value as the m-th drawn
 * sphere of snapshot s. */
static void png_take(png_sink *p, const sph_particles *ps, size_t a, double v,
                     png_frame *s, size_t m) {
  const double *x = ps->field[SPH_FIELD_POSITION];
  const double *J = ps->field[SPH_FIELD_JACOBIAN];
  for (int c = 0; c < 3; ++c)
    s->xyz[3 * m + c] = (float)x[3 * a + c];
  if (s->scale)
    s->scale[m] = J ? png_radius_factor(p->dim, J[a]) : 1.0f;
  s->value[m] = v;
  sph_png_hist_add(p, v);
}

/* A finite colour value v into the frame's least, greatest and largest
 * distance from the centre c0. */
static void png_count(png_sink *p, double v, double c0, double *vmin,
                      double *vmax, double *amax) {
  if (!isfinite(v))
    return;
  *vmin = fmin(*vmin, v);
  *vmax = fmax(*vmax, v);
  *amax = fmax(*amax, fabs(v - c0));
}

void sph_png_hist_add(png_sink *p, double v) {
  if (!p->hist || !isfinite(v))
    return;
  double c0 = isfinite(p->centre) ? p->centre : 0.0;
  p->hist[hist_bin(isfinite(p->centre) ? fabs(v - c0) : v)]++;
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
sph_status sph_png_snapshot(png_sink *p, const sph_frame *fr, png_frame *s,
                            sph_error *err) {
  const double *field = fr->ps->field[p->field];
  size_t n = fr->ps->n, m = 0;
  int nc = p->ncomp;
  double vmin = INFINITY, vmax = -INFINITY, amax = 0.0;
  double c0 = isfinite(p->centre) ? p->centre : 0.0;

  for (size_t j = 0; j < n; ++j) { /* creation order, as the VTK files */
    size_t a = sph_particles_slot(fr->ps, j);
    double v = field ? sph_png_value(field, nc, a) : NAN;
    png_count(p, v, c0, &vmin, &vmax, &amax);
    if (!p->keep[a])
      continue;
    png_take(p, fr->ps, a, v, s, m++);
  }
  SPH_TRY(png_finite(s, m, err));
  sph_png_box(s->xyz, m, s->box_lo, s->box_hi);
  if (p->follow)
    sph_png_follow(p, s->box_lo, s->box_hi);
  s->view = p->view;
  s->m = m;
  png_colour_range(p, s, vmin, vmax);
  s->time = fr->time;
  s->index = fr->index;
  return SPH_OK;
}

static int cmp_first_i64(const void *pa, const void *pb) {
  int64_t a = *(const int64_t *)pa, b = *(const int64_t *)pb;
  return (a > b) - (a < b);
}

/* A snapshot's m particles taken: the drawn box and value range over the
 * ranks (collective), the camera followed, the colour range set. */
static void png_frame_close(png_sink *p, png_frame *s, size_t m, double vmin,
                            double vmax, double amax) {
  double lo[5], hi[5]; /* the drawn box, the value range, over the ranks */
  sph_png_box(s->xyz, m, lo, hi);
  lo[3] = vmin, hi[3] = vmax, lo[4] = 0.0, hi[4] = amax;
  sph_domain_minmax(p->domain, lo, hi, 5);
  memcpy(s->box_lo, lo, sizeof s->box_lo);
  memcpy(s->box_hi, hi, sizeof s->box_hi);
  if (p->follow)
    sph_png_follow(p, lo, hi);
  s->view = p->view;
  s->m = m;
  png_colour_range(p, s, lo[3], hi[3]);
}

/* The same over MPI ranks (collective): this rank's particles in the
 * serial draw order (by id) with their ids as keys, the cut evaluated on
 * them (they migrate), the box, value range, counts and percentiles
 * reduced over the ranks. */
sph_status sph_png_snapshot_ranks(png_sink *p, const sph_frame *fr,
                                  png_frame *s, sph_error *err) {
  const sph_particles *ps = fr->ps;
  const double *field = ps->field[p->field];
  const double *X = ps->field[SPH_FIELD_POSITION0];
  size_t n = ps->n, m = 0;
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
    png_count(p, v, c0, &vmin, &vmax, &amax);
    if (!sph_png_cut_keeps(p->cut_c, p->cut_axis, p->cut_sign, p->dp, X,
                           ps->body, a))
      continue;
    s->key[m] = (uint32_t)ps->id[a];
    for (int k = 0; p->ghost && k < 3; ++k)
      p->ghost_xyz[3 * m + k] = (float)X[3 * a + k];
    png_take(p, ps, a, v, s, m++);
  }
  SPH_TRY(sph_domain_agree(p->domain, png_finite(s, m, err), err));
  png_frame_close(p, s, m, vmin, vmax, amax);
  s->time = fr->time;
  s->index = fr->index;
  return SPH_OK;
}

/* One earlier frame of a resumed run from its file's positions x, colour
 * values v and J (NULL: radius factor 1), n particles in file order, into
 * snapshot s with its range and camera (collective over MPI ranks). */
static void replay_frame(png_sink *p, const sph_particles *ps, const double *x,
                         const double *v, const double *J, png_frame *s) {
  size_t n = ps->n, m = 0;
  double vmin = INFINITY, vmax = -INFINITY, amax = 0.0;
  double c0 = isfinite(p->centre) ? p->centre : 0.0;
  for (size_t j = 0; j < n; ++j) {
    double val = sph_png_value(v, p->ncomp, j);
    png_count(p, val, c0, &vmin, &vmax, &amax);
    if (!p->keep[sph_particles_slot(ps, j)])
      continue;
    for (int c = 0; c < 3; ++c)
      s->xyz[3 * m + c] = (float)x[3 * j + c];
    if (s->scale)
      s->scale[m] = J ? png_radius_factor(p->dim, J[j]) : 1.0f;
    s->value[m++] = val;
    sph_png_hist_add(p, val);
  }
  png_frame_close(p, s, m, vmin, vmax, amax);
}

/* A resumed run's frames 0 .. frames - 1 are taken back from the stopped
 * run's scratch file (png_store.c), exactly as recorded, and drawn again
 * at close with the final range and camera. Without it (a run killed with
 * SIGKILL: records not on disk yet) they are replayed from their .vtp
 * files (positions, the colour field, J: without J in the files the
 * spheres of those frames take the factor 1), so the run-wide range and
 * camera include them, and (serial runs) recorded in the scratch file as
 * not drawn, so close draws them again with the final ones. Without the
 * files
 * (vtk off, the field not among output.fields), or over MPI ranks (their
 * pieces are not recorded; with migrating particles not even replayed),
 * the frames written before stay as they were drawn. */
sph_status sph_png_replay(png_sink *p, const sph_sim *sim, const char *dir,
                          int frames, sph_error *err) {
  if (frames <= 0 || sph_png_store_resume(p, frames, err))
    return SPH_OK;
  if (!sim->scene->output.vtk || sph_domain_migrates(p->domain))
    return SPH_OK;
  const sph_particles *ps = sim->ps;
  size_t n = ps->n ? ps->n : 1;
  png_frame *s = &p->slot[0];
  double *x = malloc(3 * n * sizeof *x);
  double *v = malloc((size_t)p->ncomp * n * sizeof *v);
  double *J = s->scale ? malloc(n * sizeof *J) : NULL;
  sph_status st = SPH_OK;
  if (!x || !v || (s->scale && !J))
    st = sph_error_set(err, SPH_ERR_NOMEM, "png sink: resume");
  for (int i = 0; st == SPH_OK && i < frames; ++i) {
    char path[1300];
    double t;
    sph_error rerr;
    if (p->domain)
      snprintf(path, sizeof path, "%s/%s_%04d_p%d.vtp", dir, sim->scene->name,
               i, p->rank);
    else
      snprintf(path, sizeof path, "%s/%s_%04d.vtp", dir, sim->scene->name, i);
    int ok = sph_vtp_read(path, ps->n, x, sph_field_name((sph_field)p->field),
                          p->ncomp, v, &t, &rerr) == SPH_OK;
    if (!sph_domain_min(p->domain, ok)) /* every rank's piece */
      break;
    double t2;
    int with_j =
        J && sph_vtp_read(path, ps->n, x, "J", 1, J, &t2, &rerr) == SPH_OK;
    replay_frame(p, ps, x, v, with_j ? J : NULL, s);
    s->time = isfinite(t) ? t : i * sim->scene->output.every;
    s->index = i;
    if (!p->domain)
      st = sph_png_store_put(p, s, 0, err);
  }
  free(x);
  free(v);
  free(J);
  return st;
}
