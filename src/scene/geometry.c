/* Geometry: signed distance functions of the scene shapes, their bounds and
 * exact measures, and the particle sets that fill them:
 *   - a box lattice with particles on the faces and tributary volumes
 *     (docs/benchmarks.md D.5: sum V = body volume);
 *   - a cell-centred lattice, tiling a box exactly, clipped to other shapes;
 *   - seeded uniform jitter (splitmix64).
 * The relaxation to a uniform, irregular distribution is in relax.c. */
#include "scene/geometry.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene/cloud.h"
#include "scene/geometry_impl.h"
#include "scene/mesh.h"
#include "scene/polygon.h"

/* ---- shapes ------------------------------------------------------------- */

/* exact distance of the intersection of a radial and an axial slab */
static double combine(double dr, double da) {
  double ox = dr > 0 ? dr : 0, oy = da > 0 ? da : 0;
  double inside = dr > da ? dr : da;
  return sqrt(ox * ox + oy * oy) + (inside < 0 ? inside : 0);
}

/* distance from the axis and coordinate along it from the base centre (exact
 * for a coordinate axis: the other components of a are zero) */
static void axial_coords(const sph_shape *s, const double X[3], double *rho,
                         double *along) {
  const double *a = s->axis;
  double d[3] = {X[0] - s->center[0], X[1] - s->center[1], X[2] - s->center[2]};
  *along = d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
  for (int c = 0; c < 3; ++c)
    d[c] -= *along * a[c];
  *rho = hypot3(d[0], d[1], d[2]);
}

double sph_shape_distance(const sph_shape *s, int dim, const double X[3]) {
  double dz = dim == 3 ? X[2] - s->center[2] : 0.0;
  switch (s->kind) {
  case SPH_SHAPE_BOX: {
    double outside = 0.0, inside = -INFINITY;
    for (int c = 0; c < dim; ++c) {
      double q = fabs(X[c] - 0.5 * (s->min[c] + s->max[c])) -
                 0.5 * (s->max[c] - s->min[c]);
      outside += q > 0 ? q * q : 0.0;
      inside = q > inside ? q : inside;
    }
    return sqrt(outside) + (inside < 0 ? inside : 0);
  }
  case SPH_SHAPE_DISC:
    return hypot3(X[0] - s->center[0], X[1] - s->center[1], 0.0) - s->radius;
  case SPH_SHAPE_SPHERE:
    return hypot3(X[0] - s->center[0], X[1] - s->center[1], dz) - s->radius;
  case SPH_SHAPE_SHELL: {
    double r = hypot3(X[0] - s->center[0], X[1] - s->center[1], dz);
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
  case SPH_SHAPE_MESH: /* the side only */
    return sph_mesh_inside(s->mesh, X) ? -1.0 : 1.0;
  case SPH_SHAPE_POLYGON:
    return sph_polygon_inside(s->polygon, X) ? -1.0 : 1.0;
  case SPH_SHAPE_PARTICLES: /* never asked: the particles are not moved */
    return -1.0;
  }
  return INFINITY;
}

void sph_shape_bounds(const sph_shape *s, int dim, double lo[3], double hi[3]) {
  for (int c = 0; c < 3; ++c)
    lo[c] = hi[c] = 0.0;
  if (s->kind == SPH_SHAPE_BOX || s->kind == SPH_SHAPE_MESH ||
      s->kind == SPH_SHAPE_POLYGON || s->kind == SPH_SHAPE_PARTICLES) {
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
  if (shape_is_axial(s, dim))
    for (int c = 0; c < 3; ++c) {
      /* the end discs: radius r sqrt(1 - a_c^2) across component c */
      double end = s->center[c] + s->length * s->axis[c];
      double across = r * sqrt(fmax(1.0 - s->axis[c] * s->axis[c], 0.0));
      lo[c] = fmin(s->center[c], end) - across;
      hi[c] = fmax(s->center[c], end) + across;
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
    return 4.0 / 3.0 * M_PI * s->radius * s->radius * s->radius;
  case SPH_SHAPE_SHELL:
    return 4.0 / 3.0 * M_PI *
           (s->outer_radius * s->outer_radius * s->outer_radius -
            s->inner_radius * s->inner_radius * s->inner_radius);
  case SPH_SHAPE_RING: {
    double a = M_PI * (s->outer_radius * s->outer_radius -
                       s->inner_radius * s->inner_radius);
    return dim == 2 ? a : a * s->length;
  }
  case SPH_SHAPE_CYLINDER:
    return M_PI * s->radius * s->radius * s->length;
  case SPH_SHAPE_MESH:
    return sph_mesh_get_info(s->mesh)->volume;
  case SPH_SHAPE_POLYGON:
    return sph_polygon_area(s->polygon);
  case SPH_SHAPE_PARTICLES:
    return sph_cloud_volume(s->cloud);
  }
  return 0.0;
}

/* ---- random numbers: splitmix64 ------------------------------------------ */

static uint64_t rng_next(uint64_t *state) {
  uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

/* uniform in [-1, 1) */
static double rng_uniform(uint64_t *state) {
  return 2.0 * ((double)(rng_next(state) >> 11) * 0x1.0p-53) - 1.0;
}

/* ---- lattices ------------------------------------------------------------ */

sph_status sph_pointset_push(void *ctx, const double X[3], double volume,
                             sph_error *err) {
  pointset *p = ctx;
  if (p->n == p->cap) {
    size_t c = p->cap ? 2 * p->cap : 1024;
    double *x = realloc(p->x, 3 * c * sizeof *x);
    if (!x)
      return sph_error_set(err, SPH_ERR_NOMEM, "particles");
    p->x = x;
    double *v = realloc(p->v, c * sizeof *v);
    if (!v)
      return sph_error_set(err, SPH_ERR_NOMEM, "particles");
    p->v = v;
    p->cap = c;
  }
  memcpy(p->x + 3 * p->n, X, 3 * sizeof *X);
  p->v[p->n++] = volume;
  return SPH_OK;
}

/* more lattice points than this is a mistake in the scene */
#define LATTICE_MAX 2147483647.0

/* a body's lattice: points per axis, spacing per axis, first point */
typedef struct lattice {
  const sph_body *b;
  int dim, faces, box;
  long n[3];
  double lo[3], h[3], vol;
  uint64_t state;        /* the jitter's stream */
  unsigned char *inside; /* a mesh's: which lattice points it holds */
} lattice;

static sph_status lattice_faces(lattice *L, sph_error *err) {
  const sph_body *b = L->b;
  const sph_shape *s = &b->shape;
  double total = 1.0;
  for (int c = 0; c < L->dim; ++c) {
    L->n[c] = b->count[c];
    L->h[c] = (s->max[c] - s->min[c]) / (b->count[c] - 1);
    total *= b->count[c];
  }
  if (total > LATTICE_MAX)
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': %.3g particles are too many", b->name,
                         total);
  return SPH_OK;
}

static sph_status lattice_cells(lattice *L, sph_error *err) {
  const sph_body *b = L->b;
  const sph_shape *s = &b->shape;
  double hi[3], total = 1.0;
  sph_shape_bounds(s, L->dim, L->lo, hi);
  for (int c = 0; c < L->dim; ++c) {
    double len = hi[c] - L->lo[c], cells = len / b->spacing;
    if (cells > LATTICE_MAX)
      cells = LATTICE_MAX + 1.0;
    /* boxes are tiled exactly by n cells; other shapes keep dp */
    L->n[c] = L->box ? (long)floor(cells + 0.5) : (long)ceil(cells) + 1;
    L->h[c] = L->box && L->n[c] > 0 ? len / (double)L->n[c] : b->spacing;
    total *= (double)L->n[c];
  }
  if (total > LATTICE_MAX)
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': spacing %g gives %.3g lattice points, too "
                         "many",
                         b->name, b->spacing, total);
  L->vol = 1.0;
  for (int c = 0; c < L->dim; ++c)
    L->vol *= L->h[c];
  return SPH_OK;
}

/* lattice point idx into X with its volume; 0 when outside the shape */
static int lattice_point(const lattice *L, const long idx[3], double X[3],
                         double *vol) {
  const sph_shape *s = &L->b->shape;
  int in = !L->inside ||
           L->inside[((size_t)idx[0] * (size_t)L->n[1] + (size_t)idx[1]) *
                         (size_t)L->n[2] +
                     (size_t)idx[2]];
  X[0] = X[1] = X[2] = 0.0;
  if (L->faces) {
    *vol = 1.0;
    for (int c = 0; c < L->dim; ++c) {
      /* the last layer sits exactly on the max face */
      X[c] = idx[c] == L->n[c] - 1 ? s->max[c]
                                   : s->min[c] + (double)idx[c] * L->h[c];
      *vol *= (idx[c] == 0 || idx[c] == L->n[c] - 1) ? 0.5 * L->h[c] : L->h[c];
    }
    return in;
  }
  *vol = L->vol;
  for (int c = 0; c < L->dim; ++c)
    X[c] = L->lo[c] + ((double)idx[c] + 0.5) * L->h[c];
  if (L->inside)
    return in;
  return L->box || sph_shape_distance(s, L->dim, X) < 0.0;
}

/* a mesh's lattice, classified at once (a face lattice's points moved
 * towards the box centre by 1e-9 of the way: those on the box's faces are
 * in when the surface holds them) */
static sph_status lattice_mesh(lattice *L, sph_error *err) {
  const sph_shape *s = &L->b->shape;
  double *x[3] = {NULL, NULL, NULL};
  size_t total = (size_t)L->n[0] * (size_t)L->n[1] * (size_t)L->n[2];
  L->inside = malloc(total);
  sph_status st = L->inside ? SPH_OK
                            : sph_error_set(err, SPH_ERR_NOMEM,
                                            "body '%s': %zu lattice points",
                                            L->b->name, total);
  for (int c = 0; st == SPH_OK && c < 3; ++c) {
    if (!(x[c] = malloc((size_t)L->n[c] * sizeof *x[c]))) {
      st = sph_error_set(err, SPH_ERR_NOMEM, "lattice");
      break;
    }
    double mid = 0.5 * (s->min[c] + s->max[c]);
    for (long i = 0; i < L->n[c]; ++i) {
      double X = L->faces ? (i == L->n[c] - 1 ? s->max[c]
                                              : s->min[c] + (double)i * L->h[c])
                          : L->lo[c] + ((double)i + 0.5) * L->h[c];
      x[c][i] = L->faces ? X + 1e-9 * (mid - X) : X;
    }
  }
  if (st == SPH_OK)
    st = sph_mesh_inside_lattice(s->mesh, L->n, (const double *const *)x,
                                 L->inside, err);
  for (int c = 0; c < 3; ++c)
    free(x[c]);
  return st;
}

/* ---- jitter -------------------------------------------------------------- */

/* the next particle's offset, drawn from the body's stream in creation
 * order */
static void jitter(lattice *L, double X[3]) {
  const sph_body *b = L->b;
  const sph_shape *s = &b->shape;
  int dim = L->dim, faces = L->faces;
  double Y[3] = {X[0], X[1], X[2]};
  int inside = 1;
  for (int c = 0; c < dim; ++c) {
    double u = rng_uniform(&L->state); /* drawn always: one stream per seed */
    /* face particles stay on their faces */
    if (faces && (X[c] == s->min[c] || X[c] == s->max[c]))
      continue;
    Y[c] += b->jitter * L->h[c] * u;
    inside = inside && (!faces || (Y[c] > s->min[c] && Y[c] < s->max[c]));
  }
  /* a particle that would leave the shape keeps its lattice place */
  if (faces ? inside : sph_shape_distance(s, dim, Y) < 0.0)
    memcpy(X, Y, sizeof Y);
}

/* ---- bodies -------------------------------------------------------------- */

static const char *shape_name(sph_shape_kind kind) {
  static const char *const names[] = {"box",  "cylinder", "ring",
                                      "disc", "sphere",   "shell",
                                      "mesh", "polygon",  "particles"};
  return (int)kind >= 0 && kind <= SPH_SHAPE_PARTICLES ? names[kind] : "shape";
}

static sph_status check_body(const sph_body *b, int dim, sph_error *err) {
  const sph_shape *s = &b->shape;
  const char *name = shape_name(s->kind);
  if (dim != 2 && dim != 3)
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': dimension must be 2 or 3, got %d", b->name,
                         dim);
  if (dim == 2 && (s->kind == SPH_SHAPE_SPHERE || s->kind == SPH_SHAPE_SHELL ||
                   s->kind == SPH_SHAPE_CYLINDER || s->kind == SPH_SHAPE_MESH))
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': a %s is a 3D shape; in 2D use a %s",
                         b->name, name,
                         s->kind == SPH_SHAPE_CYLINDER ? "box"
                         : s->kind == SPH_SHAPE_MESH   ? "polygon"
                                                       : "disc or ring");
  if (dim == 3 && s->kind == SPH_SHAPE_DISC)
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': a disc is a 2D shape; in 3D use a "
                         "cylinder",
                         b->name);
  if (dim == 3 && s->kind == SPH_SHAPE_RING && !(s->length > 0.0))
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': a ring in 3D is a tube and needs a "
                         "positive length, got %g",
                         b->name, s->length);
  if ((s->kind == SPH_SHAPE_MESH && !s->mesh) ||
      (s->kind == SPH_SHAPE_POLYGON && !s->polygon) ||
      (s->kind == SPH_SHAPE_PARTICLES && !s->cloud))
    return sph_error_set(err, SPH_ERR_GEOMETRY, "body '%s': no %s", b->name,
                         name);
  if (dim == 3 && s->kind == SPH_SHAPE_POLYGON)
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': a polygon is a 2D shape; in 3D use a "
                         "mesh",
                         b->name);
  switch (s->kind) {
  case SPH_SHAPE_PARTICLES:
    if (b->lattice == SPH_LATTICE_FACES || b->distribution != SPH_DIST_LATTICE)
      return sph_error_set(err, SPH_ERR_GEOMETRY,
                           "body '%s': particles from a file take no count "
                           "and are not moved",
                           b->name);
    break;
  case SPH_SHAPE_MESH: /* its bounding box */
  case SPH_SHAPE_POLYGON:
  case SPH_SHAPE_BOX:
    for (int c = 0; c < dim; ++c)
      if (!(s->max[c] > s->min[c]))
        return sph_error_set(err, SPH_ERR_GEOMETRY,
                             "body '%s': empty box, max[%d] = %g <= min[%d] "
                             "= %g",
                             b->name, c, s->max[c], c, s->min[c]);
    break;
  case SPH_SHAPE_DISC:
  case SPH_SHAPE_SPHERE:
  case SPH_SHAPE_CYLINDER:
    if (!(s->radius > 0.0))
      return sph_error_set(err, SPH_ERR_GEOMETRY,
                           "body '%s': the %s radius must be positive, got %g",
                           b->name, name, s->radius);
    break;
  case SPH_SHAPE_RING:
  case SPH_SHAPE_SHELL:
    if (!(s->inner_radius >= 0.0 && s->outer_radius > s->inner_radius))
      return sph_error_set(err, SPH_ERR_GEOMETRY,
                           "body '%s': the %s needs 0 <= inner radius < outer "
                           "radius, got %g and %g",
                           b->name, name, s->inner_radius, s->outer_radius);
    break;
  }
  if (shape_is_axial(s, dim) &&
      (fabs(hypot3(s->axis[0], s->axis[1], s->axis[2]) - 1.0) > 1e-12 ||
       !(s->length > 0.0)))
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': the %s needs a unit axis and a positive "
                         "length, got axis (%g, %g, %g), length %g",
                         b->name, name, s->axis[0], s->axis[1], s->axis[2],
                         s->length);
  if (b->lattice == SPH_LATTICE_FACES) {
    if (s->kind != SPH_SHAPE_BOX && s->kind != SPH_SHAPE_MESH)
      return sph_error_set(err, SPH_ERR_GEOMETRY,
                           "body '%s': particle counts apply to boxes and "
                           "meshes; give a spacing for a %s",
                           b->name, name);
    for (int c = 0; c < dim; ++c)
      if (b->count[c] < 2)
        return sph_error_set(err, SPH_ERR_GEOMETRY,
                             "body '%s': a face lattice needs at least 2 "
                             "particles per axis, got %d on axis %d",
                             b->name, b->count[c], c);
  } else if (!(b->spacing > 0.0 && isfinite(b->spacing))) {
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': spacing must be positive, got %g", b->name,
                         b->spacing);
  }
  if (b->distribution != SPH_DIST_LATTICE &&
      !(b->jitter >= 0.0 && b->jitter < 0.5))
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "body '%s': jitter is a fraction of the spacing in "
                         "[0, 0.5), got %g",
                         b->name, b->jitter);
  return SPH_OK;
}

/* a particle file's body: its particles in the file's order */
static sph_status visit_cloud(const sph_cloud *c, sph_point_fn fn, void *ctx,
                              size_t *n, sph_error *err) {
  for (size_t i = 0; i < c->n; ++i) {
    SPH_TRY(fn(ctx, c->x + 3 * i, c->v[i], err));
    ++*n;
  }
  return SPH_OK;
}

sph_status sph_body_visit(const sph_body *b, int dim, sph_point_fn fn,
                          void *ctx, size_t *n, sph_error *err) {
  *n = 0;
  SPH_TRY(check_body(b, dim, err));
  if (b->shape.kind == SPH_SHAPE_PARTICLES)
    return visit_cloud(b->shape.cloud, fn, ctx, n, err);
  lattice L = {.b = b,
               .dim = dim,
               .faces = b->lattice == SPH_LATTICE_FACES,
               .box = b->shape.kind == SPH_SHAPE_BOX,
               .n = {1, 1, 1},
               .state = (uint64_t)b->seed};
  SPH_TRY(L.faces ? lattice_faces(&L, err) : lattice_cells(&L, err));
  sph_status st =
      b->shape.kind == SPH_SHAPE_MESH ? lattice_mesh(&L, err) : SPH_OK;
  int jittered = b->distribution != SPH_DIST_LATTICE;
  long idx[3];
  for (idx[0] = 0; st == SPH_OK && idx[0] < L.n[0]; ++idx[0])
    for (idx[1] = 0; st == SPH_OK && idx[1] < L.n[1]; ++idx[1])
      for (idx[2] = 0; st == SPH_OK && idx[2] < L.n[2]; ++idx[2]) {
        double X[3], vol;
        if (!lattice_point(&L, idx, X, &vol))
          continue;
        if (jittered)
          jitter(&L, X);
        st = fn(ctx, X, vol, err);
        *n += st == SPH_OK;
      }
  free(L.inside);
  if (st == SPH_OK && *n == 0 && b->shape.kind == SPH_SHAPE_MESH)
    st = sph_error_set(err, SPH_ERR_GEOMETRY,
                       "body '%s' has no particles: no lattice point (spacing "
                       "%g) is inside the mesh %s",
                       b->name, b->spacing, b->shape.file);
  if (st == SPH_OK && *n == 0)
    st = sph_error_set(err, SPH_ERR_GEOMETRY,
                       "body '%s' has no particles: spacing %g is larger than "
                       "the shape",
                       b->name, b->spacing);
  return st;
}

sph_status sph_body_generate(const sph_body *b, int dim, double **x,
                             double **volume, size_t *n, sph_error *err) {
  *x = *volume = NULL;
  *n = 0;
  pointset p = {0};
  sph_status st = sph_body_visit(b, dim, sph_pointset_push, &p, n, err);
  if (st == SPH_ERR_NOMEM)
    st = sph_error_set(err, SPH_ERR_NOMEM, "particles of body '%s'", b->name);
  if (st == SPH_OK && b->distribution == SPH_DIST_RELAX) {
    st = sph_body_relax(b, dim, &p, err);
    /* equal volumes that add up to the exact measure */
    double v = sph_shape_measure(&b->shape, dim) / (double)p.n;
    for (size_t a = 0; st == SPH_OK && a < p.n; ++a)
      p.v[a] = v;
  }
  if (st != SPH_OK) {
    free(p.x);
    free(p.v);
    *n = 0;
    return st;
  }
  *x = p.x;
  *volume = p.v;
  return SPH_OK;
}
