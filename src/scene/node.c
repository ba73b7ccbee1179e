/* The scene tree (no paper: input handling, docs/design.md sec. 6): nodes that
 * keep their file, line, column and dotted path; lookups, errors at a node,
 * Levenshtein "did you mean" hints and the check of a map's keys; scalar
 * conversions and the typed getters that fill defaults and mark keys used.
 * Reading and writing YAML and --set overrides are in node_yaml.c. */
#include "scene/node.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "scene/node_impl.h"

/* ---- construction ---- */

char *sph_node_join_key(const char *parent, const char *key) {
  size_t len = strlen(parent) + strlen(key) + 2;
  char *p = malloc(len);
  if (p)
    snprintf(p, len, "%s%s%s", parent, *parent ? "." : "", key);
  return p;
}

char *sph_node_join_index(const char *parent, size_t i) {
  size_t len = strlen(parent) + 24;
  char *p = malloc(len);
  if (p)
    snprintf(p, len, "%s[%zu]", parent, i);
  return p;
}

sph_node *sph_node_new(sph_node_kind kind, const char *file, int line,
                       int col) {
  sph_node *n = calloc(1, sizeof *n);
  if (!n)
    return NULL;
  n->kind = kind;
  n->file = strdup(file ? file : "");
  n->path = strdup("");
  n->line = line;
  n->col = col;
  if (!n->file || !n->path) {
    free(n->file);
    free(n->path);
    free(n);
    return NULL;
  }
  return n;
}

sph_node *sph_node_scalar_new(const char *text, const char *file, int line,
                              int col) {
  sph_node *n = sph_node_new(SPH_NODE_SCALAR, file, line, col);
  if (n && !(n->value = strdup(text))) {
    sph_node_destroy(n);
    return NULL;
  }
  return n;
}

void sph_node_destroy(sph_node *n) {
  if (!n)
    return;
  for (size_t i = 0; i < n->count; ++i) {
    if (n->keys)
      free(n->keys[i]);
    sph_node_destroy(n->items[i]);
  }
  free(n->keys);
  free(n->items);
  free(n->value);
  free(n->file);
  free(n->path);
  free(n);
}

/* Appends a child (key ignored for sequences); takes ownership on success. */
int sph_node_append(sph_node *parent, const char *key, sph_node *child) {
  size_t c = parent->count + 1;
  char *k = NULL;
  if (parent->kind == SPH_NODE_MAP && !(k = strdup(key ? key : "")))
    return -1;
  sph_node **items = realloc(parent->items, c * sizeof *items);
  if (!items) {
    free(k);
    return -1;
  }
  parent->items = items;
  if (parent->kind == SPH_NODE_MAP) {
    char **keys = realloc(parent->keys, c * sizeof *keys);
    if (!keys) {
      free(k);
      return -1;
    }
    parent->keys = keys;
    keys[c - 1] = k;
  }
  items[c - 1] = child;
  parent->count = c;
  return 0;
}

/* Sets the path of n and, recursively, of its children. */
int sph_node_set_path(sph_node *n, const char *path) {
  char *p = strdup(path);
  if (!p)
    return -1;
  free(n->path);
  n->path = p; /* path may have been the old n->path: use p from here */
  for (size_t i = 0; i < n->count; ++i) {
    char *cp = n->kind == SPH_NODE_MAP ? sph_node_join_key(p, n->keys[i])
                                       : sph_node_join_index(p, i);
    int rc = cp ? sph_node_set_path(n->items[i], cp) : -1;
    free(cp);
    if (rc)
      return -1;
  }
  return 0;
}

void sph_node_set_origin(sph_node *n, const char *file, int line, int col) {
  char *f = strdup(file);
  if (f) {
    free(n->file);
    n->file = f;
  }
  n->line = line;
  n->col = col;
  for (size_t i = 0; i < n->count; ++i)
    sph_node_set_origin(n->items[i], file, line, col);
}

static const char *kind_name(sph_node_kind k) {
  return k == SPH_NODE_MAP ? "a mapping"
                           : (k == SPH_NODE_SEQ ? "a sequence" : "a scalar");
}

/* ---- lookups and errors ---- */

sph_node *sph_node_child(const sph_node *map, const char *key) {
  if (!map || map->kind != SPH_NODE_MAP)
    return NULL;
  for (size_t i = 0; i < map->count; ++i)
    if (strcmp(map->keys[i], key) == 0)
      return map->items[i];
  return NULL;
}

const sph_node *sph_node_from_command_line(const sph_node *n) {
  if (!n)
    return NULL;
  if (n->file && !strcmp(n->file, "<command line>"))
    return n;
  for (size_t i = 0; i < n->count; ++i) {
    const sph_node *c = sph_node_from_command_line(n->items[i]);
    if (c)
      return c;
  }
  return NULL;
}

static const sph_node *node_at_path(const sph_node *n, const char *path) {
  if (n->path && !strcmp(n->path, path))
    return n;
  for (size_t i = 0; i < n->count; ++i) {
    const sph_node *c = node_at_path(n->items[i], path);
    if (c)
      return c;
  }
  return NULL;
}

void sph_node_blame_set(const sph_node *root, const char *file,
                        sph_error *err) {
  if (!root || !err || !err->key[0] || strcmp(err->file, file))
    return;
  const sph_node *n = node_at_path(root, err->key);
  const sph_node *set = n ? sph_node_from_command_line(n) : NULL;
  if (!set || set == n)
    return;
  snprintf(err->file, sizeof err->file, "%s", set->file);
  err->line = set->line;
  err->col = set->col;
  sph_key_path_fit(err->key, sizeof err->key, set->path);
}

sph_status sph_node_error(const sph_node *n, sph_error *err, sph_status code,
                          const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  /* an error at a key whose value --set changed inside it (an element of a
   * list, a key of a map) is the command line's (issue 36 item 7) */
  const sph_node *set =
      n && n->path && n->path[0] ? sph_node_from_command_line(n) : NULL;
  if (set)
    n = set;
  if (n)
    sph_error_atv(err, code, n->file, n->line, n->col, n->path, fmt, ap);
  else
    sph_error_atv(err, code, NULL, 0, 0, NULL, fmt, ap);
  va_end(ap);
  return code;
}

size_t sph_edit_distance(const char *a, const char *b) {
  size_t la = strlen(a), lb = strlen(b);
  size_t *row = malloc((lb + 1) * sizeof *row);
  if (!row)
    return la > lb ? la : lb; /* an upper bound */
  for (size_t j = 0; j <= lb; ++j)
    row[j] = j;
  for (size_t i = 1; i <= la; ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= lb; ++j) {
      size_t up = row[j];
      size_t best = diag + (a[i - 1] != b[j - 1]);
      if (up + 1 < best)
        best = up + 1;
      if (row[j - 1] + 1 < best)
        best = row[j - 1] + 1;
      row[j] = best;
      diag = up;
    }
  }
  size_t d = row[lb];
  free(row);
  return d;
}

const char *sph_suggest(const char *word, const char *const *candidates) {
  const char *best = NULL;
  size_t best_d = (size_t)-1, len = strlen(word);
  size_t limit = len / 3 > 2 ? len / 3 : 2;
  for (const char *const *c = candidates; *c; ++c) {
    size_t d = sph_edit_distance(word, *c);
    /* a prefix of a longer key ("poisson" for "poisson_ratio") counts as 1 */
    if (len >= 3 && strncmp(word, *c, len) == 0 && d > 1)
      d = 1;
    if (d < best_d) {
      best_d = d;
      best = *c;
    }
  }
  return best_d <= limit ? best : NULL;
}

sph_status sph_node_check_keys(const sph_node *map, const char *const *allowed,
                               sph_error *err) {
  if (!map || map->kind != SPH_NODE_MAP)
    return SPH_OK;
  for (size_t i = 0; i < map->count; ++i) {
    const char *key = map->keys[i];
    int ok = 0;
    for (const char *const *a = allowed; *a && !ok; ++a)
      ok = strcmp(*a, key) == 0;
    if (ok)
      continue;
    const char *hint = sph_suggest(key, allowed);
    if (hint)
      return sph_node_error(map->items[i], err, SPH_ERR_UNKNOWN_KEY,
                            "unknown key '%s'; did you mean '%s'?", key, hint);
    char list[512] = "";
    for (const char *const *a = allowed; *a; ++a) {
      strncat(list, a == allowed ? "" : ", ", sizeof list - strlen(list) - 1);
      strncat(list, *a, sizeof list - strlen(list) - 1);
    }
    return sph_node_error(map->items[i], err, SPH_ERR_UNKNOWN_KEY,
                          "unknown key '%s' (allowed: %s)", key, list);
  }
  return SPH_OK;
}

/* ---- scalar conversions ---- */

static sph_status need_scalar(const sph_node *n, const char *what,
                              sph_error *err) {
  if (n->kind != SPH_NODE_SCALAR)
    return sph_node_error(n, err, SPH_ERR_TYPE, "expected %s, got %s", what,
                          kind_name(n->kind));
  if (n->quoted)
    return sph_node_error(n, err, SPH_ERR_TYPE,
                          "expected %s, got the quoted string \"%s\"", what,
                          n->value);
  return SPH_OK;
}

sph_status sph_node_as_double(const sph_node *n, double *out, sph_error *err) {
  SPH_TRY(need_scalar(n, "a number", err));
  const char *s = n->value;
  /* decimal only: strtod would also take "inf", "nan" and hex floats */
  int bad = *s == '\0';
  for (const char *c = s; *c && !bad; ++c)
    bad = !(isdigit((unsigned char)*c) || strchr("+-.eE", *c));
  char *end = NULL;
  double v = bad ? 0.0 : strtod(s, &end);
  if (bad || end == s || *end != '\0')
    return sph_node_error(n, err, SPH_ERR_TYPE, "expected a number, got '%s'",
                          s);
  if (!isfinite(v))
    return sph_node_error(n, err, SPH_ERR_RANGE,
                          "the number '%s' is out of range", s);
  *out = v;
  return SPH_OK;
}

sph_status sph_node_as_int(const sph_node *n, long *out, sph_error *err) {
  SPH_TRY(need_scalar(n, "an integer", err));
  const char *s = n->value;
  int bad = *s == '\0';
  for (const char *c = s; *c && !bad; ++c)
    bad = !(isdigit((unsigned char)*c) || (c == s && strchr("+-", *c)));
  char *end = NULL;
  errno = 0;
  long v = bad ? 0 : strtol(s, &end, 10);
  if (bad || end == s || *end != '\0')
    return sph_node_error(n, err, SPH_ERR_TYPE, "expected an integer, got '%s'",
                          s);
  if (errno == ERANGE)
    return sph_node_error(n, err, SPH_ERR_RANGE,
                          "the integer '%s' is out of range", s);
  *out = v;
  return SPH_OK;
}

sph_status sph_node_as_bool(const sph_node *n, int *out, sph_error *err) {
  SPH_TRY(need_scalar(n, "true or false", err));
  static const char *const yes[] = {"true", "yes", "on"};
  static const char *const no[] = {"false", "no", "off"};
  for (int i = 0; i < 3; ++i) {
    if (!strcasecmp(n->value, yes[i])) {
      *out = 1;
      return SPH_OK;
    }
    if (!strcasecmp(n->value, no[i])) {
      *out = 0;
      return SPH_OK;
    }
  }
  return sph_node_error(n, err, SPH_ERR_TYPE,
                        "expected true or false, got '%s'", n->value);
}

/* ---- getters ---- */

sph_status sph_node_missing(const sph_node *map, const char *key,
                            sph_error *err) {
  char *path = sph_node_join_key(map->path, key);
  sph_status st =
      sph_error_at(err, SPH_ERR_MISSING_KEY, map->file, map->line, map->col,
                   path ? path : key, "missing required key '%s'", key);
  free(path);
  return st;
}

/* Appends n to map under key as a default (path set); NULL on no memory. */
static sph_node *adopt_default(sph_node *map, const char *key, sph_node *n) {
  char *p = sph_node_join_key(map->path, key);
  if (!n || !p || sph_node_set_path(n, p) || sph_node_append(map, key, n)) {
    free(p);
    sph_node_destroy(n);
    return NULL;
  }
  free(p);
  n->is_default = 1;
  n->used = 1;
  return n;
}

static sph_status insert_scalar(sph_node *map, const char *key,
                                const char *text, sph_node **out,
                                sph_error *err) {
  *out = adopt_default(
      map, key, sph_node_scalar_new(text, map->file, map->line, map->col));
  return *out ? SPH_OK
              : sph_error_set(err, SPH_ERR_NOMEM, "default for '%s'", key);
}

/* Shortest %g form that reads back to v ("0.3", not "0.29999999999999999"). */
static void format_double(double v, char *buf, size_t size) {
  for (int prec = 1; prec <= 17; ++prec) {
    snprintf(buf, size, "%.*g", prec, v);
    if (strtod(buf, NULL) == v)
      return;
  }
}

/* Finds key in map (marking it used); NULL with SPH_OK when optional and
 * absent. */
static sph_status lookup(sph_node *map, const char *key, int required,
                         sph_node **child, sph_error *err) {
  *child = NULL;
  if (!map)
    return sph_error_set(err, SPH_ERR_ARG, "no mapping to read '%s' from", key);
  if (map->kind != SPH_NODE_MAP)
    return sph_node_error(map, err, SPH_ERR_TYPE,
                          "expected a mapping with '%s', got %s", key,
                          kind_name(map->kind));
  *child = sph_node_child(map, key);
  if (!*child)
    return required ? sph_node_missing(map, key, err) : SPH_OK;
  (*child)->used = 1;
  return SPH_OK;
}

sph_status sph_node_get_double(sph_node *map, const char *key, int required,
                               double def, double *out, sph_error *err) {
  sph_node *c;
  SPH_TRY(lookup(map, key, required, &c, err));
  if (c)
    return sph_node_as_double(c, out, err);
  *out = def;
  if (!isfinite(def)) /* "none" (NAN): a scene cannot give it, so the */
    return SPH_OK;    /* resolved tree leaves the key out to load back */
  char buf[40];
  format_double(def, buf, sizeof buf);
  return insert_scalar(map, key, buf, &c, err);
}

sph_status sph_node_get_positive(sph_node *map, const char *key, int required,
                                 double def, double *out, sph_error *err) {
  SPH_TRY(sph_node_get_double(map, key, required, def, out, err));
  if (!(*out > 0.0))
    return sph_node_error(sph_node_child(map, key), err, SPH_ERR_RANGE,
                          "must be positive, got %g", *out);
  return SPH_OK;
}

sph_status sph_node_get_int(sph_node *map, const char *key, int required,
                            long def, long *out, sph_error *err) {
  sph_node *c;
  SPH_TRY(lookup(map, key, required, &c, err));
  if (c)
    return sph_node_as_int(c, out, err);
  char buf[32];
  snprintf(buf, sizeof buf, "%ld", def);
  SPH_TRY(insert_scalar(map, key, buf, &c, err));
  *out = def;
  return SPH_OK;
}

sph_status sph_node_get_bool(sph_node *map, const char *key, int required,
                             int def, int *out, sph_error *err) {
  sph_node *c;
  SPH_TRY(lookup(map, key, required, &c, err));
  if (c)
    return sph_node_as_bool(c, out, err);
  SPH_TRY(insert_scalar(map, key, def ? "true" : "false", &c, err));
  *out = def != 0;
  return SPH_OK;
}

sph_status sph_node_get_string(sph_node *map, const char *key, int required,
                               const char *def, const char **out,
                               sph_error *err) {
  sph_node *c;
  *out = NULL;
  SPH_TRY(lookup(map, key, required, &c, err));
  if (c) {
    if (c->kind != SPH_NODE_SCALAR)
      return sph_node_error(c, err, SPH_ERR_TYPE, "expected a string, got %s",
                            kind_name(c->kind));
    *out = c->value;
    return SPH_OK;
  }
  if (def) {
    SPH_TRY(insert_scalar(map, key, def, &c, err));
    *out = c->value;
  }
  return SPH_OK;
}

sph_status sph_node_get_choice(sph_node *map, const char *key,
                               const char *const *values, const char *def,
                               int *out, sph_error *err) {
  const char *v;
  SPH_TRY(sph_node_get_string(map, key, 0, def, &v, err));
  char list[128] = "";
  for (int i = 0; values[i]; ++i) {
    if (!strcmp(values[i], v)) {
      *out = i;
      return SPH_OK;
    }
    strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
    strncat(list, values[i], sizeof list - strlen(list) - 1);
  }
  return sph_node_error(sph_node_child(map, key), err, SPH_ERR_RANGE,
                        "'%s' is not one of: %s", v, list);
}

sph_status sph_node_get_doubles(sph_node *map, const char *key, int required,
                                size_t n, double *out, size_t *got,
                                sph_error *err) {
  sph_node *c;
  size_t cap = got ? *got : n;
  if (got)
    *got = 0;
  sph_status st = lookup(map, key, required, &c, err);
  if (st != SPH_OK || !c)
    return st;
  char want[48] = "a sequence of numbers";
  if (n)
    snprintf(want, sizeof want, "a sequence of %zu numbers", n);
  if (c->kind == SPH_NODE_SCALAR)
    return sph_node_error(c, err, SPH_ERR_TYPE, "expected %s, got '%s'", want,
                          c->value);
  if (c->kind != SPH_NODE_SEQ)
    return sph_node_error(c, err, SPH_ERR_TYPE, "expected %s, got %s", want,
                          kind_name(c->kind));
  if (n && c->count != n)
    return sph_node_error(c, err, SPH_ERR_TYPE, "expected %s, got %zu", want,
                          c->count);
  if (!n && c->count > cap)
    return sph_node_error(c, err, SPH_ERR_RANGE,
                          "expected at most %zu numbers, got %zu", cap,
                          c->count);
  for (size_t i = 0; i < c->count; ++i)
    SPH_TRY(sph_node_as_double(c->items[i], &out[i], err));
  if (got)
    *got = c->count;
  return SPH_OK;
}

sph_status sph_node_get_map(sph_node *map, const char *key, int required,
                            sph_node **out, sph_error *err) {
  sph_node *c;
  *out = NULL;
  sph_status st = lookup(map, key, required, &c, err);
  if (st != SPH_OK || !c)
    return st;
  if (c->kind != SPH_NODE_MAP)
    return sph_node_error(c, err, SPH_ERR_TYPE, "expected a mapping, got %s",
                          kind_name(c->kind));
  *out = c;
  return SPH_OK;
}

sph_status sph_node_insert_default(sph_node *map, const char *key,
                                   const char *yaml, sph_node **out,
                                   sph_error *err) {
  *out = NULL;
  sph_node *c;
  SPH_TRY(lookup(map, key, 0, &c, err));
  if (c) {
    *out = c;
    return SPH_OK;
  }
  sph_node *n = NULL;
  SPH_TRY(sph_node_load_text(yaml, strlen(yaml), map->file, 1, &n, err));
  sph_node_set_origin(n, map->file, map->line, map->col);
  if (!(*out = adopt_default(map, key, n)))
    return sph_error_set(err, SPH_ERR_NOMEM, "default for '%s'", key);
  return SPH_OK;
}
