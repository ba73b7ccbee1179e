/* The scene's `boundaries:` and `contact:` blocks: selections (plane, box,
 * face of a body, in the frame of the body they name), conditions (clamp,
 * roller, velocity, symmetry and skew-symmetry planes) and the rigid walls
 * of penalty contact. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/mesh.h"
#include "scene/schema_impl.h"

/* The placement of the body a selection names, or NULL (world frame). */
const sph_transform *sph_schema_selection_frame(const sph_scene *s,
                                                const sph_selection *sel) {
  if (sel->body < 0 || !s->bodies[sel->body].transform.given)
    return NULL;
  return &s->bodies[sel->body].transform;
}

/* near: {file, units, distance, body}: the surface a selection is near,
 * any triangles (an open face is fine); distance read by the caller */
static sph_status parse_near(sph_scene *s, sph_selection *sel, sph_node *g,
                             sph_error *err) {
  if (s->dimension != 3)
    return sph_node_error(g, err, SPH_ERR_GEOMETRY,
                          "a near selection takes a mesh: 3D scenes only");
  const char *file;
  int u;
  SPH_TRY(sph_node_get_string(g, "file", 1, NULL, &file, err));
  sph_node *fn = sph_node_child(g, "file");
  SPH_TRY(sph_node_get_choice(g, "units", sph_length_units, "m", &u, err));
  char path[1024];
  sph_schema_file_path(fn, file, path, sizeof path);
  double *tri;
  size_t n;
  sph_status st = sph_mesh_read(path, &tri, &n, err);
  if (st == SPH_OK) {
    st = sph_mesh_create(&sel->near, tri, n, sph_length_scale[u], 0, err);
    free(tri);
  }
  if (st != SPH_OK) {
    char msg[768];
    snprintf(msg, sizeof msg, "%s", err->message);
    return sph_node_error(fn, err, st, "mesh %s", msg);
  }
  sph_schema_name_absolute(fn, path);
  return SPH_OK;
}

static sph_status parse_selection(sph_scene *s, sph_selection *sel, sph_node *n,
                                  sph_error *err) {
  static const char *const kinds[] = {"plane", "box", "face", "near", NULL};
  SPH_TRY(sph_node_check_keys(n, kinds, err));
  int which;
  SPH_TRY(sph_schema_one_of(n, kinds, "selection", &which, err));
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
  } else if (which == SPH_SELECT_NEAR) {
    static const char *const keys[] = {"file", "units", "distance", "body",
                                       NULL};
    SPH_TRY(sph_node_check_keys(g, keys, err));
    SPH_TRY(sph_node_get_string(g, "body", 0, NULL, &body, err));
    SPH_TRY(parse_near(s, sel, g, err));
    sel->tolerance = -1.0; /* resolved below */
    if (sph_node_child(g, "distance"))
      SPH_TRY(sph_node_get_positive(g, "distance", 1, 0, &sel->tolerance, err));
  } else {
    static const char *const pkeys[] = {"axis", "at", "tolerance", "body",
                                        NULL};
    static const char *const bkeys[] = {"min", "max", "body", NULL};
    SPH_TRY(sph_node_check_keys(g, which == 0 ? pkeys : bkeys, err));
    SPH_TRY(sph_node_get_string(g, "body", 0, NULL, &body, err));
    if (which == SPH_SELECT_PLANE) {
      SPH_TRY(sph_schema_get_direction(g, "axis", 1, 0, s->dimension,
                                       sel->normal, err));
      SPH_TRY(sph_node_get_double(g, "at", 1, 0, &sel->at, err));
      sel->tolerance = -1.0; /* resolved below */
      if (sph_node_child(g, "tolerance"))
        SPH_TRY(
            sph_node_get_positive(g, "tolerance", 1, 0, &sel->tolerance, err));
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
                                sph_axis_names[c]);
    }
  }
  if (body) {
    sel->body = sph_scene_find_body(s, body);
    if (sel->body < 0)
      return sph_node_error(sph_node_child(g, "body"), err, SPH_ERR_ARG,
                            "no body named '%s'", body);
  }
  /* a plane in the frame of a placed body, in the world frame */
  const sph_transform *T = sph_schema_selection_frame(s, sel);
  if (sel->kind == SPH_SELECT_PLANE && T) {
    double w[3];
    sph_transform_rotate(T, sel->normal, w);
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
  int own = sel->kind == SPH_SELECT_PLANE || sel->kind == SPH_SELECT_NEAR;
  if (own && sel->tolerance < 0.0) {
    char buf[40];
    snprintf(buf, sizeof buf, "%.17g", tol);
    sel->tolerance = tol;
    SPH_TRY(sph_node_insert_default(
        g, sel->kind == SPH_SELECT_NEAR ? "distance" : "tolerance", buf,
        &(sph_node *){0}, err));
  } else if (!own) {
    sel->tolerance = 1e-9 * spacing;
  }
  return SPH_OK;
}

sph_status sph_schema_boundaries(sph_scene *s, sph_node *root, sph_error *err) {
  sph_node *list;
  SPH_TRY(sph_schema_get_seq(root, "boundaries", 0, &list, err));
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
    sph_schema_copy_name(b->name, name);
    sph_node *sel;
    SPH_TRY(sph_node_get_map(n, "select", 1, &sel, err));
    SPH_TRY(parse_selection(s, &b->select, sel, err));
    int which;
    SPH_TRY(sph_schema_one_of(n, conds, "condition", &which, err));
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
      const sph_transform *T = sph_schema_selection_frame(s, &b->select);
      if (T) {
        double w[3];
        sph_transform_rotate(T, b->value, w);
        memcpy(b->value, w, sizeof w);
      }
      sph_node *comp;
      SPH_TRY(sph_schema_get_seq(v, "components", 0, &comp, err));
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
      SPH_TRY(sph_schema_get_direction(c, "axis", 1, 0, s->dimension, b->normal,
                                       err));
      const sph_transform *T = sph_schema_selection_frame(s, &b->select);
      if (T) {
        double w[3];
        sph_transform_rotate(T, b->normal, w);
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

/* contact: {stiffness, between_bodies, walls: [{name, plane|box, velocity}]}
 * (rigid frictionless walls and body-to-body contact, src/terms/contact.c) */
sph_status sph_schema_contact(sph_scene *s, sph_node *root, sph_error *err) {
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
  SPH_TRY(sph_node_get_positive(c, "stiffness", 0, 1.0, &ct->stiffness, err));
  SPH_TRY(
      sph_node_get_bool(c, "between_bodies", 0, 0, &ct->between_bodies, err));
  if (ct->between_bodies && s->nbodies < 2)
    return sph_node_error(sph_node_child(c, "between_bodies"), err, SPH_ERR_ARG,
                          "between_bodies needs two bodies or more, the scene "
                          "has %zu",
                          s->nbodies);
  sph_node *list;
  SPH_TRY(sph_schema_get_seq(c, "walls", 0, &list, err));
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
    sph_schema_copy_name(w->name, name);
    int which;
    SPH_TRY(sph_schema_one_of(n, kinds, "wall shape", &which, err));
    sph_node *g;
    SPH_TRY(sph_node_get_map(n, kinds[which], 1, &g, err));
    if (which == 0) {
      static const char *const pkeys[] = {"point", "normal", NULL};
      SPH_TRY(sph_node_check_keys(g, pkeys, err));
      w->kind = SPH_WALL_PLANE;
      SPH_TRY(sph_node_get_doubles(g, "point", 1, d, w->point, NULL, err));
      SPH_TRY(sph_schema_get_direction(g, "normal", 1, 0, s->dimension,
                                       w->normal, err));
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
                                sph_axis_names[k]);
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
