/* 2D outlines (polygon.h): rings of vertices, the even-odd inside test with
 * half-open edges, the shoelace area. */
#include "scene/polygon.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct sph_polygon {
  double *xy;
  size_t *start, nrings;
  double lo[2], hi[2], area;
};

/* "the outline" or "hole N" (1-based) */
static const char *ring_name(size_t r, char buf[32]) {
  if (r == 0)
    return "the outline";
  snprintf(buf, 32, "hole %zu", r);
  return buf;
}

/* twice the signed area of ring r */
static double ring_area2(const sph_polygon *p, size_t r) {
  size_t a = p->start[r], b = p->start[r + 1];
  double s = 0.0;
  for (size_t i = a; i < b; ++i) {
    size_t j = i + 1 < b ? i + 1 : a;
    s += p->xy[2 * i] * p->xy[2 * j + 1] - p->xy[2 * j] * p->xy[2 * i + 1];
  }
  return s;
}

sph_status sph_polygon_create(sph_polygon **out, const double *xy,
                              const size_t *start, size_t nrings,
                              sph_error *err) {
  *out = NULL;
  char buf[32];
  size_t n = start[nrings];
  for (size_t r = 0; r < nrings; ++r)
    if (start[r + 1] < start[r] + 3)
      return sph_error_set(err, SPH_ERR_GEOMETRY,
                           "%s has %zu points; a ring needs at least 3",
                           ring_name(r, buf), start[r + 1] - start[r]);
  for (size_t i = 0; i < 2 * n; ++i)
    if (!isfinite(xy[i]))
      return sph_error_set(err, SPH_ERR_GEOMETRY,
                           "point %zu is not a pair of finite numbers", i / 2);
  sph_polygon *p = calloc(1, sizeof *p);
  if (!p || !(p->xy = malloc(2 * n * sizeof *p->xy)) ||
      !(p->start = malloc((nrings + 1) * sizeof *p->start))) {
    sph_polygon_destroy(p);
    return sph_error_set(err, SPH_ERR_NOMEM, "polygon");
  }
  memcpy(p->xy, xy, 2 * n * sizeof *xy);
  memcpy(p->start, start, (nrings + 1) * sizeof *start);
  p->nrings = nrings;
  for (int c = 0; c < 2; ++c) {
    p->lo[c] = INFINITY;
    p->hi[c] = -INFINITY;
  }
  for (size_t i = 0; i < start[1]; ++i)
    for (int c = 0; c < 2; ++c) {
      p->lo[c] = fmin(p->lo[c], xy[2 * i + c]);
      p->hi[c] = fmax(p->hi[c], xy[2 * i + c]);
    }
  for (size_t r = 0; r < nrings; ++r) {
    double a = 0.5 * fabs(ring_area2(p, r));
    if (!(a > 0.0)) {
      sph_polygon_destroy(p);
      return sph_error_set(err, SPH_ERR_GEOMETRY, "%s encloses no area",
                           ring_name(r, buf));
    }
    p->area += r ? -a : a;
  }
  if (!(p->area > 0.0)) {
    double left = p->area;
    sph_polygon_destroy(p);
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "the holes cover the outline (area left %g)", left);
  }
  *out = p;
  return SPH_OK;
}

void sph_polygon_destroy(sph_polygon *p) {
  if (!p)
    return;
  free(p->xy);
  free(p->start);
  free(p);
}

int sph_polygon_inside(const sph_polygon *p, const double X[3]) {
  int odd = 0;
  for (size_t r = 0; r < p->nrings; ++r) {
    size_t a = p->start[r], b = p->start[r + 1];
    for (size_t i = a; i < b; ++i) {
      size_t j = i + 1 < b ? i + 1 : a;
      const double *P = p->xy + 2 * i, *Q = p->xy + 2 * j;
      if ((P[1] > X[1]) != (Q[1] > X[1])) {
        double x = P[0] + (X[1] - P[1]) * (Q[0] - P[0]) / (Q[1] - P[1]);
        odd ^= X[0] < x;
      }
    }
  }
  return odd;
}

void sph_polygon_bounds(const sph_polygon *p, double lo[2], double hi[2]) {
  for (int c = 0; c < 2; ++c) {
    lo[c] = p->lo[c];
    hi[c] = p->hi[c];
  }
}

double sph_polygon_area(const sph_polygon *p) { return p->area; }
