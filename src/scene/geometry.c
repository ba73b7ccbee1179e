/* Geometry: signed distance functions of the scene shapes, their bounds and
 * exact measures, and the particle sets that fill them (a box lattice with
 * particles on the faces and tributary volumes, BENCHMARKS.md D.5; a
 * cell-centred lattice clipped to any shape; seeded jitter; a relaxation to
 * a uniform irregular set by kernel-gradient particle shifting, in the
 * spirit of the level-set relaxation of seed 002 sec. 6). */
#include "sph/geometry.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "sph/kernel.h"
#include "sph/neighbors.h"

/* ---- shapes ------------------------------------------------------------- */

static double hypot3(double a, double b, double c) {
  return sqrt(a * a + b * b + c * c);
}

/* distance combining a radial and an axial slab (cylinder, tube) */
static double combine(double dr, double da) {
  double ox = dr > 0 ? dr : 0, oy = da > 0 ? da : 0;
  double inside = dr > da ? dr : da;
  return sqrt(ox * ox + oy * oy) + (inside < 0 ? inside : 0);
}

/* radial distance from the axis and axial coordinate from the base */
static void axial_coords(const sph_shape *s, const double X[3], double *rho,
                         double *along) {
  double d[3] = {X[0] - s->center[0], X[1] - s->center[1], X[2] - s->center[2]};
  *along = d[s->axis];
  d[s->axis] = 0.0;
  *rho = hypot3(d[0], d[1], d[2]);
}

double sph_shape_distance(const sph_shape *s, int dim, const double X[3]) {
  switch (s->kind) {
  case SPH_SHAPE_BOX: {
    double q[3] = {0, 0, 0}, outside = 0.0, inside = -INFINITY;
    for (int c = 0; c < dim; ++c) {
      double mid = 0.5 * (s->min[c] + s->max[c]);
      double half = 0.5 * (s->max[c] - s->min[c]);
      q[c] = fabs(X[c] - mid) - half;
      outside += q[c] > 0 ? q[c] * q[c] : 0.0;
      inside = q[c] > inside ? q[c] : inside;
    }
    return sqrt(outside) + (inside < 0 ? inside : 0);
  }
  case SPH_SHAPE_DISC:
  case SPH_SHAPE_SPHERE: {
    double z = dim == 3 ? X[2] - s->center[2] : 0.0;
    return hypot3(X[0] - s->center[0], X[1] - s->center[1], z) - s->radius;
  }
  case SPH_SHAPE_SHELL: {
    double r = hypot3(X[0] - s->center[0], X[1] - s->center[1],
                      dim == 3 ? X[2] - s->center[2] : 0.0);
    return fmax(r - s->outer_radius, s->inner_radius - r);
  }
  case SPH_SHAPE_RING:
    if (dim == 2) {
      double r = hypot3(X[0] - s->center[0], X[1] - s->center[1], 0.0);
      return fmax(r - s->outer_radius, s->inner_radius - r);
    } else {
      double rho, along;
      axial_coords(s, X, &rho, &along);
      return combine(fmax(rho - s->outer_radius, s->inner_radius - rho),
                     fmax(-along, along - s->length));
    }
  case SPH_SHAPE_CYLINDER: {
    double rho, along;
    axial_coords(s, X, &rho, &along);
    return combine(rho - s->radius, fmax(-along, along - s->length));
  }
  }
  return INFINITY;
}

void sph_shape_bounds(const sph_shape *s, int dim, double lo[3], double hi[3]) {
  for (int c = 0; c < 3; ++c)
    lo[c] = hi[c] = 0.0;
  if (s->kind == SPH_SHAPE_BOX) {
    for (int c = 0; c < dim; ++c) {
      lo[c] = s->min[c];
      hi[c] = s->max[c];
    }
    return;
  }
  double r = s->kind == SPH_SHAPE_DISC || s->kind == SPH_SHAPE_SPHERE ||
                     s->kind == SPH_SHAPE_CYLINDER
                 ? s->radius
                 : s->outer_radius;
  for (int c = 0; c < dim; ++c) {
    lo[c] = s->center[c] - r;
    hi[c] = s->center[c] + r;
  }
  int axial =
      s->kind == SPH_SHAPE_CYLINDER || (s->kind == SPH_SHAPE_RING && dim == 3);
  if (axial) {
    lo[s->axis] = s->center[s->axis];
    hi[s->axis] = s->center[s->axis] + s->length;
  }
}

double sph_shape_measure(const sph_shape *s, int dim) {
  switch (s->kind) {
  case SPH_SHAPE_BOX: {
    double m = 1.0;
    for (int c = 0; c < dim; ++c)
      m *= s->max[c] - s->min[c];
    return m;
  }
  case SPH_SHAPE_DISC:
    return M_PI * s->radius * s->radius;
  case SPH_SHAPE_SPHERE:
    return 4.0 / 3.0 * M_PI * pow(s->radius, 3);
  case SPH_SHAPE_SHELL:
    return 4.0 / 3.0 * M_PI *
           (pow(s->outer_radius, 3) - pow(s->inner_radius, 3));
  case SPH_SHAPE_RING: {
    double a = M_PI * (s->outer_radius * s->outer_radius -
                       s->inner_radius * s->inner_radius);
    return dim == 2 ? a : a * s->length;
  }
  case SPH_SHAPE_CYLINDER:
    return M_PI * s->radius * s->radius * s->length;
  }
  return 0.0;
}

/* ---- random numbers (splitmix64) ------------------------------------------
 */

static uint64_t rng_next(uint64_t *state) {
  uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

static double rng_uniform(uint64_t *state) { /* [-1, 1) */
  return 2.0 * ((double)(rng_next(state) >> 11) * 0x1.0p-53) - 1.0;
}

/* ---- lattices -------------------------------------------------------------
 */

typedef struct pointset {
  double *x, *v;
  size_t n, cap;
} pointset;

static int push(pointset *p, const double X[3], double volume) {
  if (p->n == p->cap) {
    size_t c = p->cap ? 2 * p->cap : 1024;
    double *x = realloc(p->x, 3 * c * sizeof *x);
    if (!x)
      return -1;
    p->x = x;
    double *v = realloc(p->v, c * sizeof *v);
    if (!v)
      return -1;
    p->v = v;
    p->cap = c;
  }
  memcpy(p->x + 3 * p->n, X, 3 * sizeof *X);
  p->v[p->n++] = volume;
  return 0;
}

static int lattice_faces(const sph_body *b, int dim, pointset *p) {
  const sph_shape *s = &b->shape;
  int n[3] = {1, 1, 1};
  double h[3] = {1, 1, 1};
  for (int c = 0; c < dim; ++c) {
    n[c] = b->count[c];
    h[c] = (s->max[c] - s->min[c]) / (n[c] - 1);
  }
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k) {
        int idx[3] = {i, j, k};
        double X[3] = {0, 0, 0}, vol = 1.0;
        for (int c = 0; c < dim; ++c) {
          /* the last point is placed exactly on the max face */
          X[c] = idx[c] == n[c] - 1 ? s->max[c] : s->min[c] + idx[c] * h[c];
          vol *= (idx[c] == 0 || idx[c] == n[c] - 1) ? 0.5 * h[c] : h[c];
        }
        if (push(p, X, vol))
          return -1;
      }
  return 0;
}

static int lattice_cells(const sph_body *b, int dim, pointset *p) {
  const sph_shape *s = &b->shape;
  double lo[3], hi[3], h[3] = {1, 1, 1};
  long n[3] = {1, 1, 1};
  sph_shape_bounds(s, dim, lo, hi);
  for (int c = 0; c < dim; ++c) {
    double len = hi[c] - lo[c];
    n[c] = (long)floor(len / b->spacing + 0.5);
    if (n[c] < 1)
      n[c] = 1;
    /* boxes tile exactly; curved shapes keep the given spacing */
    h[c] = s->kind == SPH_SHAPE_BOX ? len / (double)n[c] : b->spacing;
    if (s->kind != SPH_SHAPE_BOX)
      n[c] = (long)ceil(len / b->spacing) + 1;
  }
  double vol = 1.0;
  for (int c = 0; c < dim; ++c)
    vol *= h[c];
  for (long i = 0; i < n[0]; ++i)
    for (long j = 0; j < n[1]; ++j)
      for (long k = 0; k < n[2]; ++k) {
        long idx[3] = {i, j, k};
        double X[3] = {0, 0, 0};
        for (int c = 0; c < dim; ++c)
          X[c] = lo[c] + (idx[c] + 0.5) * h[c];
        if (s->kind != SPH_SHAPE_BOX && sph_shape_distance(s, dim, X) >= 0.0)
          continue;
        if (push(p, X, vol))
          return -1;
      }
  return 0;
}

static void jitter(const sph_body *b, int dim, pointset *p) {
  uint64_t state = (uint64_t)b->seed * 0x2545f4914f6cdd1dull + 1u;
  double amp = b->jitter * b->spacing;
  for (size_t i = 0; i < p->n; ++i) {
    double X[3] = {p->x[3 * i], p->x[3 * i + 1], p->x[3 * i + 2]};
    for (int c = 0; c < dim; ++c)
      X[c] += amp * rng_uniform(&state);
    /* a particle that would leave the shape keeps its lattice place */
    if (sph_shape_distance(&b->shape, dim, X) < 0.0)
      memcpy(p->x + 3 * i, X, sizeof X);
  }
}

/* pulls X inside to distance -margin along the numerical SDF gradient */
static void project_inside(const sph_shape *s, int dim, double X[3],
                           double margin, double eps) {
  for (int iter = 0; iter < 4; ++iter) {
    double d = sph_shape_distance(s, dim, X);
    if (d <= -margin)
      return;
    double g[3] = {0, 0, 0}, g2 = 0.0;
    for (int c = 0; c < dim; ++c) {
      double Xp[3] = {X[0], X[1], X[2]}, Xm[3] = {X[0], X[1], X[2]};
      Xp[c] += eps;
      Xm[c] -= eps;
      g[c] = (sph_shape_distance(s, dim, Xp) - sph_shape_distance(s, dim, Xm)) /
             (2 * eps);
      g2 += g[c] * g[c];
    }
    if (g2 <= 0.0)
      return;
    for (int c = 0; c < dim; ++c)
      X[c] -= (d + margin) * g[c] / g2;
  }
}

static sph_status relax(const sph_body *b, int dim, pointset *p,
                        sph_error *err) {
  double dp = b->spacing;
  sph_kernel k;
  sph_status st =
      sph_kernel_create(&k, SPH_KERNEL_WENDLAND_C2, dim, 1.3 * dp, err);
  sph_neighbors *nl = NULL;
  double *shift = NULL;
  if (st == SPH_OK)
    st = sph_neighbors_create(&nl, err);
  if (st == SPH_OK && !(shift = calloc(3 * p->n, sizeof *shift)))
    st = sph_error_set(err, SPH_ERR_NOMEM, "relaxation of body '%s'", b->name);
  double vol = pow(dp, dim), diff = 0.5 * k.h * k.h, cap = 0.2 * dp;
  for (int it = 0; st == SPH_OK && it < b->relax_steps; ++it) {
    st = sph_neighbors_build(nl, p->x, p->n, dim, k.support, NULL,
                             SPH_PAIRS_ALL, err);
    if (st != SPH_OK)
      break;
    long n = (long)p->n;
    /* shift down the gradient of the particle concentration */
#pragma omp parallel for schedule(static)
    for (long a = 0; a < n; ++a) {
      double g[3] = {0, 0, 0};
      for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s) {
        size_t j = (size_t)nl->index[s];
        double r3[3], gw[3];
        for (int c = 0; c < 3; ++c)
          r3[c] = p->x[3 * a + c] - p->x[3 * j + c];
        sph_kernel_gradient(&k, r3, hypot3(r3[0], r3[1], r3[2]), gw);
        for (int c = 0; c < 3; ++c)
          g[c] += vol * gw[c];
      }
      double len = 0.0;
      for (int c = 0; c < dim; ++c) {
        g[c] *= -diff;
        len += g[c] * g[c];
      }
      len = sqrt(len);
      double scale = len > cap ? cap / len : 1.0;
      for (int c = 0; c < 3; ++c)
        shift[3 * a + c] = c < dim ? scale * g[c] : 0.0;
    }
    for (size_t a = 0; a < p->n; ++a) {
      double *X = p->x + 3 * a;
      for (int c = 0; c < dim; ++c)
        X[c] += shift[3 * a + c];
      project_inside(&b->shape, dim, X, 0.5 * dp, 1e-4 * dp);
    }
  }
  /* equal volumes that add up to the exact measure */
  if (st == SPH_OK) {
    double v = sph_shape_measure(&b->shape, dim) / (double)p->n;
    for (size_t a = 0; a < p->n; ++a)
      p->v[a] = v;
  }
  free(shift);
  sph_neighbors_destroy(nl);
  return st;
}

sph_status sph_body_generate(const sph_body *b, int dim, double **x,
                             double **volume, size_t *n, sph_error *err) {
  *x = *volume = NULL;
  *n = 0;
  const sph_shape *s = &b->shape;
  int is3d = s->kind == SPH_SHAPE_SPHERE || s->kind == SPH_SHAPE_SHELL ||
             s->kind == SPH_SHAPE_CYLINDER;
  if (dim == 2 && is3d)
    return sph_error_set(
        err, SPH_ERR_GEOMETRY, "body '%s': a %s needs dimension 3", b->name,
        s->kind == SPH_SHAPE_CYLINDER
            ? "cylinder"
            : (s->kind == SPH_SHAPE_SPHERE ? "sphere" : "shell"));
  if (dim == 3 && s->kind == SPH_SHAPE_DISC)
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': a disc is 2D; use a cylinder in 3D",
                         b->name);
  if (b->lattice == SPH_LATTICE_FACES) {
    if (s->kind != SPH_SHAPE_BOX)
      return sph_error_set(err, SPH_ERR_GEOMETRY,
                           "body '%s': particle counts apply to boxes; give "
                           "a spacing for other shapes",
                           b->name);
    for (int c = 0; c < dim; ++c)
      if (b->count[c] < 2)
        return sph_error_set(err, SPH_ERR_GEOMETRY,
                             "body '%s': at least 2 particles per axis, got "
                             "%d",
                             b->name, b->count[c]);
  } else if (!(b->spacing > 0.0)) {
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': spacing must be positive", b->name);
  }
  pointset p = {0};
  int fail = b->lattice == SPH_LATTICE_FACES ? lattice_faces(b, dim, &p)
                                             : lattice_cells(b, dim, &p);
  sph_status st = SPH_OK;
  if (fail)
    st = sph_error_set(err, SPH_ERR_NOMEM, "particles of body '%s'", b->name);
  else if (p.n == 0)
    st = sph_error_set(err, SPH_ERR_GEOMETRY,
                       "body '%s' has no particles: spacing %g is larger than "
                       "the shape",
                       b->name, b->spacing);
  if (st == SPH_OK && b->distribution != SPH_DIST_LATTICE)
    jitter(b, dim, &p);
  if (st == SPH_OK && b->distribution == SPH_DIST_RELAX)
    st = relax(b, dim, &p, err);
  if (st != SPH_OK) {
    free(p.x);
    free(p.v);
    return st;
  }
  *x = p.x;
  *volume = p.v;
  *n = p.n;
  return SPH_OK;
}
