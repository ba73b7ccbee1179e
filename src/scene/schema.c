/* The scene schema (docs/design.md sec. 6): the top-level keys, the kernel,
 * time and stability blocks, the loader (YAML tree, --set overrides, every
 * section checked, typed and defaulted, with errors at the file, line,
 * column and key) and the helpers the section files share (schema_impl.h):
 * axes and directions (x, y, z or any vector), lists and one-of choices.
 * The method and reference blocks are left to their users. */
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "scene/cloud.h"
#include "scene/expr.h"
#include "scene/mesh.h"
#include "scene/polygon.h"
#include "scene/schema_impl.h"
#include "solver/stability.h"

/* the most time steps a scene may need (check_step_count) */
#define SPH_STEPS_MAX 1e12

const char *const sph_axis_names[] = {"x", "y", "z", NULL};

/* (schema_impl.h) */
sph_status sph_schema_get_seq(sph_node *map, const char *key, int required,
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
  SPH_TRY(
      sph_node_get_string(map, key, required, sph_axis_names[def], &name, err));
  for (int a = 0; a < 3; ++a)
    if (!strcmp(name, sph_axis_names[a])) {
      *out = a;
      return SPH_OK;
    }
  return sph_node_error(sph_node_child(map, key), err, SPH_ERR_RANGE,
                        "%s must be x, y, z or a vector [a, b, c], got '%s'",
                        key, name);
}

/* A direction: x, y or z, or a non-zero vector of n numbers (n = 2 leaves
 * z = 0), scaled to unit length. */
sph_status sph_schema_get_direction(sph_node *map, const char *key,
                                    int required, int def, int n, double out[3],
                                    sph_error *err) {
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

/* The one key of `map` among `choices`; errors when none or several. */
sph_status sph_schema_one_of(sph_node *map, const char *const *choices,
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

void sph_schema_copy_name(char *dst, const char *src) {
  snprintf(dst, SPH_NAME_MAX, "%s", src);
}

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

/* A run needs at least time.end * c / dp steps (a CFL number <= 1, c the
 * p-wave speed): more than 1e12 is no physical scene (a density of 1e-300)
 * and is refused at the density of the fastest body's material. */
static sph_status check_step_count(const sph_scene *s, sph_node *root,
                                   sph_error *err) {
  double most = 0.0;
  size_t at = 0;
  for (size_t b = 0; b < s->nbodies; ++b) {
    const sph_body *body = &s->bodies[b];
    double c = sph_material_wave_speed(&s->materials[body->material]);
    double steps = body->spacing > 0.0 ? s->t_end * c / body->spacing : 0.0;
    if (!(steps <= most)) { /* NaN too */
      most = steps;
      at = b;
    }
  }
  if (most <= SPH_STEPS_MAX)
    return SPH_OK;
  int m = s->bodies[at].material;
  sph_node *mats = sph_node_child(root, "materials");
  sph_node *mat = mats && (size_t)m < mats->count
                      ? mats->items[m]
                      : sph_node_child(root, "time");
  sph_node *key = mat ? sph_node_child(mat, "density") : NULL;
  if (mat && !sph_node_from_command_line(key) &&
      sph_node_from_command_line(mat))
    key = mat; /* reported at the material's key --set gave */
  sph_node *time = sph_node_child(root, "time");
  sph_node *end = time ? sph_node_child(time, "end") : NULL;
  if (end && end->file && !strcmp(end->file, "<command line>") &&
      (!key || !key->file || strcmp(key->file, "<command line>")))
    key = end; /* the --set that made it so */
  return sph_node_error(
      key ? key : mat, err, SPH_ERR_RANGE,
      "body %s would need at least %.3g time steps (wave "
      "speed %.3g m/s in material %s, spacing %.3g m, end "
      "%g s); at most %.0e: check the material's density "
      "and elastic constants",
      s->bodies[at].name, most, sph_material_wave_speed(&s->materials[m]),
      s->materials[m].name, s->bodies[at].spacing, s->t_end, SPH_STEPS_MAX);
}

static sph_status parse_scene(sph_scene *s, sph_node *root, sph_error *err) {
  if (root->kind != SPH_NODE_MAP)
    return sph_node_error(root, err, SPH_ERR_TYPE,
                          "a scene is a mapping of keys (name, dimension, "
                          "method, materials, bodies, time, ...)");
  static const char *const keys[] = {
      "name",      "dimension",  "method",     "kernel", "materials",
      "bodies",    "boundaries", "body_force", "time",   "output",
      "reference", "stability",  "contact",    "device", NULL};
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
  sph_schema_copy_name(s->name, name);
  long dim;
  SPH_TRY(sph_node_get_int(root, "dimension", 1, 3, &dim, err));
  if (dim != 2 && dim != 3)
    return sph_node_error(sph_node_child(root, "dimension"), err, SPH_ERR_RANGE,
                          "dimension is 2 or 3, got %ld", dim);
  s->dimension = (int)dim;
  /* read only when given: a scene without it resolves as before */
  if ((s->device_at = sph_node_child(root, "device"))) {
    static const char *const devices[] = {"cpu", "cuda", NULL};
    int d;
    SPH_TRY(sph_node_get_choice(root, "device", devices, "cpu", &d, err));
    s->device = d == 1 ? SPH_DEVICE_CUDA : SPH_DEVICE_CPU;
  }
  SPH_TRY(sph_node_get_map(root, "method", 1, &s->method, err));
  const char *method;
  SPH_TRY(sph_node_get_string(s->method, "name", 1, NULL, &method, err));
  sph_schema_copy_name(s->method_name, method);
  SPH_TRY(sph_node_get_map(root, "reference", 0, &s->reference, err));
  sph_node *time;
  SPH_TRY(sph_node_get_map(root, "time", 1, &time, err));
  static const char *const tkeys[] = {"end", NULL};
  SPH_TRY(sph_node_check_keys(time, tkeys, err));
  SPH_TRY(sph_node_get_positive(time, "end", 1, 0, &s->t_end, err));
  SPH_TRY(parse_kernel(s, root, err));
  SPH_TRY(sph_schema_materials(s, root, err));
  SPH_TRY(sph_schema_bodies(s, root, err));
  SPH_TRY(check_step_count(s, root, err));
  SPH_TRY(sph_schema_boundaries(s, root, err));
  if (sph_node_child(root, "body_force")) {
    s->has_body_force = 1;
    SPH_TRY(sph_node_get_doubles(root, "body_force", 1, 3, s->body_force, NULL,
                                 err));
  }
  SPH_TRY(sph_schema_contact(s, root, err));
  SPH_TRY(sph_schema_output(s, root, err));
  SPH_TRY(parse_stability(s, root, err));
  return SPH_OK;
}

/* A shipped scene's name ("punch" or "punch.yaml") that is no file here:
 * $SPH_SCENES_DIR's, the installed one, the source tree's; anything else is
 * returned as given (the loader then says what is wrong). */
static const char *scene_find(const char *path, char *buf, size_t size) {
  struct stat st;
  if (!*path || strchr(path, '/') || stat(path, &st) == 0)
    return path;
  const char *env = getenv("SPH_SCENES_DIR");
  const char *dirs[] = {env && *env ? env : NULL, SPH_SCENES_INSTALLED,
                        SPH_SCENES_SOURCE};
  size_t len = strlen(path);
  int ext = len > 5 && !strcmp(path + len - 5, ".yaml");
  for (int i = 0; i < 3; ++i)
    if (dirs[i] &&
        snprintf(buf, size, "%s/%s%s", dirs[i], path, ext ? "" : ".yaml") <
            (int)size &&
        stat(buf, &st) == 0 && S_ISREG(st.st_mode))
      return buf;
  return path;
}

sph_status sph_scene_load(sph_scene **out, const char *path,
                          const char *const *overrides, size_t nset,
                          sph_error *err) {
  *out = NULL;
  char found[sizeof((sph_scene *)0)->path];
  path = scene_find(path, found, sizeof found);
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
    sph_mesh_destroy(s->bodies[i].shape.mesh);
    sph_polygon_destroy(s->bodies[i].shape.polygon);
    sph_cloud_destroy(s->bodies[i].shape.cloud);
  }
  free(s->bodies);
  free(s->materials);
  for (size_t i = 0; i < s->nboundaries; ++i)
    sph_mesh_destroy(s->boundaries[i].select.near);
  free(s->boundaries);
  free(s->contact.walls);
  free(s->output.probes);
  sph_node_destroy(s->root);
  free(s);
}
