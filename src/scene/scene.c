/* The scene schema (DESIGN.md sec. 6): every key of a YAML scene checked,
 * typed and defaulted, with errors at the file, line, column and key; and
 * the particles the bodies make, with the checks that need them (empty or
 * overlapping bodies, selections that select nothing, probes outside every
 * body). Axes and normals are x, y, z or any vector; a body may be placed
 * by a rotation (Rodrigues' formula) and a translation, its shape, initial
 * velocity and own selections being given in its frame. The method and
 * reference blocks are left to their users. Over MPI ranks a rank can make
 * its share of the particles alone (issue 20): the bodies' particles
 * visited three times, counted per cell of the Morton order's grid. */
#include "scene/scene.h"

#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/neighbors.h"
#include "scene/expr.h"
#include "scene/geometry.h"
#include "solver/stability.h"

static const char *const axis_names[] = {"x", "y", "z", NULL};

/* ---- small readers
 * ----------------------------------------------------------- */

static sph_status get_seq(sph_node *map, const char *key, int required,
                          sph_node **out, sph_error *err) {
  *out = sph_node_child(map, key);
  if (!*out) {
    return required ? sph_node_missing(map, key, err) : SPH_OK;
  }
  (*out)->used = 1;
  if ((*out)->kind != SPH_NODE_SEQ)
    return sph_node_error(*out, err, SPH_ERR_TYPE,
                          "expected a sequence (a list with '-' items)");
  return SPH_OK;
}

static sph_status get_axis(sph_node *map, const char *key, int required,
                           int def, int *out, sph_error *err) {
  const char *name;
  SPH_TRY(sph_node_get_string(map, key, required, axis_names[def], &name, err));
  for (int a = 0; a < 3; ++a)
    if (!strcmp(name, axis_names[a])) {
      *out = a;
      return SPH_OK;
    }
  return sph_node_error(sph_node_child(map, key), err, SPH_ERR_RANGE,
                        "%s must be x, y, z or a vector [a, b, c], got '%s'",
                        key, name);
}

/* A direction: x, y or z, or a non-zero vector of n numbers (n = 2 leaves
 * z = 0), scaled to unit length. */
static sph_status get_direction(sph_node *map, const char *key, int required,
                                int def, int n, double out[3], sph_error *err) {
  sph_node *c = sph_node_child(map, key);
  out[0] = out[1] = out[2] = 0.0;
  if (!c || c->kind != SPH_NODE_SEQ) {
    int a = def;
    SPH_TRY(get_axis(map, key, required, def, &a, err));
    out[a] = 1.0;
    return SPH_OK;
  }
  SPH_TRY(sph_node_get_doubles(map, key, 1, (size_t)n, out, NULL, err));
  /* scaled by the largest component first: no underflow of tiny vectors */
  double big = fmax(fabs(out[0]), fmax(fabs(out[1]), fabs(out[2]))), len = 0;
  for (int k = 0; big > 0 && isfinite(big) && k < 3; ++k) {
    out[k] /= big;
    len += out[k] * out[k];
  }
  if (!(len > 0.0))
    return sph_node_error(c, err, SPH_ERR_RANGE,
                          "%s must be a non-zero, finite vector", key);
  len = sqrt(len);
  for (int k = 0; k < 3; ++k)
    out[k] /= len;
  return SPH_OK;
}

static sph_status positive(sph_node *map, const char *key, int required,
                           double def, double *out, sph_error *err) {
  SPH_TRY(sph_node_get_double(map, key, required, def, out, err));
  if (!(*out > 0.0))
    return sph_node_error(sph_node_child(map, key), err, SPH_ERR_RANGE,
                          "must be positive, got %g", *out);
  return SPH_OK;
}

/* The one key of `map` among `choices`; errors when none or several. */
static sph_status one_of(sph_node *map, const char *const *choices,
                         const char *what, int *which, sph_error *err) {
  *which = -1;
  char list[256] = "";
  for (int i = 0; choices[i]; ++i) {
    strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
    strncat(list, choices[i], sizeof list - strlen(list) - 1);
    if (!sph_node_child(map, choices[i]))
      continue;
    if (*which >= 0)
      return sph_node_error(sph_node_child(map, choices[i]), err, SPH_ERR_ARG,
                            "give only one %s: '%s' and '%s'", what,
                            choices[*which], choices[i]);
    *which = i;
  }
  if (*which < 0)
    return sph_node_error(map, err, SPH_ERR_MISSING_KEY, "give one %s (%s)",
                          what, list);
  return SPH_OK;
}

static void copy_name(char *dst, const char *src) {
  snprintf(dst, SPH_NAME_MAX, "%s", src);
}

/* ---- sections --------------------------------------------------------------
 */

static sph_status parse_kernel(sph_scene *s, sph_node *root, sph_error *err) {
  sph_node *k;
  SPH_TRY(sph_node_insert_default(root, "kernel", "{}", &k, err));
  if (k->kind != SPH_NODE_MAP)
    return sph_node_error(k, err, SPH_ERR_TYPE, "expected a mapping");
  static const char *const keys[] = {"type", "h_over_dp", NULL};
  SPH_TRY(sph_node_check_keys(k, keys, err));
  const char *type;
  SPH_TRY(sph_node_get_string(k, "type", 0, "cubic", &type, err));
  int t = sph_kernel_type_from_name(type);
  if (t < 0)
    return sph_node_error(sph_node_child(k, "type"), err, SPH_ERR_RANGE,
                          "unknown kernel '%s' (known: cubic, quintic, "
                          "wendland-c2, wendland-c4)",
                          type);
  s->kernel_type = (sph_kernel_type)t;
  SPH_TRY(sph_node_get_double(k, "h_over_dp", 0, 1.3, &s->h_over_dp, err));
  if (!(s->h_over_dp >= 0.8 && s->h_over_dp <= 4.0))
    return sph_node_error(sph_node_child(k, "h_over_dp"), err, SPH_ERR_RANGE,
                          "must be in [0.8, 4], got %g", s->h_over_dp);
  return SPH_OK;
}

static sph_status parse_material(sph_material *m, const char *name, sph_node *n,
                                 sph_error *err) {
  if (n->kind != SPH_NODE_MAP)
    return sph_node_error(n, err, SPH_ERR_TYPE,
                          "expected a mapping of material parameters");
  static const char *const keys[] = {"model",
                                     "density",
                                     "youngs_modulus",
                                     "poisson_ratio",
                                     "shear_modulus",
                                     "bulk_modulus",
                                     "xi",
                                     NULL};
  SPH_TRY(sph_node_check_keys(n, keys, err));
  sph_material_params p = {0};
  SPH_TRY(sph_node_get_string(n, "model", 0, "neo-hookean", &p.model, err));
  int known = 0;
  for (const char *const *mname = sph_material_models(); *mname; ++mname)
    known |= !strcmp(*mname, p.model);
  if (!known) {
    const char *hint = sph_suggest(p.model, sph_material_models());
    return sph_node_error(sph_node_child(n, "model"), err, SPH_ERR_RANGE,
                          "unknown model '%s'%s%s%s", p.model,
                          hint ? "; did you mean '"
                               : " (known: linear-"
                                 "elastic, neo-hookean, "
                                 "mooney-rivlin)",
                          hint ? hint : "", hint ? "'?" : "");
  }
  SPH_TRY(positive(n, "density", 1, 0, &p.density, err));
  p.has_youngs =
      sph_node_child(n, "youngs_modulus") || sph_node_child(n, "poisson_ratio");
  p.has_moduli =
      sph_node_child(n, "shear_modulus") || sph_node_child(n, "bulk_modulus");
  if (p.has_youngs && p.has_moduli)
    return sph_node_error(n, err, SPH_ERR_ARG,
                          "give youngs_modulus and poisson_ratio, or "
                          "shear_modulus and bulk_modulus, not both");
  if (!p.has_youngs && !p.has_moduli)
    return sph_node_error(n, err, SPH_ERR_MISSING_KEY,
                          "give youngs_modulus and poisson_ratio (or "
                          "shear_modulus and bulk_modulus)");
  if (p.has_youngs) {
    SPH_TRY(positive(n, "youngs_modulus", 1, 0, &p.youngs_modulus, err));
    SPH_TRY(
        sph_node_get_double(n, "poisson_ratio", 1, 0, &p.poisson_ratio, err));
    if (!(p.poisson_ratio > -1.0 && p.poisson_ratio < 0.5))
      return sph_node_error(sph_node_child(n, "poisson_ratio"), err,
                            SPH_ERR_RANGE, "must be in (-1, 0.5), got %g",
                            p.poisson_ratio);
  } else {
    SPH_TRY(positive(n, "shear_modulus", 1, 0, &p.shear_modulus, err));
    SPH_TRY(positive(n, "bulk_modulus", 1, 0, &p.bulk_modulus, err));
  }
  if (sph_node_child(n, "xi")) {
    p.has_xi = 1;
    SPH_TRY(sph_node_get_double(n, "xi", 1, 0, &p.xi, err));
  }
  sph_status st = sph_material_create(m, &p, err);
  if (st != SPH_OK) {
    sph_node *at = sph_node_child(n, "xi") ? sph_node_child(n, "xi") : n;
    char msg[768];
    snprintf(msg, sizeof msg, "%s", err->message);
    return sph_node_error(at, err, st, "%s", msg);
  }
  copy_name(m->name, name);
  return SPH_OK;
}

static sph_status parse_materials(sph_scene *s, sph_node *root,
                                  sph_error *err) {
  sph_node *mats;
  SPH_TRY(sph_node_get_map(root, "materials", 1, &mats, err));
  if (mats->count == 0)
    return sph_node_error(mats, err, SPH_ERR_MISSING_KEY,
                          "define at least one material");
  s->materials = calloc(mats->count, sizeof *s->materials);
  if (!s->materials)
    return sph_error_set(err, SPH_ERR_NOMEM, "materials");
  for (size_t i = 0; i < mats->count; ++i) {
    SPH_TRY(
        parse_material(&s->materials[i], mats->keys[i], mats->items[i], err));
    mats->items[i]->used = 1;
    s->nmaterials++;
  }
  return SPH_OK;
}

static sph_status parse_shape(sph_scene *s, sph_shape *sh, sph_node *n,
                              sph_error *err) {
  static const char *const kinds[] = {"box",    "cylinder", "ring", "disc",
                                      "sphere", "shell",    NULL};
  if (n->kind != SPH_NODE_MAP)
    return sph_node_error(n, err, SPH_ERR_TYPE, "expected a mapping");
  SPH_TRY(sph_node_check_keys(n, kinds, err));
  int which;
  SPH_TRY(one_of(n, kinds, "shape", &which, err));
  static const sph_shape_kind map[] = {SPH_SHAPE_BOX,    SPH_SHAPE_CYLINDER,
                                       SPH_SHAPE_RING,   SPH_SHAPE_DISC,
                                       SPH_SHAPE_SPHERE, SPH_SHAPE_SHELL};
  memset(sh, 0, sizeof *sh);
  sh->kind = map[which];
  sph_node *g;
  SPH_TRY(sph_node_get_map(n, kinds[which], 1, &g, err));
  int d = s->dimension;
  switch (sh->kind) {
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
                              axis_names[c], sh->max[c], sh->min[c]);
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
    SPH_TRY(get_direction(g, "axis", 0, 2, 3, sh->axis, err));
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
      SPH_TRY(get_direction(g, "axis", 0, 2, 3, sh->axis, err));
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
    return sph_node_error(sph_node_child(n, kinds[which]), err,
                          SPH_ERR_GEOMETRY,
                          "a %s does not exist in %dD (2D: box, disc, ring; "
                          "3D: box, cylinder, ring, sphere, shell)",
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
  SPH_TRY(one_of(n, how, "of count or spacing", &which, err));
  int d = s->dimension;
  if (which == 0) {
    if (b->shape.kind != SPH_SHAPE_BOX)
      return sph_node_error(sph_node_child(n, "count"), err, SPH_ERR_ARG,
                            "particle counts apply to boxes; give a spacing "
                            "for other shapes");
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
    SPH_TRY(positive(n, "spacing", 1, 0, &b->spacing, err));
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
  SPH_TRY(one_of(n, kinds, "initial velocity", &which, err));
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
    SPH_TRY(get_direction(r, "axis", 1, 2, 3, v->axis, err));
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
    SPH_TRY(get_seq(n, "expression", 1, &e, err));
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
      SPH_TRY(get_direction(r, "axis", 1, 2, 3, a, err));
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

static sph_status parse_bodies(sph_scene *s, sph_node *root, sph_error *err) {
  sph_node *list;
  SPH_TRY(get_seq(root, "bodies", 1, &list, err));
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
    copy_name(b->name, name);
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
    SPH_TRY(sph_node_get_map(n, "particles", 1, &parts, err));
    SPH_TRY(parse_particles(s, b, parts, err));
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

/* The placement of the body a selection names, or NULL (world frame). */
static const sph_transform *selection_frame(const sph_scene *s,
                                            const sph_selection *sel) {
  if (sel->body < 0 || !s->bodies[sel->body].transform.given)
    return NULL;
  return &s->bodies[sel->body].transform;
}

/* out = R v */
static void rotate(const sph_transform *T, const double v[3], double out[3]) {
  for (int i = 0; i < 3; ++i)
    out[i] =
        T->R[3 * i] * v[0] + T->R[3 * i + 1] * v[1] + T->R[3 * i + 2] * v[2];
}

static sph_status parse_selection(sph_scene *s, sph_selection *sel, sph_node *n,
                                  sph_error *err) {
  static const char *const kinds[] = {"plane", "box", "face", NULL};
  SPH_TRY(sph_node_check_keys(n, kinds, err));
  int which;
  SPH_TRY(one_of(n, kinds, "selection", &which, err));
  sph_node *g;
  SPH_TRY(sph_node_get_map(n, kinds[which], 1, &g, err));
  sel->body = -1;
  sel->kind = (sph_select_kind)which;
  const char *body = NULL;
  if (which == SPH_SELECT_FACE) {
    static const char *const keys[] = {"body", "side", NULL};
    SPH_TRY(sph_node_check_keys(g, keys, err));
    SPH_TRY(sph_node_get_string(g, "body", 1, NULL, &body, err));
    const char *side;
    SPH_TRY(sph_node_get_string(g, "side", 1, NULL, &side, err));
    int ok = strlen(side) == 2 && (side[1] == '-' || side[1] == '+');
    int a = ok ? side[0] - 'x' : -1;
    if (a < 0 || a > s->dimension - 1)
      return sph_node_error(sph_node_child(g, "side"), err, SPH_ERR_RANGE,
                            "side must be one of x-, x+, y-, y+%s, got '%s'",
                            s->dimension == 3 ? ", z-, z+" : "", side);
    sel->axis = a;
    sel->side = side[1] == '+' ? 1 : -1;
  } else {
    static const char *const pkeys[] = {"axis", "at", "tolerance", "body",
                                        NULL};
    static const char *const bkeys[] = {"min", "max", "body", NULL};
    SPH_TRY(sph_node_check_keys(g, which == 0 ? pkeys : bkeys, err));
    SPH_TRY(sph_node_get_string(g, "body", 0, NULL, &body, err));
    if (which == SPH_SELECT_PLANE) {
      SPH_TRY(get_direction(g, "axis", 1, 0, s->dimension, sel->normal, err));
      SPH_TRY(sph_node_get_double(g, "at", 1, 0, &sel->at, err));
      sel->tolerance = -1.0; /* resolved below */
      if (sph_node_child(g, "tolerance"))
        SPH_TRY(positive(g, "tolerance", 1, 0, &sel->tolerance, err));
    } else {
      int d = s->dimension;
      SPH_TRY(
          sph_node_get_doubles(g, "min", 1, (size_t)d, sel->min, NULL, err));
      SPH_TRY(
          sph_node_get_doubles(g, "max", 1, (size_t)d, sel->max, NULL, err));
      for (int c = 0; c < d; ++c)
        if (sel->max[c] < sel->min[c])
          return sph_node_error(sph_node_child(g, "max"), err, SPH_ERR_GEOMETRY,
                                "empty selection box: max < min on axis %s",
                                axis_names[c]);
    }
  }
  if (body) {
    sel->body = sph_scene_find_body(s, body);
    if (sel->body < 0)
      return sph_node_error(sph_node_child(g, "body"), err, SPH_ERR_ARG,
                            "no body named '%s'", body);
  }
  /* a plane in the frame of a placed body, in the world frame */
  const sph_transform *T = selection_frame(s, sel);
  if (sel->kind == SPH_SELECT_PLANE && T) {
    double w[3];
    rotate(T, sel->normal, w);
    memcpy(sel->normal, w, sizeof w);
    sel->at += w[0] * T->t[0] + w[1] * T->t[1] + w[2] * T->t[2];
  }
  if (sel->kind == SPH_SELECT_PLANE)
    sel->axis = sph_axis_index(sel->normal);
  /* the first particle layer: on the plane for face lattices, half a
   * spacing inside for cell-centred ones (jitter moves it by < dp / 2) */
  double spacing = INFINITY, tol = INFINITY;
  for (size_t b = 0; b < s->nbodies; ++b) {
    if (sel->body >= 0 && (int)b != sel->body)
      continue;
    const sph_body *bd = &s->bodies[b];
    spacing = fmin(spacing, bd->spacing);
    tol =
        fmin(tol, (bd->lattice == SPH_LATTICE_FACES ? 0.5 : 1.0) * bd->spacing);
  }
  if (sel->kind == SPH_SELECT_PLANE && sel->tolerance < 0.0) {
    char buf[40];
    snprintf(buf, sizeof buf, "%.17g", tol);
    sel->tolerance = tol;
    SPH_TRY(
        sph_node_insert_default(g, "tolerance", buf, &(sph_node *){0}, err));
  } else if (sel->kind != SPH_SELECT_PLANE) {
    sel->tolerance = 1e-9 * spacing;
  }
  return SPH_OK;
}

static sph_status parse_boundaries(sph_scene *s, sph_node *root,
                                   sph_error *err) {
  sph_node *list;
  SPH_TRY(get_seq(root, "boundaries", 0, &list, err));
  if (!list)
    return SPH_OK;
  s->boundaries = calloc(list->count ? list->count : 1, sizeof *s->boundaries);
  if (!s->boundaries)
    return sph_error_set(err, SPH_ERR_NOMEM, "boundaries");
  static const char *const keys[] = {"name",     "select",   "clamp",
                                     "roller",   "symmetry", "skew_symmetry",
                                     "velocity", NULL};
  static const char *const conds[] = {"clamp",    "roller",        "velocity",
                                      "symmetry", "skew_symmetry", NULL};
  for (size_t i = 0; i < list->count; ++i) {
    sph_node *n = list->items[i];
    sph_boundary *b = &s->boundaries[i];
    s->nboundaries++;
    if (n->kind != SPH_NODE_MAP)
      return sph_node_error(n, err, SPH_ERR_TYPE,
                            "expected a boundary condition (a mapping)");
    SPH_TRY(sph_node_check_keys(n, keys, err));
    b->line = n->line;
    b->col = n->col;
    const char *name;
    SPH_TRY(sph_node_get_string(n, "name", 1, NULL, &name, err));
    copy_name(b->name, name);
    sph_node *sel;
    SPH_TRY(sph_node_get_map(n, "select", 1, &sel, err));
    SPH_TRY(parse_selection(s, &b->select, sel, err));
    int which;
    SPH_TRY(one_of(n, conds, "condition", &which, err));
    static const sph_condition_kind kinds[] = {SPH_BC_CLAMP, SPH_BC_ROLLER,
                                               SPH_BC_VELOCITY, SPH_BC_SYMMETRY,
                                               SPH_BC_SKEW_SYMMETRY};
    b->kind = kinds[which];
    b->mask = 7u;
    b->until = INFINITY;
    if (b->kind == SPH_BC_CLAMP) {
      int on;
      SPH_TRY(sph_node_get_bool(n, "clamp", 1, 1, &on, err));
      if (!on)
        return sph_node_error(sph_node_child(n, "clamp"), err, SPH_ERR_RANGE,
                              "clamp: false imposes nothing; remove the "
                              "boundary instead");
    } else if (b->kind == SPH_BC_VELOCITY) {
      sph_node *v;
      SPH_TRY(sph_node_get_map(n, "velocity", 1, &v, err));
      static const char *const vkeys[] = {"value", "from", "until",
                                          "components", NULL};
      SPH_TRY(sph_node_check_keys(v, vkeys, err));
      SPH_TRY(sph_node_get_doubles(v, "value", 1, 3, b->value, NULL, err));
      SPH_TRY(sph_node_get_double(v, "from", 0, 0.0, &b->from, err));
      if (sph_node_child(v, "until")) {
        SPH_TRY(sph_node_get_double(v, "until", 1, 0, &b->until, err));
        if (!(b->until > b->from))
          return sph_node_error(sph_node_child(v, "until"), err, SPH_ERR_RANGE,
                                "until (%g) must be after from (%g)", b->until,
                                b->from);
      }
      const sph_transform *T = selection_frame(s, &b->select);
      if (T) {
        double w[3];
        rotate(T, b->value, w);
        memcpy(b->value, w, sizeof w);
      }
      sph_node *comp;
      SPH_TRY(get_seq(v, "components", 0, &comp, err));
      if (comp && T)
        return sph_node_error(comp, err, SPH_ERR_ARG,
                              "components name world axes; a selection in "
                              "the frame of placed body '%s' prescribes the "
                              "whole velocity",
                              s->bodies[b->select.body].name);
      if (comp) {
        b->mask = 0;
        for (size_t k = 0; k < comp->count; ++k) {
          const char *c = comp->items[k]->value;
          int a = c && strlen(c) == 1 ? c[0] - 'x' : -1;
          if (a < 0 || a > 2)
            return sph_node_error(comp->items[k], err, SPH_ERR_RANGE,
                                  "components are x, y or z");
          b->mask |= 1u << a;
        }
      }
    } else {
      sph_node *c;
      SPH_TRY(sph_node_get_map(n, conds[which], 1, &c, err));
      static const char *const akeys[] = {"axis", NULL};
      SPH_TRY(sph_node_check_keys(c, akeys, err));
      SPH_TRY(get_direction(c, "axis", 1, 0, s->dimension, b->normal, err));
      const sph_transform *T = selection_frame(s, &b->select);
      if (T) {
        double w[3];
        rotate(T, b->normal, w);
        memcpy(b->normal, w, sizeof w);
      }
      b->axis = sph_axis_index(b->normal);
      const double *m = b->select.normal;
      if (b->kind != SPH_BC_ROLLER &&
          (b->select.kind != SPH_SELECT_PLANE ||
           fabs(m[0] * b->normal[0] + m[1] * b->normal[1] +
                m[2] * b->normal[2]) < 1.0 - 1e-12))
        return sph_node_error(sph_node_child(n, conds[which]), err, SPH_ERR_ARG,
                              "a %s plane needs a plane selection with the "
                              "same normal",
                              conds[which]);
    }
  }
  return SPH_OK;
}

static sph_status field_list(sph_scene *s, sph_node *list, int *fields,
                             int *nfields, int max, int allow_ids,
                             sph_error *err) {
  *nfields = 0;
  for (size_t i = 0; i < list->count; ++i) {
    sph_node *it = list->items[i];
    if (it->kind != SPH_NODE_SCALAR)
      return sph_node_error(it, err, SPH_ERR_TYPE, "expected a field name");
    if (allow_ids && !strcmp(it->value, "body_id")) {
      s->output.body_id = 1;
      continue;
    }
    if (allow_ids && !strcmp(it->value, "particle_id")) {
      s->output.particle_id = 1;
      continue;
    }
    int f = sph_field_from_name(it->value);
    if (f < 0) {
      const char *names[SPH_FIELD_COUNT + 3];
      int k = 0;
      for (int j = 0; j < SPH_FIELD_COUNT; ++j)
        names[k++] = sph_field_name((sph_field)j);
      if (allow_ids) {
        names[k++] = "body_id";
        names[k++] = "particle_id";
      }
      names[k] = NULL;
      const char *hint = sph_suggest(it->value, names);
      return sph_node_error(it, err, SPH_ERR_RANGE, "unknown field '%s'%s%s%s",
                            it->value, hint ? "; did you mean '" : "",
                            hint ? hint : "", hint ? "'?" : "");
    }
    if (*nfields >= max)
      return sph_node_error(it, err, SPH_ERR_RANGE, "at most %d fields", max);
    fields[(*nfields)++] = f;
  }
  return SPH_OK;
}

static sph_status parse_png(sph_scene *s, sph_node *out, sph_error *err) {
  sph_node *png = sph_node_child(out, "png");
  /* png: false turns the frames off (sph study, --set output.png=false);
   * png: true is png: {} (frames with the defaults) */
  if (png && png->kind == SPH_NODE_SCALAR && !png->quoted) {
    int on;
    if (sph_node_as_bool(png, &on, err) != SPH_OK)
      return sph_node_error(png, err, SPH_ERR_TYPE,
                            "expected a mapping, true or false");
    png->used = 1;
    if (!on)
      return SPH_OK;
    free(png->value);
    png->value = NULL;
    png->kind = SPH_NODE_MAP;
  }
  SPH_TRY(sph_node_get_map(out, "png", 0, &png, err));
  sph_png_output *p = &s->output.png;
  if (!png)
    return SPH_OK;
  static const char *const keys[] = {
      "width", "height", "color", "range", "colormap", "camera",    "mp4",
      "fps",   "clip",   "cut",   "ghost", "axes",     "scale_bar", NULL};
  SPH_TRY(sph_node_check_keys(png, keys, err));
  p->enabled = 1;
  long w, h;
  SPH_TRY(sph_node_get_int(png, "width", 0, 1280, &w, err));
  SPH_TRY(sph_node_get_int(png, "height", 0, 720, &h, err));
  if (w < 16 || w > 16384)
    return sph_node_error(sph_node_child(png, "width"), err, SPH_ERR_RANGE,
                          "width must be in [16, 16384], got %ld", w);
  if (h < 16 || h > 16384)
    return sph_node_error(sph_node_child(png, "height"), err, SPH_ERR_RANGE,
                          "height must be in [16, 16384], got %ld", h);
  p->width = (int)w;
  p->height = (int)h;
  const char *color;
  SPH_TRY(sph_node_get_string(png, "color", 0, "pressure", &color, err));
  int f = sph_field_from_name(color);
  if (f < 0)
    return sph_node_error(sph_node_child(png, "color"), err, SPH_ERR_RANGE,
                          "unknown field '%s'", color);
  p->color_field = f;
  sph_node *range = sph_node_child(png, "range");
  snprintf(p->range_mode, sizeof p->range_mode, "robust");
  if (range && range->kind == SPH_NODE_SEQ) {
    range->used = 1;
    SPH_TRY(sph_node_get_doubles(png, "range", 1, 2, p->range, NULL, err));
    if (!(p->range[1] > p->range[0]))
      return sph_node_error(range, err, SPH_ERR_RANGE,
                            "range [min, max] needs min < max");
    snprintf(p->range_mode, sizeof p->range_mode, "fixed");
  } else {
    const char *mode;
    SPH_TRY(sph_node_get_string(png, "range", 0, "robust", &mode, err));
    if (strcmp(mode, "robust") && strcmp(mode, "auto") &&
        strcmp(mode, "symmetric") && strcmp(mode, "global"))
      return sph_node_error(sph_node_child(png, "range"), err, SPH_ERR_RANGE,
                            "range is robust, auto, symmetric, global or "
                            "[min, max], got '%s'",
                            mode);
    snprintf(p->range_mode, sizeof p->range_mode, "%s", mode);
  }
  const char *cmap;
  SPH_TRY(sph_node_get_string(png, "colormap", 0, "", &cmap, err));
  if (*cmap && strcmp(cmap, "cool-warm") && strcmp(cmap, "viridis"))
    return sph_node_error(sph_node_child(png, "colormap"), err, SPH_ERR_RANGE,
                          "colormap is cool-warm or viridis, got '%s'", cmap);
  snprintf(p->colormap, sizeof p->colormap, "%s", cmap);
  sph_node *cam;
  SPH_TRY(sph_node_get_map(png, "camera", 0, &cam, err));
  if (cam) {
    static const char *const ckeys[] = {"position",   "target",    "up",
                                        "azimuth",    "elevation", "zoom",
                                        "projection", "follow",    NULL};
    SPH_TRY(sph_node_check_keys(cam, ckeys, err));
    sph_camera *c = &p->camera;
    c->given = 1;
    c->up[1] = 1.0;
    c->zoom = 1.0;
    if (sph_node_child(cam, "position")) {
      c->has_position = 1;
      SPH_TRY(
          sph_node_get_doubles(cam, "position", 1, 3, c->position, NULL, err));
    }
    if (sph_node_child(cam, "target"))
      SPH_TRY(sph_node_get_doubles(cam, "target", 1, 3, c->target, NULL, err));
    if (sph_node_child(cam, "up"))
      SPH_TRY(sph_node_get_doubles(cam, "up", 1, 3, c->up, NULL, err));
    SPH_TRY(sph_node_get_double(cam, "azimuth", 0, 0.0, &c->azimuth, err));
    SPH_TRY(sph_node_get_double(cam, "elevation", 0, 0.0, &c->elevation, err));
    SPH_TRY(positive(cam, "zoom", 0, 1.0, &c->zoom, err));
    const char *proj;
    SPH_TRY(
        sph_node_get_string(cam, "projection", 0, "orthographic", &proj, err));
    if (strcmp(proj, "orthographic") && strcmp(proj, "perspective"))
      return sph_node_error(sph_node_child(cam, "projection"), err,
                            SPH_ERR_RANGE,
                            "projection is orthographic or perspective");
    c->orthographic = !strcmp(proj, "orthographic");
    SPH_TRY(sph_node_get_bool(cam, "follow", 0, 1, &c->follow, err));
  } else {
    p->camera.follow = 1;
  }
  /* the animation, the cutaway and the reference outline */
  SPH_TRY(sph_node_get_bool(png, "mp4", 0, 1, &p->mp4, err));
  SPH_TRY(positive(png, "fps", 0, 30.0, &p->fps, err));
  if (p->fps > 240.0)
    return sph_node_error(sph_node_child(png, "fps"), err, SPH_ERR_RANGE,
                          "fps must be in (0, 240], got %g", p->fps);
  sph_node *clip;
  SPH_TRY(sph_node_get_map(png, "clip", 0, &clip, err));
  if (clip) {
    static const char *const pkeys[] = {"normal", "at", NULL};
    SPH_TRY(sph_node_check_keys(clip, pkeys, err));
    SPH_TRY(
        sph_node_get_doubles(clip, "normal", 1, 3, p->clip_normal, NULL, err));
    SPH_TRY(sph_node_get_double(clip, "at", 1, 0.0, &p->clip_at, err));
    double nn = 0.0;
    for (int k = 0; k < 3; ++k)
      nn += p->clip_normal[k] * p->clip_normal[k];
    if (!(nn > 0.0) || !isfinite(nn))
      return sph_node_error(sph_node_child(clip, "normal"), err, SPH_ERR_RANGE,
                            "the clip normal must be a non-zero vector");
    p->clip = 1;
  }
  const char *cut;
  SPH_TRY(sph_node_get_string(png, "cut", 0, "none", &cut, err));
  if (strcmp(cut, "none") && strcmp(cut, "half"))
    return sph_node_error(sph_node_child(png, "cut"), err, SPH_ERR_RANGE,
                          "cut is none or half, got '%s'", cut);
  p->cut_half = !strcmp(cut, "half");
  SPH_TRY(sph_node_get_bool(png, "ghost", 0, 0, &p->ghost, err));
  SPH_TRY(sph_node_get_bool(png, "axes", 0, 0, &p->axes, err));
  SPH_TRY(sph_node_get_bool(png, "scale_bar", 0, 0, &p->scale_bar, err));
  return SPH_OK;
}

static sph_status parse_output(sph_scene *s, sph_node *root, sph_error *err) {
  sph_node *out;
  SPH_TRY(sph_node_insert_default(root, "output", "{}", &out, err));
  if (out->kind != SPH_NODE_MAP)
    return sph_node_error(out, err, SPH_ERR_TYPE, "expected a mapping");
  static const char *const keys[] = {"every",  "fields",           "vtk", "png",
                                     "probes", "checkpoint_every", NULL};
  SPH_TRY(sph_node_check_keys(out, keys, err));
  sph_output *o = &s->output;
  SPH_TRY(positive(out, "every", 0, s->t_end / 100.0, &o->every, err));
  if (o->every > s->t_end * (1 + 1e-12))
    return sph_node_error(sph_node_child(out, "every"), err, SPH_ERR_RANGE,
                          "output interval %g is longer than the run (%g)",
                          o->every, s->t_end);
  /* frame numbers have four digits (<scene>_NNNN.vtp, .png) */
  double frames = ceil(s->t_end / o->every * (1.0 - 1e-12)) + 1.0;
  if (frames > 10000.0)
    return sph_node_error(sph_node_child(out, "every"), err, SPH_ERR_RANGE,
                          "%.0f output frames (end %g s every %g s); at "
                          "most 10000: a longer interval, or a shorter run",
                          frames, s->t_end, o->every);
  sph_node *fields;
  SPH_TRY(sph_node_insert_default(
      out, "fields",
      "[pressure, velocity, displacement, von_mises, J, body_id]", &fields,
      err));
  if (fields->kind != SPH_NODE_SEQ)
    return sph_node_error(fields, err, SPH_ERR_TYPE,
                          "expected a list of field names");
  SPH_TRY(
      field_list(s, fields, o->fields, &o->nfields, SPH_FIELD_COUNT, 1, err));
  sph_node *vtk = sph_node_child(out, "vtk");
  o->vtk = 1;
  if (vtk && vtk->kind == SPH_NODE_MAP) {
    vtk->used = 1;
    static const char *const vkeys[] = {"format", "compress", NULL};
    SPH_TRY(sph_node_check_keys(vtk, vkeys, err));
    const char *fmt, *zip;
    SPH_TRY(sph_node_get_string(vtk, "format", 0, "binary", &fmt, err));
    if (strcmp(fmt, "binary") && strcmp(fmt, "ascii"))
      return sph_node_error(sph_node_child(vtk, "format"), err, SPH_ERR_RANGE,
                            "format is binary or ascii, got '%s'", fmt);
    o->vtk_ascii = !strcmp(fmt, "ascii");
    SPH_TRY(sph_node_get_string(vtk, "compress", 0, "none", &zip, err));
    if (strcmp(zip, "none") && strcmp(zip, "zlib"))
      return sph_node_error(sph_node_child(vtk, "compress"), err, SPH_ERR_RANGE,
                            "compress is none or zlib, got '%s'", zip);
    o->vtk_zlib = !strcmp(zip, "zlib");
    if (o->vtk_zlib && o->vtk_ascii)
      return sph_node_error(sph_node_child(vtk, "compress"), err, SPH_ERR_ARG,
                            "compress: zlib applies to the binary format");
  } else {
    SPH_TRY(sph_node_get_bool(out, "vtk", 0, 1, &o->vtk, err));
  }
  SPH_TRY(parse_png(s, out, err));
  if (sph_node_child(out, "checkpoint_every"))
    SPH_TRY(positive(out, "checkpoint_every", 1, 0, &o->checkpoint_every, err));
  sph_node *probes;
  SPH_TRY(get_seq(out, "probes", 0, &probes, err));
  if (probes && probes->count) {
    o->probes = calloc(probes->count, sizeof *o->probes);
    if (!o->probes)
      return sph_error_set(err, SPH_ERR_NOMEM, "probes");
    static const char *const pkeys[] = {"name", "at", "fields", NULL};
    for (size_t i = 0; i < probes->count; ++i) {
      sph_node *n = probes->items[i];
      sph_probe *p = &o->probes[i];
      o->nprobes++;
      if (n->kind != SPH_NODE_MAP)
        return sph_node_error(n, err, SPH_ERR_TYPE,
                              "expected a probe (a mapping)");
      SPH_TRY(sph_node_check_keys(n, pkeys, err));
      const char *name;
      SPH_TRY(sph_node_get_string(n, "name", 1, NULL, &name, err));
      copy_name(p->name, name);
      if (!name[0])
        return sph_node_error(sph_node_child(n, "name"), err, SPH_ERR_RANGE,
                              "a probe needs a name");
      for (size_t j = 0; j < i; ++j)
        if (!strcmp(o->probes[j].name, p->name))
          return sph_node_error(sph_node_child(n, "name"), err, SPH_ERR_ARG,
                                "two probes are named '%s' (their columns in "
                                "probes.csv would clash)",
                                name);
      SPH_TRY(sph_node_get_doubles(n, "at", 1, (size_t)s->dimension, p->at,
                                   NULL, err));
      sph_node *at = sph_node_child(n, "at");
      p->line = at->line;
      p->col = at->col;
      sph_node *pf;
      SPH_TRY(sph_node_insert_default(n, "fields", "[displacement, velocity]",
                                      &pf, err));
      if (pf->kind != SPH_NODE_SEQ)
        return sph_node_error(pf, err, SPH_ERR_TYPE,
                              "expected a list of field names");
      SPH_TRY(field_list(s, pf, p->fields, &p->nfields, 8, 0, err));
    }
  }
  return SPH_OK;
}

/* A threshold of the stability block: >= 0, 0 turns the indicator off. */
static sph_status threshold(sph_node *map, const char *key, double def,
                            double *out, sph_error *err) {
  SPH_TRY(sph_node_get_double(map, key, 0, def, out, err));
  if (!(*out >= 0.0) || !isfinite(*out))
    return sph_node_error(sph_node_child(map, key), err, SPH_ERR_RANGE,
                          "must be >= 0 (0 turns the indicator off), got %g",
                          *out);
  return SPH_OK;
}

static sph_status parse_stability(sph_scene *s, sph_node *root,
                                  sph_error *err) {
  sph_node *st;
  SPH_TRY(sph_node_insert_default(root, "stability", "{}", &st, err));
  if (st->kind != SPH_NODE_MAP)
    return sph_node_error(st, err, SPH_ERR_TYPE, "expected a mapping");
  static const char *const keys[] = {"fracture_dp", "zigzag_max", NULL};
  SPH_TRY(sph_node_check_keys(st, keys, err));
  SPH_TRY(threshold(st, "fracture_dp", SPH_FRACTURE_DP,
                    &s->stability.fracture_dp, err));
  SPH_TRY(threshold(st, "zigzag_max", SPH_ZIGZAG_MAX, &s->stability.zigzag_max,
                    err));
  return SPH_OK;
}

/* contact: {stiffness, between_bodies, walls: [{name, plane|box, velocity}]}
 * (rigid frictionless walls and body-to-body contact, src/terms/contact.c) */
static sph_status parse_contact(sph_scene *s, sph_node *root, sph_error *err) {
  sph_node *c;
  SPH_TRY(sph_node_get_map(root, "contact", 0, &c, err));
  if (!c)
    return SPH_OK;
  sph_contact *ct = &s->contact;
  static const char *const keys[] = {"stiffness", "between_bodies", "walls",
                                     NULL};
  SPH_TRY(sph_node_check_keys(c, keys, err));
  ct->given = 1;
  ct->line = c->line;
  ct->col = c->col;
  SPH_TRY(positive(c, "stiffness", 0, 1.0, &ct->stiffness, err));
  SPH_TRY(
      sph_node_get_bool(c, "between_bodies", 0, 0, &ct->between_bodies, err));
  if (ct->between_bodies && s->nbodies < 2)
    return sph_node_error(sph_node_child(c, "between_bodies"), err, SPH_ERR_ARG,
                          "between_bodies needs two bodies or more, the scene "
                          "has %zu",
                          s->nbodies);
  sph_node *list;
  SPH_TRY(get_seq(c, "walls", 0, &list, err));
  if (!list && !ct->between_bodies)
    return sph_node_error(c, err, SPH_ERR_ARG,
                          "contact with nothing: give walls or "
                          "between_bodies: true");
  size_t nw = list ? list->count : 0;
  ct->walls = calloc(nw ? nw : 1, sizeof *ct->walls);
  if (!ct->walls)
    return sph_error_set(err, SPH_ERR_NOMEM, "walls");
  static const char *const wkeys[] = {"name", "plane", "box", "velocity", NULL};
  static const char *const kinds[] = {"plane", "box", NULL};
  const size_t d = (size_t)s->dimension;
  for (size_t i = 0; i < nw; ++i) {
    sph_node *n = list->items[i];
    sph_wall *w = &ct->walls[ct->nwalls++];
    if (n->kind != SPH_NODE_MAP)
      return sph_node_error(n, err, SPH_ERR_TYPE,
                            "expected a wall (a mapping with name and plane "
                            "or box)");
    SPH_TRY(sph_node_check_keys(n, wkeys, err));
    w->line = n->line;
    w->col = n->col;
    const char *name;
    SPH_TRY(sph_node_get_string(n, "name", 1, NULL, &name, err));
    copy_name(w->name, name);
    int which;
    SPH_TRY(one_of(n, kinds, "wall shape", &which, err));
    sph_node *g;
    SPH_TRY(sph_node_get_map(n, kinds[which], 1, &g, err));
    if (which == 0) {
      static const char *const pkeys[] = {"point", "normal", NULL};
      SPH_TRY(sph_node_check_keys(g, pkeys, err));
      w->kind = SPH_WALL_PLANE;
      SPH_TRY(sph_node_get_doubles(g, "point", 1, d, w->point, NULL, err));
      SPH_TRY(get_direction(g, "normal", 1, 0, s->dimension, w->normal, err));
    } else {
      static const char *const bkeys[] = {"min", "max", NULL};
      SPH_TRY(sph_node_check_keys(g, bkeys, err));
      w->kind = SPH_WALL_BOX;
      SPH_TRY(sph_node_get_doubles(g, "min", 1, d, w->min, NULL, err));
      SPH_TRY(sph_node_get_doubles(g, "max", 1, d, w->max, NULL, err));
      for (size_t k = 0; k < d; ++k)
        if (!(w->max[k] > w->min[k]))
          return sph_node_error(sph_node_child(g, "max"), err, SPH_ERR_GEOMETRY,
                                "empty wall box: max <= min on axis %s",
                                axis_names[k]);
      if (d == 2) { /* plane strain: the box spans z */
        w->min[2] = -INFINITY;
        w->max[2] = INFINITY;
      }
    }
    SPH_TRY(sph_node_get_doubles(n, "velocity", 0, 3, w->velocity, NULL, err));
    if (d == 2 && w->velocity[2] != 0.0)
      return sph_node_error(sph_node_child(n, "velocity"), err, SPH_ERR_RANGE,
                            "a 2D scene's wall moves in x and y only");
  }
  return SPH_OK;
}

static sph_status parse_scene(sph_scene *s, sph_node *root, sph_error *err) {
  if (root->kind != SPH_NODE_MAP)
    return sph_node_error(root, err, SPH_ERR_TYPE,
                          "a scene is a mapping of keys (name, dimension, "
                          "method, materials, bodies, time, ...)");
  static const char *const keys[] = {
      "name",      "dimension",  "method",     "kernel", "materials",
      "bodies",    "boundaries", "body_force", "time",   "output",
      "reference", "stability",  "contact",    NULL};
  SPH_TRY(sph_node_check_keys(root, keys, err));
  const char *name;
  SPH_TRY(sph_node_get_string(root, "name", 1, NULL, &name, err));
  size_t len = strlen(name);
  int ok = len > 0 && len < SPH_NAME_MAX;
  for (const char *c = name; *c && ok; ++c)
    ok = isalnum((unsigned char)*c) || *c == '_' || *c == '-';
  if (!ok)
    return sph_node_error(sph_node_child(root, "name"), err, SPH_ERR_RANGE,
                          "a scene name is 1-63 letters, digits, '_' or '-' "
                          "(it names the output folder), got '%s'",
                          name);
  copy_name(s->name, name);
  long dim;
  SPH_TRY(sph_node_get_int(root, "dimension", 1, 3, &dim, err));
  if (dim != 2 && dim != 3)
    return sph_node_error(sph_node_child(root, "dimension"), err, SPH_ERR_RANGE,
                          "dimension is 2 or 3, got %ld", dim);
  s->dimension = (int)dim;
  SPH_TRY(sph_node_get_map(root, "method", 1, &s->method, err));
  const char *method;
  SPH_TRY(sph_node_get_string(s->method, "name", 1, NULL, &method, err));
  copy_name(s->method_name, method);
  SPH_TRY(sph_node_get_map(root, "reference", 0, &s->reference, err));
  sph_node *time;
  SPH_TRY(sph_node_get_map(root, "time", 1, &time, err));
  static const char *const tkeys[] = {"end", NULL};
  SPH_TRY(sph_node_check_keys(time, tkeys, err));
  SPH_TRY(positive(time, "end", 1, 0, &s->t_end, err));
  SPH_TRY(parse_kernel(s, root, err));
  SPH_TRY(parse_materials(s, root, err));
  SPH_TRY(parse_bodies(s, root, err));
  SPH_TRY(parse_boundaries(s, root, err));
  if (sph_node_child(root, "body_force")) {
    s->has_body_force = 1;
    SPH_TRY(sph_node_get_doubles(root, "body_force", 1, 3, s->body_force, NULL,
                                 err));
  }
  SPH_TRY(parse_contact(s, root, err));
  SPH_TRY(parse_output(s, root, err));
  SPH_TRY(parse_stability(s, root, err));
  return SPH_OK;
}

sph_status sph_scene_load(sph_scene **out, const char *path,
                          const char *const *overrides, size_t nset,
                          sph_error *err) {
  *out = NULL;
  sph_scene *s = calloc(1, sizeof *s);
  if (!s)
    return sph_error_set(err, SPH_ERR_NOMEM, "scene");
  snprintf(s->path, sizeof s->path, "%s", path);
  sph_status st = sph_node_load_file(&s->root, path, err);
  for (size_t i = 0; st == SPH_OK && i < nset; ++i)
    st = sph_node_set(s->root, overrides[i], err);
  if (st == SPH_OK)
    st = parse_scene(s, s->root, err);
  if (st != SPH_OK) {
    sph_scene_destroy(s);
    return st;
  }
  *out = s;
  return SPH_OK;
}

void sph_scene_destroy(sph_scene *s) {
  if (!s)
    return;
  for (size_t i = 0; i < s->nbodies; ++i) {
    sph_expr_destroy(s->bodies[i].velocity.profile);
    for (int c = 0; c < 3; ++c)
      sph_expr_destroy(s->bodies[i].velocity.expr[c]);
  }
  free(s->bodies);
  free(s->materials);
  free(s->boundaries);
  free(s->contact.walls);
  free(s->output.probes);
  sph_node_destroy(s->root);
  free(s);
}

int sph_scene_has_essential_bc(const sph_scene *s) {
  for (size_t k = 0; k < s->nboundaries; ++k)
    if (s->boundaries[k].kind == SPH_BC_CLAMP ||
        s->boundaries[k].kind == SPH_BC_ROLLER ||
        s->boundaries[k].kind == SPH_BC_VELOCITY)
      return 1;
  return 0;
}

double sph_wall_distance(const sph_wall *w, double t, int dim,
                         const double x[3], double n[3]) {
  double y[3]; /* x in the frame of the wall at t = 0 */
  for (int c = 0; c < 3; ++c)
    y[c] = c < dim ? x[c] - t * w->velocity[c] : 0.0;
  if (w->kind == SPH_WALL_PLANE) {
    double g = 0.0;
    for (int c = 0; c < 3; ++c) {
      n[c] = w->normal[c];
      g += (y[c] - w->point[c]) * n[c];
    }
    return g;
  }
  /* box: distance to the nearest point of its surface, negative inside */
  double out[3], out2 = 0.0, depth = INFINITY;
  int face = 0;
  for (int c = 0; c < dim; ++c) {
    out[c] = y[c] < w->min[c]   ? y[c] - w->min[c]
             : y[c] > w->max[c] ? y[c] - w->max[c]
                                : 0.0;
    out2 += out[c] * out[c];
    double lo = y[c] - w->min[c], hi = w->max[c] - y[c];
    if (lo < depth) {
      depth = lo;
      face = -(c + 1);
    }
    if (hi < depth) {
      depth = hi;
      face = c + 1;
    }
  }
  n[0] = n[1] = n[2] = 0.0;
  if (out2 > 0.0) {
    double g = sqrt(out2);
    for (int c = 0; c < dim; ++c)
      n[c] = out[c] / g;
    return g;
  }
  n[abs(face) - 1] = face > 0 ? 1.0 : -1.0;
  return -depth;
}

double sph_output_time(const sph_scene *s, int index) {
  return fmin(s->t_end, s->output.every * (double)index);
}

double sph_scene_min_spacing(const sph_scene *s) {
  double dp = INFINITY;
  for (size_t b = 0; b < s->nbodies; ++b)
    dp = s->bodies[b].spacing < dp ? s->bodies[b].spacing : dp;
  return dp;
}

int sph_scene_find_material(const sph_scene *s, const char *name) {
  for (size_t i = 0; i < s->nmaterials; ++i)
    if (!strcmp(s->materials[i].name, name))
      return (int)i;
  return -1;
}

int sph_scene_find_body(const sph_scene *s, const char *name) {
  for (size_t i = 0; i < s->nbodies; ++i)
    if (!strcmp(s->bodies[i].name, name))
      return (int)i;
  return -1;
}

void sph_body_local(const sph_body *b, const double X[3], double Xb[3]) {
  const sph_transform *T = &b->transform;
  if (!T->given) {
    memmove(Xb, X, 3 * sizeof *X);
    return;
  }
  double d[3] = {X[0] - T->t[0], X[1] - T->t[1], X[2] - T->t[2]};
  for (int i = 0; i < 3; ++i)
    Xb[i] = T->R[i] * d[0] + T->R[3 + i] * d[1] + T->R[6 + i] * d[2];
}

void sph_body_world(const sph_body *b, const double Xb[3], double X[3]) {
  const sph_transform *T = &b->transform;
  if (!T->given) {
    memmove(X, Xb, 3 * sizeof *X);
    return;
  }
  double r[3];
  rotate(T, Xb, r);
  for (int i = 0; i < 3; ++i)
    X[i] = r[i] + T->t[i];
}

int sph_axis_index(const double n[3]) {
  for (int a = 0; a < 3; ++a)
    if (n[a] == 1.0 && n[(a + 1) % 3] == 0.0 && n[(a + 2) % 3] == 0.0)
      return a;
  return -1;
}

int sph_selection_contains(const sph_scene *s, const sph_selection *sel,
                           int body, const double X[3]) {
  if (sel->body >= 0 && body != sel->body)
    return 0;
  double Xb[3];
  if (sel->kind != SPH_SELECT_PLANE && sel->body >= 0) {
    sph_body_local(&s->bodies[sel->body], X, Xb);
    X = Xb;
  }
  switch (sel->kind) {
  case SPH_SELECT_PLANE:
    if (sel->axis >= 0)
      return fabs(X[sel->axis] - sel->at) <= sel->tolerance;
    return fabs(X[0] * sel->normal[0] + X[1] * sel->normal[1] +
                X[2] * sel->normal[2] - sel->at) <= sel->tolerance;
  case SPH_SELECT_BOX:
    for (int c = 0; c < s->dimension; ++c)
      if (X[c] < sel->min[c] - sel->tolerance ||
          X[c] > sel->max[c] + sel->tolerance)
        return 0;
    return 1;
  case SPH_SELECT_FACE: {
    double lo[3], hi[3];
    const sph_body *b = &s->bodies[sel->body];
    sph_shape_bounds(&b->shape, s->dimension, lo, hi);
    double at = sel->side > 0 ? hi[sel->axis] : lo[sel->axis];
    /* first layer: on the face (face lattice) or about dp / 2 inside */
    double tol = (b->lattice == SPH_LATTICE_FACES ? 0.5 : 1.0) * b->spacing;
    return fabs(X[sel->axis] - at) <= tol;
  }
  }
  return 0;
}

/* ---- particles
 * ----------------------------------------------------------------- */

static void initial_velocity(const sph_velocity *v, const double X[3],
                             double out[3]) {
  out[0] = out[1] = out[2] = 0.0;
  switch (v->kind) {
  case SPH_VEL_NONE:
    return;
  case SPH_VEL_UNIFORM:
    memcpy(out, v->value, 3 * sizeof *out);
    return;
  case SPH_VEL_ROTATION: {
    double w =
        v->omega *
        (v->profile ? sph_expr_eval(v->profile, X[0], X[1], X[2], 0.0) : 1.0);
    double omega[3] = {w * v->axis[0], w * v->axis[1], w * v->axis[2]}, r[3];
    for (int c = 0; c < 3; ++c)
      r[c] = X[c] - v->center[c];
    out[0] = omega[1] * r[2] - omega[2] * r[1];
    out[1] = omega[2] * r[0] - omega[0] * r[2];
    out[2] = omega[0] * r[1] - omega[1] * r[0];
    return;
  }
  case SPH_VEL_EXPRESSION:
    for (int c = 0; c < 3; ++c)
      out[c] = sph_expr_eval(v->expr[c], X[0], X[1], X[2], 0.0);
    return;
  }
}

/* What the set-up checks particle by particle, in creation order: the first
 * particle with a non-finite initial velocity, the first beyond where
 * doubles resolve the spacing, the selections and probes each reaches, the
 * first wall with a particle behind it. Shared by the whole set and the
 * per-rank share (which sees every particle once in its first pass). */
typedef struct build_checks {
  int velocity, resolvable; /* found (the error in *_err) */
  sph_error velocity_err, resolvable_err;
  char *hit;    /* per boundary: selects a particle */
  char *inside; /* per probe: within a spacing of a particle */
  size_t wall;  /* lowest wall with a particle behind it (nwalls: none) */
  sph_error wall_err;
} build_checks;

static sph_status checks_create(const sph_scene *s, build_checks *c,
                                sph_error *err) {
  memset(c, 0, sizeof *c);
  c->wall = s->contact.nwalls;
  c->hit = calloc(s->nboundaries + 1, 1);
  c->inside = calloc(s->output.nprobes + 1, 1);
  if (!c->hit || !c->inside)
    return sph_error_set(err, SPH_ERR_NOMEM, "particle checks");
  return SPH_OK;
}

static void checks_destroy(build_checks *c) {
  free(c->hit);
  free(c->inside);
}

/* Positions a double can tell apart at the particle spacing: beyond 1e9
 * spacings from the origin a coordinate's rounding step exceeds 1e-7 dp
 * (kernel sums and neighbour cells lose their meaning). */
static void check_resolvable(const sph_scene *s, size_t b, const double X[3],
                             build_checks *c) {
  double limit = 1e9 * sph_scene_min_spacing(s);
  for (int k = 0; k < 3 && !c->resolvable; ++k)
    if (!(fabs(X[k]) <= limit)) {
      const sph_body *bd = &s->bodies[b];
      char key[32];
      snprintf(key, sizeof key, "bodies[%d]", (int)b);
      c->resolvable = 1;
      sph_error_at(
          &c->resolvable_err, SPH_ERR_GEOMETRY, s->path, bd->line, bd->col, key,
          "a particle at %g m lies more than 1e9 particle spacings (%g m) "
          "from the origin, where double precision cannot resolve the "
          "spacing: place the body nearer the origin",
          X[k], sph_scene_min_spacing(s));
    }
}

/* The particle of body b at Xb (body frame): its world position X, initial
 * velocity v (world frame) and flags, the checks updated when c is given. */
static void particle_state(const sph_scene *s, size_t b, const double Xb[3],
                           double X[3], double v[3], uint32_t *flags,
                           build_checks *c) {
  const sph_body *bd = &s->bodies[b];
  double vb[3];
  sph_body_world(bd, Xb, X);
  initial_velocity(&bd->velocity, Xb, vb);
  if (bd->transform.given)
    rotate(&bd->transform, vb, v);
  else
    memcpy(v, vb, sizeof vb);
  *flags = 0;
  for (size_t k = 0; k < s->nboundaries; ++k)
    if (sph_selection_contains(s, &s->boundaries[k].select, (int)b, X)) {
      *flags |= SPH_FLAG_BOUNDARY;
      if (c)
        c->hit[k] = 1;
    }
  if (!c)
    return;
  if (!c->velocity && !isfinite(vb[0] + vb[1] + vb[2])) {
    char key[48];
    snprintf(key, sizeof key, "bodies[%zu].initial_velocity", b);
    c->velocity = 1;
    sph_error_at(&c->velocity_err, SPH_ERR_RANGE, s->path, bd->line, bd->col,
                 key, "not finite at (%g, %g, %g) (body frame)", Xb[0], Xb[1],
                 Xb[2]);
  }
  check_resolvable(s, b, X, c);
  /* probes: within one spacing of a particle */
  for (size_t k = 0; k < s->output.nprobes; ++k) {
    const sph_probe *p = &s->output.probes[k];
    double d2 = 0.0;
    for (int e = 0; e < s->dimension; ++e)
      d2 += (X[e] - p->at[e]) * (X[e] - p->at[e]);
    c->inside[k] |= d2 <= bd->spacing * bd->spacing;
  }
  /* walls: no particle starts behind one */
  for (size_t k = 0; k < c->wall; ++k) {
    const sph_wall *w = &s->contact.walls[k];
    double nrm[3], g = sph_wall_distance(w, 0.0, s->dimension, X, nrm);
    if (g >= 0.0)
      continue;
    char key[48];
    snprintf(key, sizeof key, "contact.walls[%zu]", k);
    sph_error_at(&c->wall_err, SPH_ERR_GEOMETRY, s->path, w->line, w->col, key,
                 "body '%s' starts inside wall '%s' (a particle %g m "
                 "beyond it)",
                 bd->name, w->name, -g);
    c->wall = k;
    break;
  }
}

/* the checks' first failure in the serial order: velocities, positions */
static sph_status checks_first(const build_checks *c, sph_error *err) {
  if (c->velocity || c->resolvable) {
    *err = c->velocity ? c->velocity_err : c->resolvable_err;
    return err->code;
  }
  return SPH_OK;
}

/* then selections, probes and walls */
static sph_status checks_rest(const sph_scene *s, const build_checks *c,
                              sph_error *err) {
  for (size_t k = 0; k < s->nboundaries; ++k)
    if (!c->hit[k]) {
      const sph_boundary *bc = &s->boundaries[k];
      char key[48];
      snprintf(key, sizeof key, "boundaries[%zu].select", k);
      return sph_error_at(err, SPH_ERR_GEOMETRY, s->path, bc->line, bc->col,
                          key, "boundary '%s' selects no particle", bc->name);
    }
  for (size_t k = 0; k < s->output.nprobes; ++k)
    if (!c->inside[k]) {
      const sph_probe *p = &s->output.probes[k];
      char key[48];
      snprintf(key, sizeof key, "output.probes[%zu].at", k);
      return sph_error_at(err, SPH_ERR_GEOMETRY, s->path, p->line, p->col, key,
                          "probe '%s' at (%g, %g, %g) is outside every body",
                          p->name, p->at[0], p->at[1],
                          s->dimension == 3 ? p->at[2] : 0.0);
    }
  if (c->wall < s->contact.nwalls) {
    *err = c->wall_err;
    return err->code;
  }
  return SPH_OK;
}

/* a body's generation error at its key */
static sph_status body_error(const sph_scene *s, size_t b, sph_status st,
                             sph_error *err) {
  char msg[768], key[32];
  snprintf(msg, sizeof msg, "%s", err->message);
  snprintf(key, sizeof key, "bodies[%zu]", b);
  return sph_error_at(err, st, s->path, s->bodies[b].line, s->bodies[b].col,
                      key, "%s", msg);
}

/* bodies A and B overlap: particles at Xa and Xb closer than dp / 2 */
static sph_status overlap_error(const sph_scene *s, int32_t A, int32_t B,
                                const double Xa[3], const double Xb[3],
                                sph_error *err) {
  const sph_body *later = &s->bodies[A > B ? A : B];
  const sph_body *first = &s->bodies[A > B ? B : A];
  char key[32];
  snprintf(key, sizeof key, "bodies[%d]", (int)(later - s->bodies));
  return sph_error_at(err, SPH_ERR_GEOMETRY, s->path, later->line, later->col,
                      key,
                      "body '%s' overlaps body '%s' (particles %.3g m "
                      "apart)",
                      later->name, first->name,
                      sqrt(pow(Xa[0] - Xb[0], 2) + pow(Xa[1] - Xb[1], 2) +
                           pow(Xa[2] - Xb[2], 2)));
}

/* the first of the n points X (bodies, in creation order) that `check`
 * marks with a point of another body closer than dp / 2, and the first
 * such point: as an error, *first its index (n: none) */
static sph_status find_overlap(const sph_scene *s, const double *X,
                               const int32_t *body, const char *check, size_t n,
                               size_t *first, sph_error *err) {
  *first = n;
  sph_neighbors *nl;
  SPH_TRY(sph_neighbors_create(&nl, err));
  sph_status st = sph_neighbors_build(nl, X, n, s->dimension,
                                      0.5 * sph_scene_min_spacing(s), NULL,
                                      SPH_PAIRS_ALL, err);
  for (size_t a = 0; st == SPH_OK && a < n; ++a)
    for (size_t k = nl->offset[a];
         (!check || check[a]) && k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      if (body[b] == body[a])
        continue;
      *first = a;
      st = overlap_error(s, body[a], body[b], X + 3 * a, X + 3 * b, err);
      break;
    }
  sph_neighbors_destroy(nl);
  return st;
}

static sph_status check_overlap(const sph_scene *s, sph_particles *ps,
                                sph_error *err) {
  if (s->nbodies < 2)
    return SPH_OK;
  size_t first;
  return find_overlap(s, ps->field[SPH_FIELD_POSITION0], ps->body, NULL, ps->n,
                      &first, err);
}

sph_status sph_scene_build_particles(const sph_scene *s, sph_particles **out,
                                     sph_error *err) {
  *out = NULL;
  double **xs = calloc(s->nbodies, sizeof *xs);
  double **vs = calloc(s->nbodies, sizeof *vs);
  size_t *ns = calloc(s->nbodies, sizeof *ns), total = 0;
  build_checks c;
  sph_status st = checks_create(s, &c, err);
  if (st == SPH_OK && !(xs && vs && ns))
    st = sph_error_set(err, SPH_ERR_NOMEM, "bodies");
  for (size_t b = 0; st == SPH_OK && b < s->nbodies; ++b) {
    st = sph_body_generate(&s->bodies[b], s->dimension, &xs[b], &vs[b], &ns[b],
                           err);
    if (st != SPH_OK)
      st = body_error(s, b, st, err);
    total += ns[b];
  }
  sph_particles *ps = NULL;
  if (st == SPH_OK)
    st = sph_particles_create(&ps, total, s->dimension, err);
  if (st == SPH_OK)
    st = sph_particles_require(ps, SPH_FIELD_VELOCITY, err);
  /* positions and initial velocities from the body frame to the world */
  for (size_t b = 0; st == SPH_OK && b < s->nbodies; ++b)
    for (size_t i = 0; st == SPH_OK && i < ns[b]; ++i) {
      double X[3], v[3];
      uint32_t flags;
      particle_state(s, b, xs[b] + 3 * i, X, v, &flags, &c);
      st = sph_particles_append(ps, X, vs[b][i], (int32_t)b, err);
      if (st == SPH_OK) {
        memcpy(ps->field[SPH_FIELD_VELOCITY] + 3 * (ps->n - 1), v, sizeof v);
        ps->flags[ps->n - 1] = flags;
      }
    }
  for (size_t b = 0; xs && vs && b < s->nbodies; ++b) {
    free(xs[b]);
    free(vs[b]);
  }
  free(xs);
  free(vs);
  free(ns);
  if (st == SPH_OK)
    st = checks_first(&c, err);
  if (st == SPH_OK)
    st = check_overlap(s, ps, err);
  if (st == SPH_OK)
    st = checks_rest(s, &c, err);
  checks_destroy(&c);
  if (st != SPH_OK) {
    sph_particles_destroy(ps);
    return st;
  }
  *out = ps;
  return SPH_OK;
}

/* ---- one rank's share, without the whole set ------------------------------
 */

/* the passes of sph_scene_build_share over every particle in creation order */
typedef struct share_pass {
  const sph_scene *s;
  int pass;       /* 1: bounds and checks, 2: count per cell, 3: keep */
  size_t b;       /* the body visited */
  int64_t id;     /* creation index of the next particle */
  build_checks c; /* pass 1 */
  double lo[3], hi[3], cell;
  size_t nc[3];  /* cells per axis */
  int64_t *grid; /* pass 2: particles per cell; pass 3: next storage index */
  int64_t first, last; /* storage indices kept: [first, last) */
  sph_particles *ps;
  int64_t *gidx;
  /* several bodies: the share's particles and those of the cells next to
   * its cells (the overlap check's neighbours), in creation order */
  char *mine; /* per cell: holds a particle of the share */
  double *nx;
  int32_t *nbody;
  int64_t *nid;
  char *nin; /* in the share */
  size_t nn, ncap;
  sph_body_slice **slices; /* per body: a relax body's slice on this rank */
} share_pass;

/* whether a cell next to q (or q) holds a particle of the share */
static int near_share(const share_pass *p, const uint32_t q[3]) {
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k) {
        long c[3] = {(long)q[0] + i, (long)q[1] + j, (long)q[2] + k};
        int in = 1;
        for (int e = 0; e < 3; ++e)
          in &= c[e] >= 0 && c[e] < (long)p->nc[e];
        if (in && p->mine[((size_t)c[2] * p->nc[1] + (size_t)c[1]) * p->nc[0] +
                          (size_t)c[0]])
          return 1;
      }
  return 0;
}

/* a point of the overlap check */
static sph_status keep_near(share_pass *p, const double X[3], int64_t id,
                            int in, sph_error *err) {
  if (p->nn == p->ncap) {
    size_t c = p->ncap ? 2 * p->ncap : 1024;
    double *x = realloc(p->nx, 3 * c * sizeof *x);
    if (x)
      p->nx = x;
    int32_t *b = realloc(p->nbody, c * sizeof *b);
    if (b)
      p->nbody = b;
    int64_t *i = realloc(p->nid, c * sizeof *i);
    if (i)
      p->nid = i;
    char *n = realloc(p->nin, c);
    if (n)
      p->nin = n;
    if (!x || !b || !i || !n)
      return sph_error_set(err, SPH_ERR_NOMEM, "overlap check");
    p->ncap = c;
  }
  memcpy(p->nx + 3 * p->nn, X, 3 * sizeof *X);
  p->nbody[p->nn] = (int32_t)p->b;
  p->nid[p->nn] = id;
  p->nin[p->nn++] = (char)in;
  return SPH_OK;
}

typedef struct share_cell {
  uint64_t key;
  size_t cell;
} share_cell;

static int cmp_share_cell(const void *pa, const void *pb) {
  const share_cell *a = pa, *b = pb;
  return (a->key > b->key) - (a->key < b->key);
}

static sph_status share_point(void *ctx, const double Xb[3], double volume,
                              sph_error *err) {
  share_pass *p = ctx;
  const sph_scene *s = p->s;
  double X[3], v[3];
  uint32_t flags, q[3];
  int64_t id = p->id++;
  if (p->pass == 1) {
    particle_state(s, p->b, Xb, X, v, &flags, &p->c);
    for (int c = 0; c < 3; ++c) {
      p->lo[c] = fmin(p->lo[c], X[c]);
      p->hi[c] = fmax(p->hi[c], X[c]);
    }
    return SPH_OK;
  }
  sph_body_world(&s->bodies[p->b], Xb, X);
  sph_morton_cell(X, p->lo, p->cell, q);
  size_t cell = ((size_t)q[2] * p->nc[1] + q[1]) * p->nc[0] + q[0];
  if (p->pass == 2) {
    p->grid[cell]++;
    return SPH_OK;
  }
  /* particles of one cell in creation order: the sort's tie-break */
  int64_t g = p->grid[cell]++;
  int in = g >= p->first && g < p->last;
  if (p->mine && (in || near_share(p, q)))
    SPH_TRY(keep_near(p, X, id, in, err));
  if (!in)
    return SPH_OK;
  sph_particles *ps = p->ps;
  particle_state(s, p->b, Xb, X, v, &flags, NULL);
  SPH_TRY(sph_particles_append(ps, X, volume, (int32_t)p->b, err));
  memcpy(ps->field[SPH_FIELD_VELOCITY] + 3 * (ps->n - 1), v, sizeof v);
  ps->flags[ps->n - 1] = flags;
  ps->id[ps->n - 1] = id;
  p->gidx[ps->n - 1] = g;
  return SPH_OK;
}

/* one pass over every body's particles */
static sph_status share_visit(share_pass *p, int pass, sph_error *err) {
  p->pass = pass;
  p->id = 0;
  for (p->b = 0; p->b < p->s->nbodies; ++p->b) {
    size_t n;
    sph_status st =
        sph_body_visit_share(&p->s->bodies[p->b], p->s->dimension,
                             &p->slices[p->b], share_point, p, &n, err);
    if (st != SPH_OK)
      return body_error(p->s, p->b, st, err);
  }
  return SPH_OK;
}

/* grid[cell] = the storage index of the cell's first particle: the
 * occupied cells in Morton order */
static sph_status share_starts(share_pass *p, size_t cells, sph_error *err) {
  size_t m = 0;
  for (size_t k = 0; k < cells; ++k)
    m += p->grid[k] > 0;
  share_cell *occ = malloc((m ? m : 1) * sizeof *occ);
  if (!occ)
    return sph_error_set(err, SPH_ERR_NOMEM, "particle order (%zu cells)", m);
  m = 0;
  for (size_t k = 0; k < cells; ++k)
    if (p->grid[k] > 0) {
      uint32_t q[3] = {(uint32_t)(k % p->nc[0]),
                       (uint32_t)(k / p->nc[0] % p->nc[1]),
                       (uint32_t)(k / p->nc[0] / p->nc[1])};
      occ[m++] = (share_cell){sph_morton_key(q), k};
    }
  qsort(occ, m, sizeof *occ, cmp_share_cell);
  int64_t start = 0;
  for (size_t j = 0; j < m; ++j) {
    int64_t count = p->grid[occ[j].cell];
    p->grid[occ[j].cell] = start;
    if (p->mine)
      p->mine[occ[j].cell] = start < p->last && start + count > p->first;
    start += count;
  }
  free(occ);
  return SPH_OK;
}

static sph_status build_share(const sph_scene *s, double cell, int rank,
                              int size, sph_particles **out, int64_t **gidx,
                              size_t *total, int64_t *overlap,
                              sph_body_slice **slices, sph_error *err) {
  *out = NULL;
  *gidx = NULL;
  *total = 0;
  *overlap = INT64_MAX;
  share_pass p = {.s = s,
                  .cell = cell,
                  .slices = slices,
                  .lo = {INFINITY, INFINITY, INFINITY},
                  .hi = {-INFINITY, -INFINITY, -INFINITY}};
  /* pass 1: the bounds and the checks, as the whole set's (relax bodies
   * relaxed per rank on their first visit) */
  sph_status st = checks_create(s, &p.c, err);
  if (st == SPH_OK)
    st = share_visit(&p, 1, err);
  size_t N = (size_t)p.id;
  if (st == SPH_OK)
    st = checks_first(&p.c, err);
  /* the later checks' error comes after the overlap check's */
  sph_error later;
  sph_status rest = st == SPH_OK ? checks_rest(s, &p.c, &later) : SPH_OK;
  checks_destroy(&p.c);
  int several = s->nbodies > 1;
  if (st == SPH_OK && rest != SPH_OK && !several)
    *err = later, st = rest;
  if (st != SPH_OK)
    return st;
  /* the cell grid of the Morton order; a sparse one (far apart bodies)
   * larger than 2 cells a particle and 2^22 cells, or for the overlap check
   * cells clamped or smaller than its dp / 2: the whole set instead */
  double cells = 1.0;
  int clamped = 0;
  for (int c = 0; c < 3; ++c) {
    double q = floor((p.hi[c] - p.lo[c]) / cell);
    clamped |= q > 2097151.0;
    p.nc[c] = (size_t)fmin(q, 2097151.0) + 1;
    cells *= (double)p.nc[c];
  }
  if (!(cell > 0.0) || cells > fmax(2.0 * (double)N, 4194304.0) ||
      (several && (clamped || 0.5 * sph_scene_min_spacing(s) > cell)))
    return SPH_OK;
  p.grid = calloc((size_t)cells, sizeof *p.grid);
  if (several)
    p.mine = calloc((size_t)cells, 1);
  if (!p.grid || (several && !p.mine)) {
    free(p.grid);
    free(p.mine);
    return sph_error_set(err, SPH_ERR_NOMEM, "particle order (%.3g cells)",
                         cells);
  }
  /* pass 2: particles per cell; pass 3: storage indices, keeping the
   * share [rank N / size, (rank + 1) N / size) */
  p.first = (int64_t)(N * (size_t)rank / (size_t)size);
  p.last = (int64_t)(N * ((size_t)rank + 1) / (size_t)size);
  size_t m = (size_t)(p.last - p.first);
  st = share_visit(&p, 2, err);
  if (st == SPH_OK)
    st = share_starts(&p, (size_t)cells, err);
  if (st == SPH_OK)
    st = sph_particles_create(&p.ps, m, s->dimension, err);
  if (st == SPH_OK)
    st = sph_particles_require(p.ps, SPH_FIELD_VELOCITY, err);
  if (st == SPH_OK && !(p.gidx = malloc((m ? m : 1) * sizeof *p.gidx)))
    st = sph_error_set(err, SPH_ERR_NOMEM, "particle share (%zu)", m);
  if (st == SPH_OK)
    st = share_visit(&p, 3, err);
  free(p.grid);
  free(p.mine);
  /* bodies that overlap: the share's first particle with a neighbour of
   * another body closer than dp / 2 (its neighbours are in the share or
   * the cells next to its cells) */
  size_t bad = p.nn;
  if (st == SPH_OK && several)
    st = find_overlap(s, p.nx, p.nbody, p.nin, p.nn, &bad, err);
  if (bad < p.nn)
    *overlap = p.nid[bad];
  if (st == SPH_OK && rest != SPH_OK)
    *err = later, st = rest;
  free(p.nx);
  free(p.nbody);
  free(p.nid);
  free(p.nin);
  if (st != SPH_OK) {
    sph_particles_destroy(p.ps);
    free(p.gidx);
    return st;
  }
  *out = p.ps;
  *gidx = p.gidx;
  *total = N;
  return SPH_OK;
}

sph_status sph_scene_build_share(const sph_scene *s, double cell, int rank,
                                 int size, sph_particles **out, int64_t **gidx,
                                 size_t *total, int64_t *overlap,
                                 sph_error *err) {
  sph_body_slice **slices = calloc(s->nbodies + 1, sizeof *slices);
  if (!slices)
    return sph_error_set(err, SPH_ERR_NOMEM, "bodies");
  sph_status st =
      build_share(s, cell, rank, size, out, gidx, total, overlap, slices, err);
  for (size_t b = 0; b < s->nbodies; ++b)
    sph_body_slice_destroy(slices[b]);
  free(slices);
  return st;
}
