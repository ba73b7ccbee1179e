/* The scene's `bodies:` block: each body's material, shape, particle
 * lattice (count or spacing, jitter, relaxation), initial velocity (uniform,
 * rotation, expressions) and placement (a rotation by Rodrigues' formula and
 * a translation; shape, velocity and own selections in the body frame). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/cloud.h"
#include "scene/expr.h"
#include "scene/mesh.h"
#include "scene/outline_read.h"
#include "scene/polygon.h"
#include "scene/schema_impl.h"

/* a file the scene names: relative to the scene file's folder (to the
 * working one for --set) */
void sph_schema_file_path(const sph_node *fn, const char *file, char *path,
                          size_t size) {
  const char *slash = fn->file ? strrchr(fn->file, '/') : NULL;
  if (file[0] != '/' && slash && fn->file[0] != '<')
    snprintf(path, size, "%.*s/%s", (int)(slash - fn->file), fn->file, file);
  else
    snprintf(path, size, "%s", file);
}

/* the resolved scene (a run's scene_used.yaml) names the file wherever it
 * is read from: its absolute path replaces fn's value */
void sph_schema_name_absolute(sph_node *fn, const char *path) {
  char *abs = realpath(path, NULL);
  if (abs) {
    free(fn->value);
    fn->value = abs;
  }
}

const char *const sph_length_units[] = {"m",  "cm", "mm", "um",
                                        "in", "ft", NULL};
const double sph_length_scale[] = {1.0, 1e-2, 1e-3, 1e-6, 0.0254, 0.3048};

/* a shape's {file, units}: the name kept in sh->file, the path to open
 * (relative to the scene's folder) and the unit's index */
static sph_status shape_file(sph_shape *sh, sph_node *g, const char *what,
                             char *path, size_t size, int *u, sph_node **fn,
                             sph_error *err) {
  const char *file;
  SPH_TRY(sph_node_get_string(g, "file", 1, NULL, &file, err));
  *fn = sph_node_child(g, "file");
  SPH_TRY(sph_node_get_choice(g, "units", sph_length_units, "m", u, err));
  if (!file[0] || strlen(file) >= sizeof sh->file)
    return sph_node_error(*fn, err, SPH_ERR_RANGE,
                          "give the %s file's name (under %zu bytes)", what,
                          sizeof sh->file);
  snprintf(sh->file, sizeof sh->file, "%s", file);
  sph_schema_file_path(*fn, file, path, size);
  return SPH_OK;
}

/* a reader's error ("path: why") placed at the file key, after the shape */
static sph_status shape_file_error(sph_node *fn, const char *what,
                                   sph_status st, sph_error *err) {
  char msg[768];
  snprintf(msg, sizeof msg, "%s", err->message);
  return sph_node_error(fn, err, st, "%s %s", what, msg);
}

/* mesh: {file, units, flip_normals}: the file (relative to the scene's)
 * read, scaled to metres, checked for an inside and an outward surface */
static sph_status parse_mesh(sph_scene *s, sph_shape *sh, sph_node *g,
                             sph_error *err) {
  static const char *const keys[] = {"file", "units", "flip_normals", NULL};
  SPH_TRY(sph_node_check_keys(g, keys, err));
  if (s->dimension != 3)
    return sph_node_error(g, err, SPH_ERR_GEOMETRY,
                          "a mesh is a 3D shape (this scene is 2D)");
  int flip, u;
  sph_node *fn;
  char path[1024];
  SPH_TRY(shape_file(sh, g, "mesh", path, sizeof path, &u, &fn, err));
  SPH_TRY(sph_node_get_bool(g, "flip_normals", 0, 0, &flip, err));
  double *tri;
  size_t n;
  sph_status st = sph_mesh_read(path, &tri, &n, err);
  if (st == SPH_OK) {
    st = sph_mesh_create(&sh->mesh, tri, n, sph_length_scale[u], flip, err);
    free(tri);
  }
  if (st != SPH_OK)
    return shape_file_error(fn, "mesh", st, err);
  sph_schema_name_absolute(fn, path);
  const char *file = sh->file; /* the name as given (fn->value was it) */
  const sph_mesh_info *in = sph_mesh_get_info(sh->mesh);
  double box = 1.0;
  for (int c = 0; c < 3; ++c) {
    sh->min[c] = in->lo[c];
    sh->max[c] = in->hi[c];
    box *= in->hi[c] - in->lo[c];
  }
  if (!(fabs(in->volume) > 1e-9 * box))
    return sph_node_error(fn, err, SPH_ERR_GEOMETRY,
                          "mesh %s encloses no volume (%zu triangles, %zu "
                          "open edges): an open sheet has no inside to fill",
                          file, in->triangles, in->open_edges);
  if (in->volume < 0.0)
    return sph_node_error(
        fn, err, SPH_ERR_GEOMETRY,
        "mesh %s: its volume is negative (%.4g m^3): the triangles face "
        "inwards; %s",
        file, in->volume,
        flip ? "remove flip_normals: true" : "set flip_normals: true");
  return SPH_OK;
}

/* one ring of [x, y] pairs appended to *xy (grown by realloc) */
static sph_status parse_ring(sph_node *ring, double **xy, size_t *n,
                             sph_error *err) {
  if (ring->kind != SPH_NODE_SEQ)
    return sph_node_error(ring, err, SPH_ERR_TYPE,
                          "expected a list of points [[x, y], ...]");
  if (ring->count > 1000000)
    return sph_node_error(ring, err, SPH_ERR_RANGE,
                          "%zu points: at most 1e6 a ring", ring->count);
  double *grown = realloc(*xy, 2 * (*n + ring->count) * sizeof *grown);
  if (!grown)
    return sph_error_set(err, SPH_ERR_NOMEM, "polygon");
  *xy = grown;
  for (size_t i = 0; i < ring->count; ++i) {
    sph_node *pt = ring->items[i];
    if (pt->kind != SPH_NODE_SEQ || pt->count != 2)
      return sph_node_error(pt, err, SPH_ERR_TYPE, "expected a point [x, y]");
    for (int c = 0; c < 2; ++c)
      SPH_TRY(sph_node_as_double(pt->items[c], &grown[2 * *n + c], err));
    ++*n;
  }
  return SPH_OK;
}

/* polygon: {points: [[x, y], ...], holes: [[[x, y], ...], ...]} */
static sph_status parse_polygon(sph_scene *s, sph_shape *sh, sph_node *g,
                                sph_error *err) {
  static const char *const keys[] = {"points", "holes", NULL};
  SPH_TRY(sph_node_check_keys(g, keys, err));
  if (s->dimension != 2)
    return sph_node_error(g, err, SPH_ERR_GEOMETRY,
                          "a polygon is a 2D shape (in 3D use a mesh)");
  sph_node *pts, *holes;
  SPH_TRY(sph_schema_get_seq(g, "points", 1, &pts, err));
  SPH_TRY(sph_schema_get_seq(g, "holes", 0, &holes, err));
  size_t nr = 1 + (holes ? holes->count : 0), n = 0;
  size_t *start = malloc((nr + 1) * sizeof *start);
  double *xy = NULL;
  if (!start)
    return sph_error_set(err, SPH_ERR_NOMEM, "polygon");
  start[0] = 0;
  sph_status st = SPH_OK;
  for (size_t r = 0; st == SPH_OK && r < nr; ++r) {
    st = parse_ring(r ? holes->items[r - 1] : pts, &xy, &n, err);
    start[r + 1] = n;
  }
  if (st == SPH_OK &&
      (st = sph_polygon_create(&sh->polygon, xy, start, nr, err)) != SPH_OK) {
    char msg[768];
    snprintf(msg, sizeof msg, "%s", err->message);
    st = sph_node_error(g, err, st, "polygon: %s", msg);
  }
  free(xy);
  free(start);
  if (st == SPH_OK)
    sph_polygon_bounds(sh->polygon, sh->min, sh->max);
  return st;
}

/* points [a, b) of xy in reverse order */
static void reverse_points(double *xy, size_t a, size_t b) {
  for (; a + 1 < b; ++a, --b)
    for (int c = 0; c < 2; ++c) {
      double t = xy[2 * a + c];
      xy[2 * a + c] = xy[2 * (b - 1) + c];
      xy[2 * (b - 1) + c] = t;
    }
}

/* the ring of largest area first: the outline, the others its holes */
static void outline_first(double *xy, size_t *start, size_t nr) {
  size_t best = 0;
  double most = -1.0;
  for (size_t r = 0; r < nr; ++r) {
    double a = 0.0;
    for (size_t i = start[r]; i < start[r + 1]; ++i) {
      size_t j = i + 1 < start[r + 1] ? i + 1 : start[r];
      a += xy[2 * i] * xy[2 * j + 1] - xy[2 * j] * xy[2 * i + 1];
    }
    if (fabs(a) > most) {
      most = fabs(a);
      best = r;
    }
  }
  /* rings [0, best] turned right by ring best's length: three reversals */
  size_t len = start[best + 1] - start[best], end = start[best + 1];
  reverse_points(xy, 0, end);
  reverse_points(xy, 0, len);
  reverse_points(xy, len, end);
  for (size_t r = best; r > 0; --r)
    start[r] = start[r - 1] + len;
}

/* outline: {file, units}: a CSV or SVG outline (outline_read.c) */
static sph_status parse_outline(sph_scene *s, sph_shape *sh, sph_node *g,
                                sph_error *err) {
  static const char *const keys[] = {"file", "units", NULL};
  SPH_TRY(sph_node_check_keys(g, keys, err));
  if (s->dimension != 2)
    return sph_node_error(g, err, SPH_ERR_GEOMETRY,
                          "an outline is a 2D shape (in 3D use a mesh)");
  int u;
  sph_node *fn;
  char path[1024];
  SPH_TRY(shape_file(sh, g, "outline", path, sizeof path, &u, &fn, err));
  double *xy;
  size_t *start, nr;
  sph_status st = sph_outline_read(path, &xy, &start, &nr, err);
  if (st == SPH_OK) {
    for (size_t i = 0; i < 2 * start[nr]; ++i)
      xy[i] *= sph_length_scale[u];
    outline_first(xy, start, nr);
    st = sph_polygon_create(&sh->polygon, xy, start, nr, err);
    free(xy);
    free(start);
  }
  if (st != SPH_OK)
    return shape_file_error(fn, "outline", st, err);
  sph_schema_name_absolute(fn, path);
  sph_polygon_bounds(sh->polygon, sh->min, sh->max);
  return SPH_OK;
}

/* particles: {file, units}: positions and optional volumes from a CSV or a
 * .vtp (cloud.c) */
static sph_status parse_cloud(sph_scene *s, sph_shape *sh, sph_node *g,
                              sph_error *err) {
  static const char *const keys[] = {"file", "units", NULL};
  SPH_TRY(sph_node_check_keys(g, keys, err));
  int u;
  sph_node *fn;
  char path[1024];
  SPH_TRY(shape_file(sh, g, "particle", path, sizeof path, &u, &fn, err));
  sph_status st =
      sph_cloud_read(path, s->dimension, sph_length_scale[u], &sh->cloud, err);
  if (st != SPH_OK)
    return shape_file_error(fn, "particles", st, err);
  sph_schema_name_absolute(fn, path);
  for (int c = 0; c < 3; ++c) {
    sh->min[c] = sh->cloud->lo[c];
    sh->max[c] = sh->cloud->hi[c];
  }
  return SPH_OK;
}

static sph_status parse_shape(sph_scene *s, sph_shape *sh, sph_node *n,
                              sph_error *err) {
  static const char *const kinds[] = {"box",     "cylinder",  "ring", "disc",
                                      "sphere",  "shell",     "mesh", "polygon",
                                      "outline", "particles", NULL};
  if (n->kind != SPH_NODE_MAP)
    return sph_node_error(n, err, SPH_ERR_TYPE, "expected a mapping");
  SPH_TRY(sph_node_check_keys(n, kinds, err));
  int which;
  SPH_TRY(sph_schema_one_of(n, kinds, "shape", &which, err));
  static const sph_shape_kind map[] = {
      SPH_SHAPE_BOX,     SPH_SHAPE_CYLINDER, SPH_SHAPE_RING, SPH_SHAPE_DISC,
      SPH_SHAPE_SPHERE,  SPH_SHAPE_SHELL,    SPH_SHAPE_MESH, SPH_SHAPE_POLYGON,
      SPH_SHAPE_POLYGON, SPH_SHAPE_PARTICLES};
  memset(sh, 0, sizeof *sh);
  sh->kind = map[which];
  sph_node *g;
  SPH_TRY(sph_node_get_map(n, kinds[which], 1, &g, err));
  int d = s->dimension;
  switch (sh->kind) {
  case SPH_SHAPE_MESH:
    return parse_mesh(s, sh, g, err);
  case SPH_SHAPE_POLYGON:
    return which == 8 ? parse_outline(s, sh, g, err)
                      : parse_polygon(s, sh, g, err);
  case SPH_SHAPE_PARTICLES:
    return parse_cloud(s, sh, g, err);
  case SPH_SHAPE_BOX: {
    static const char *const keys[] = {"min", "max", NULL};
    SPH_TRY(sph_node_check_keys(g, keys, err));
    SPH_TRY(sph_node_get_doubles(g, "min", 1, (size_t)d, sh->min, NULL, err));
    SPH_TRY(sph_node_get_doubles(g, "max", 1, (size_t)d, sh->max, NULL, err));
    for (int c = 0; c < d; ++c)
      if (!(sh->max[c] > sh->min[c]))
        return sph_node_error(sph_node_child(g, "max"), err, SPH_ERR_GEOMETRY,
                              "empty box: max must exceed min on every axis "
                              "(axis %s: %g <= %g)",
                              sph_axis_names[c], sh->max[c], sh->min[c]);
    break;
  }
  case SPH_SHAPE_DISC:
  case SPH_SHAPE_SPHERE: {
    static const char *const keys[] = {"center", "radius", NULL};
    SPH_TRY(sph_node_check_keys(g, keys, err));
    SPH_TRY(
        sph_node_get_doubles(g, "center", 1, (size_t)d, sh->center, NULL, err));
    sph_node *r = sph_node_child(g, "radius");
    SPH_TRY(sph_node_get_double(g, "radius", 1, 0, &sh->radius, err));
    if (!(sh->radius > 0))
      return sph_node_error(r, err, SPH_ERR_GEOMETRY,
                            "empty shape: radius must be positive, got %g",
                            sh->radius);
    break;
  }
  case SPH_SHAPE_CYLINDER: {
    static const char *const keys[] = {"center", "axis", "radius", "length",
                                       NULL};
    SPH_TRY(sph_node_check_keys(g, keys, err));
    SPH_TRY(sph_node_get_doubles(g, "center", 1, 3, sh->center, NULL, err));
    SPH_TRY(sph_schema_get_direction(g, "axis", 0, 2, 3, sh->axis, err));
    SPH_TRY(sph_node_get_double(g, "radius", 1, 0, &sh->radius, err));
    if (!(sh->radius > 0))
      return sph_node_error(sph_node_child(g, "radius"), err, SPH_ERR_GEOMETRY,
                            "empty shape: radius must be positive, got %g",
                            sh->radius);
    SPH_TRY(sph_node_get_double(g, "length", 1, 0, &sh->length, err));
    if (!(sh->length > 0))
      return sph_node_error(sph_node_child(g, "length"), err, SPH_ERR_GEOMETRY,
                            "empty shape: length must be positive, got %g",
                            sh->length);
    break;
  }
  case SPH_SHAPE_RING:
  case SPH_SHAPE_SHELL: {
    int tube = sh->kind == SPH_SHAPE_RING && d == 3;
    static const char *const keys2[] = {"center", "inner_radius",
                                        "outer_radius", NULL};
    static const char *const keys3[] = {
        "center", "inner_radius", "outer_radius", "axis", "length", NULL};
    SPH_TRY(sph_node_check_keys(g, tube ? keys3 : keys2, err));
    SPH_TRY(sph_node_get_doubles(g, "center", 1, tube ? 3 : (size_t)d,
                                 sh->center, NULL, err));
    SPH_TRY(
        sph_node_get_double(g, "inner_radius", 1, 0, &sh->inner_radius, err));
    SPH_TRY(
        sph_node_get_double(g, "outer_radius", 1, 0, &sh->outer_radius, err));
    if (!(sh->inner_radius >= 0 && sh->outer_radius > sh->inner_radius))
      return sph_node_error(sph_node_child(g, "outer_radius"), err,
                            SPH_ERR_GEOMETRY,
                            "empty shape: need 0 <= inner_radius < "
                            "outer_radius, got %g and %g",
                            sh->inner_radius, sh->outer_radius);
    if (tube) {
      SPH_TRY(sph_schema_get_direction(g, "axis", 0, 2, 3, sh->axis, err));
      SPH_TRY(sph_node_get_double(g, "length", 1, 0, &sh->length, err));
      if (!(sh->length > 0))
        return sph_node_error(
            sph_node_child(g, "length"), err, SPH_ERR_GEOMETRY,
            "empty shape: length must be positive, got %g", sh->length);
    }
    break;
  }
  }
  int is3d = sh->kind == SPH_SHAPE_SPHERE || sh->kind == SPH_SHAPE_SHELL ||
             sh->kind == SPH_SHAPE_CYLINDER;
  if ((d == 2 && is3d) || (d == 3 && sh->kind == SPH_SHAPE_DISC))
    return sph_node_error(
        sph_node_child(n, kinds[which]), err, SPH_ERR_GEOMETRY,
        "a %s does not exist in %dD (2D: box, disc, ring, polygon; "
        "3D: box, cylinder, ring, sphere, shell, mesh)",
        kinds[which], d);
  return SPH_OK;
}

static sph_status parse_particles(sph_scene *s, sph_body *b, sph_node *n,
                                  sph_error *err) {
  static const char *const keys[] = {"count",  "spacing", "distribution",
                                     "jitter", "seed",    "relax_steps",
                                     NULL};
  SPH_TRY(sph_node_check_keys(n, keys, err));
  static const char *const how[] = {"count", "spacing", NULL};
  int which;
  SPH_TRY(sph_schema_one_of(n, how, "of count or spacing", &which, err));
  int d = s->dimension;
  if (which == 0) {
    if (b->shape.kind != SPH_SHAPE_BOX && b->shape.kind != SPH_SHAPE_MESH)
      return sph_node_error(sph_node_child(n, "count"), err, SPH_ERR_ARG,
                            "particle counts apply to boxes and meshes; give "
                            "a spacing for other shapes");
    double c[3];
    SPH_TRY(sph_node_get_doubles(n, "count", 1, (size_t)d, c, NULL, err));
    b->lattice = SPH_LATTICE_FACES;
    b->spacing = INFINITY;
    for (int k = 0; k < d; ++k) {
      if (c[k] != floor(c[k]) || c[k] < 2 || c[k] > 1e6)
        return sph_node_error(sph_node_child(n, "count"), err, SPH_ERR_RANGE,
                              "counts must be whole numbers from 2 to 1e6, "
                              "got %g",
                              c[k]);
      b->count[k] = (int)c[k];
      double h = (b->shape.max[k] - b->shape.min[k]) / (c[k] - 1);
      b->spacing = h < b->spacing ? h : b->spacing;
    }
  } else {
    b->lattice = SPH_LATTICE_CELL_CENTRED;
    SPH_TRY(sph_node_get_positive(n, "spacing", 1, 0, &b->spacing, err));
  }
  static const char *const dists[] = {"lattice", "jitter", "relax", NULL};
  const char *dist;
  SPH_TRY(sph_node_get_string(n, "distribution", 0, "lattice", &dist, err));
  int dk = -1;
  for (int i = 0; dists[i]; ++i)
    if (!strcmp(dist, dists[i]))
      dk = i;
  if (dk < 0)
    return sph_node_error(sph_node_child(n, "distribution"), err, SPH_ERR_RANGE,
                          "distribution must be lattice, jitter or relax, got "
                          "'%s'",
                          dist);
  b->distribution = (sph_distribution)dk;
  if (dk == SPH_DIST_RELAX &&
      (b->shape.kind == SPH_SHAPE_MESH || b->shape.kind == SPH_SHAPE_POLYGON))
    return sph_node_error(sph_node_child(n, "distribution"), err, SPH_ERR_ARG,
                          "a %s body is not relaxed yet: use lattice or "
                          "jitter",
                          b->shape.kind == SPH_SHAPE_MESH ? "mesh" : "polygon");
  if (dk != SPH_DIST_LATTICE) {
    SPH_TRY(sph_node_get_double(n, "jitter", 0, 0.25, &b->jitter, err));
    if (!(b->jitter >= 0.0 && b->jitter < 0.5))
      return sph_node_error(sph_node_child(n, "jitter"), err, SPH_ERR_RANGE,
                            "jitter is a fraction of the spacing in [0, 0.5), "
                            "got %g",
                            b->jitter);
    long seed, steps = 0;
    SPH_TRY(sph_node_get_int(n, "seed", 0, 1, &seed, err));
    if (seed < 0)
      return sph_node_error(sph_node_child(n, "seed"), err, SPH_ERR_RANGE,
                            "seed must be >= 0");
    b->seed = (unsigned long)seed;
    if (dk == SPH_DIST_RELAX) {
      SPH_TRY(sph_node_get_int(n, "relax_steps", 0, 100, &steps, err));
      if (steps < 0 || steps > 100000)
        return sph_node_error(sph_node_child(n, "relax_steps"), err,
                              SPH_ERR_RANGE,
                              "relax_steps must be in [0, "
                              "100000]");
    }
    b->relax_steps = (int)steps;
  }
  return SPH_OK;
}

static sph_status make_expr(sph_node *n, sph_expr **out, sph_error *err) {
  if (n->kind != SPH_NODE_SCALAR)
    return sph_node_error(n, err, SPH_ERR_TYPE, "expected an expression");
  sph_status st = sph_expr_create(out, n->value, err);
  if (st != SPH_OK) {
    char msg[768];
    snprintf(msg, sizeof msg, "%s", err->message);
    return sph_node_error(n, err, st, "%s", msg);
  }
  return SPH_OK;
}

static sph_status parse_velocity(sph_scene *s, sph_velocity *v, sph_node *n,
                                 sph_error *err) {
  static const char *const kinds[] = {"uniform", "rotation", "expression",
                                      NULL};
  if (n->kind != SPH_NODE_MAP)
    return sph_node_error(n, err, SPH_ERR_TYPE, "expected a mapping");
  SPH_TRY(sph_node_check_keys(n, kinds, err));
  int which;
  SPH_TRY(sph_schema_one_of(n, kinds, "initial velocity", &which, err));
  if (which == 0) {
    v->kind = SPH_VEL_UNIFORM;
    SPH_TRY(sph_node_get_doubles(n, "uniform", 1, 3, v->value, NULL, err));
  } else if (which == 1) {
    v->kind = SPH_VEL_ROTATION;
    sph_node *r;
    SPH_TRY(sph_node_get_map(n, "rotation", 1, &r, err));
    static const char *const keys[] = {"axis", "omega", "center", "profile",
                                       NULL};
    SPH_TRY(sph_node_check_keys(r, keys, err));
    SPH_TRY(sph_schema_get_direction(r, "axis", 1, 2, 3, v->axis, err));
    SPH_TRY(sph_node_get_double(r, "omega", 1, 0, &v->omega, err));
    if (sph_node_child(r, "center"))
      SPH_TRY(sph_node_get_doubles(r, "center", 1, 3, v->center, NULL, err));
    else
      SPH_TRY(sph_node_insert_default(r, "center", "[0, 0, 0]",
                                      &(sph_node *){0}, err));
    sph_node *p = sph_node_child(r, "profile");
    if (p) {
      p->used = 1;
      SPH_TRY(make_expr(p, &v->profile, err));
    }
  } else {
    v->kind = SPH_VEL_EXPRESSION;
    sph_node *e;
    SPH_TRY(sph_schema_get_seq(n, "expression", 1, &e, err));
    if (e->count != 3)
      return sph_node_error(e, err, SPH_ERR_TYPE,
                            "expected three expressions (vx, vy, vz), got %zu",
                            e->count);
    for (int c = 0; c < 3; ++c)
      SPH_TRY(make_expr(e->items[c], &v->expr[c], err));
  }
  (void)s;
  return SPH_OK;
}

/* cos and sin of an angle in degrees, exact at multiples of 90 */
static void cos_sin_degrees(double deg, double *c, double *sn) {
  double q = fmod(deg, 360.0);
  q += q < 0.0 ? 360.0 : 0.0;
  static const double exact[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  if (fmod(q, 90.0) == 0.0) {
    *c = exact[(int)(q / 90.0) % 4][0];
    *sn = exact[(int)(q / 90.0) % 4][1];
    return;
  }
  *c = cos(deg * M_PI / 180.0);
  *sn = sin(deg * M_PI / 180.0);
}

/* transform: {rotate: {axis, angle}, translate}; R by Rodrigues' formula
 * R = cos I + sin [a]x + (1 - cos) a a^T; 2D rotates about z */
static sph_status parse_transform(sph_scene *s, sph_transform *T, sph_node *n,
                                  sph_error *err) {
  static const char *const keys[] = {"rotate", "translate", NULL};
  SPH_TRY(sph_node_check_keys(n, keys, err));
  int d = s->dimension;
  memset(T, 0, sizeof *T);
  T->given = 1;
  T->R[0] = T->R[4] = T->R[8] = 1.0;
  sph_node *r;
  SPH_TRY(sph_node_get_map(n, "rotate", 0, &r, err));
  if (r) {
    static const char *const k3[] = {"axis", "angle", NULL};
    if (d == 2 && sph_node_child(r, "axis"))
      return sph_node_error(sph_node_child(r, "axis"), err, SPH_ERR_ARG,
                            "a 2D rotation is about z: give only the angle");
    SPH_TRY(sph_node_check_keys(r, k3, err));
    double a[3] = {0.0, 0.0, 1.0}, deg, c, sn;
    if (d == 3)
      SPH_TRY(sph_schema_get_direction(r, "axis", 1, 2, 3, a, err));
    SPH_TRY(sph_node_get_double(r, "angle", 1, 0, &deg, err));
    if (!isfinite(deg))
      return sph_node_error(sph_node_child(r, "angle"), err, SPH_ERR_RANGE,
                            "the angle (degrees) must be finite");
    cos_sin_degrees(deg, &c, &sn);
    const double ax[9] = {0, -a[2], a[1], a[2], 0, -a[0], -a[1], a[0], 0};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        T->R[3 * i + j] =
            (i == j) * c + sn * ax[3 * i + j] + (1.0 - c) * a[i] * a[j];
  }
  SPH_TRY(sph_node_get_doubles(n, "translate", 0, (size_t)d, T->t, NULL, err));
  return SPH_OK;
}

/* a particle file's body: its spacing given (`particles: {spacing}`) or
 * estimated, the volumes of a file without them dp^d; no count, no jitter */
static sph_status cloud_spacing(sph_scene *s, sph_body *b, sph_node *shape,
                                sph_node *parts, sph_error *err) {
  sph_shape *sh = &b->shape;
  sph_node *sp = parts ? sph_node_child(parts, "spacing") : NULL;
  if (parts && sph_node_child(parts, "count"))
    return sph_node_error(sph_node_child(parts, "count"), err, SPH_ERR_ARG,
                          "the particles come from %s: give a spacing, or "
                          "none (it is estimated)",
                          sh->file);
  if (parts && b->distribution != SPH_DIST_LATTICE)
    return sph_node_error(sph_node_child(parts, "distribution"), err,
                          SPH_ERR_ARG,
                          "the particles come from %s: they are not moved "
                          "(distribution: lattice)",
                          sh->file);
  b->lattice = SPH_LATTICE_CELL_CENTRED;
  sh->spacing_estimated = !sp;
  if (!sp)
    b->spacing = sh->cloud->nn_median;
  if (!(b->spacing > 0.0))
    return sph_node_error(shape, err, SPH_ERR_ARG,
                          "%s holds one particle: its spacing cannot be "
                          "estimated; give particles: {spacing: ...}",
                          sh->file);
  sph_cloud_set_volumes(sh->cloud, s->dimension, b->spacing);
  return SPH_OK;
}

sph_status sph_schema_bodies(sph_scene *s, sph_node *root, sph_error *err) {
  sph_node *list;
  SPH_TRY(sph_schema_get_seq(root, "bodies", 1, &list, err));
  if (list->count == 0)
    return sph_node_error(list, err, SPH_ERR_MISSING_KEY,
                          "define at least one body");
  s->bodies = calloc(list->count, sizeof *s->bodies);
  if (!s->bodies)
    return sph_error_set(err, SPH_ERR_NOMEM, "bodies");
  static const char *const keys[] = {
      "name",      "material", "shape", "particles", "initial_velocity",
      "transform", NULL};
  for (size_t i = 0; i < list->count; ++i) {
    sph_node *n = list->items[i];
    sph_body *b = &s->bodies[i];
    s->nbodies++;
    if (n->kind != SPH_NODE_MAP)
      return sph_node_error(n, err, SPH_ERR_TYPE,
                            "expected a body (a mapping)");
    SPH_TRY(sph_node_check_keys(n, keys, err));
    b->line = n->line;
    b->col = n->col;
    const char *name, *mat;
    SPH_TRY(sph_node_get_string(n, "name", 1, NULL, &name, err));
    if (!name[0])
      return sph_node_error(sph_node_child(n, "name"), err, SPH_ERR_RANGE,
                            "a body needs a name");
    sph_schema_copy_name(b->name, name);
    for (size_t j = 0; j < i; ++j)
      if (!strcmp(s->bodies[j].name, name))
        return sph_node_error(sph_node_child(n, "name"), err, SPH_ERR_ARG,
                              "two bodies are named '%s'", name);
    SPH_TRY(sph_node_get_string(n, "material", 1, NULL, &mat, err));
    b->material = sph_scene_find_material(s, mat);
    if (b->material < 0) {
      const char *names[64];
      size_t k = 0;
      for (; k < s->nmaterials && k < 63; ++k)
        names[k] = s->materials[k].name;
      names[k] = NULL;
      const char *hint = sph_suggest(mat, names);
      return sph_node_error(sph_node_child(n, "material"), err, SPH_ERR_ARG,
                            "no material named '%s'%s%s%s", mat,
                            hint ? "; did you mean '" : "", hint ? hint : "",
                            hint ? "'?" : "");
    }
    sph_node *shape, *parts, *vel;
    SPH_TRY(sph_node_get_map(n, "shape", 1, &shape, err));
    SPH_TRY(parse_shape(s, &b->shape, shape, err));
    int file = b->shape.kind == SPH_SHAPE_PARTICLES;
    SPH_TRY(sph_node_get_map(n, "particles", !file, &parts, err));
    if (parts)
      SPH_TRY(parse_particles(s, b, parts, err));
    if (file)
      SPH_TRY(cloud_spacing(s, b, shape, parts, err));
    SPH_TRY(sph_node_get_map(n, "initial_velocity", 0, &vel, err));
    if (vel)
      SPH_TRY(parse_velocity(s, &b->velocity, vel, err));
    sph_node *tr;
    SPH_TRY(sph_node_get_map(n, "transform", 0, &tr, err));
    if (tr)
      SPH_TRY(parse_transform(s, &b->transform, tr, err));
  }
  return SPH_OK;
}
