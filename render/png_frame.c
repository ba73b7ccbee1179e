/* The PNG sink's frames on the simulation thread (png_sink.c describes the
 * sink): each frame's snapshot of the kept particles, its statistics and
 * colour range (robust percentiles, grow-only, fixed), the same over MPI
 * ranks, and a resumed run's replay of the camera and range. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/vtk_read.h"
#include "render/png_sink_impl.h"

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
void sph_png_replay(png_sink *p, const sph_sim *sim, const char *dir,
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
    sph_png_box(xyz, m, lo, hi);
    lo[3] = vmin, hi[3] = vmax, lo[4] = 0.0, hi[4] = amax;
    sph_domain_minmax(p->domain, lo, hi, 5);
    if (grow)
      png_grow_range(p, lo[3], hi[3], hi[4]);
    if (p->follow)
      sph_png_follow(p, lo, hi);
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
sph_status sph_png_snapshot(png_sink *p, const sph_frame *fr, png_frame *s,
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
    sph_png_box(s->xyz, m, lo, hi);
    sph_png_follow(p, lo, hi);
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
sph_status sph_png_snapshot_ranks(png_sink *p, const sph_frame *fr,
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
    if (!sph_png_cut_keeps(p->cut_c, p->cut_axis, p->cut_sign, p->dp, X,
                           ps->body, a))
      continue;
    s->key[m] = (uint32_t)ps->id[a];
    for (int k = 0; p->ghost && k < 3; ++k)
      p->ghost_xyz[3 * m + k] = (float)X[3 * a + k];
    png_take(p, ps, a, v, s, m++);
  }
  SPH_TRY(sph_domain_agree(p->domain, png_finite(s, m, err), err));
  double lo[5], hi[5]; /* the drawn box, the value range, over the ranks */
  sph_png_box(s->xyz, m, lo, hi);
  lo[3] = vmin, hi[3] = vmax, lo[4] = 0.0, hi[4] = amax;
  sph_domain_minmax(p->domain, lo, hi, 5);
  uint64_t all = nf;
  sph_composite_sum_u64(p->domain, &all, 1);
  if (p->follow)
    sph_png_follow(p, lo, hi);
  s->view = p->view;
  s->m = m;
  png_colour_range(p, s, lo[3], hi[3], hi[4], nf, (size_t)all);
  s->time = fr->time;
  s->index = fr->index;
  return SPH_OK;
}
