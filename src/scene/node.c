/* The scene tree: a YAML document from libyaml's document API copied into
 * nodes that keep their file, line, column and dotted path; typed getters
 * that fill defaults and mark keys used; --set overrides; a block-YAML
 * writer; "did you mean" suggestions. */
#include "sph/node.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <yaml.h>

#define MAX_DEPTH 64
#define CMDLINE "<command line>"

/* ---- construction ---------------------------------------------------- */

static sph_node *node_new(sph_node_kind kind, const char *file, int line,
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

/* Appends a child (key ignored for sequences); takes ownership of child. */
static int node_append(sph_node *parent, const char *key, sph_node *child) {
  size_t c = parent->count + 1;
  sph_node **items = realloc(parent->items, c * sizeof *items);
  if (!items)
    return -1;
  parent->items = items;
  if (parent->kind == SPH_NODE_MAP) {
    char **keys = realloc(parent->keys, c * sizeof *keys);
    if (!keys)
      return -1;
    parent->keys = keys;
    keys[c - 1] = strdup(key ? key : "");
    if (!keys[c - 1])
      return -1;
  }
  items[c - 1] = child;
  parent->count = c;
  return 0;
}

/* Sets the path of n and, recursively, of its children. */
static int node_set_path(sph_node *n, const char *path) {
  char *p = strdup(path);
  if (!p)
    return -1;
  free(n->path);
  n->path = p;
  path = p; /* the argument may have been the freed path */
  for (size_t i = 0; i < n->count; ++i) {
    size_t len = strlen(path) + (n->keys ? strlen(n->keys[i]) : 24) + 4;
    char *cp = malloc(len);
    if (!cp)
      return -1;
    if (n->kind == SPH_NODE_MAP)
      snprintf(cp, len, "%s%s%s", path, *path ? "." : "", n->keys[i]);
    else
      snprintf(cp, len, "%s[%zu]", path, i);
    int rc = node_set_path(n->items[i], cp);
    free(cp);
    if (rc)
      return rc;
  }
  return 0;
}

static void node_set_origin(sph_node *n, const char *file, int line, int col) {
  char *f = strdup(file);
  if (f) {
    free(n->file);
    n->file = f;
  }
  n->line = line;
  n->col = col;
  for (size_t i = 0; i < n->count; ++i)
    node_set_origin(n->items[i], file, line, col);
}

/* ---- loading ------------------------------------------------------------ */

typedef struct loader {
  yaml_document_t *doc;
  const char *file;
  sph_error *err;
} loader;

static sph_status convert(loader *L, yaml_node_t *y, int line, int col,
                          int depth, sph_node **out);

/* Converts y and appends it to parent under key (NULL in sequences). */
static sph_status add_child(loader *L, sph_node *parent, const char *key,
                            yaml_node_t *y, int line, int col, int depth) {
  sph_node *child;
  sph_status st = convert(L, y, line, col, depth, &child);
  if (st != SPH_OK)
    return st;
  if (node_append(parent, key, child)) {
    sph_node_destroy(child);
    return sph_error_set(L->err, SPH_ERR_NOMEM, "scene tree");
  }
  return SPH_OK;
}

static sph_status convert(loader *L, yaml_node_t *y, int line, int col,
                          int depth, sph_node **out) {
  *out = NULL;
  if (depth > MAX_DEPTH)
    return sph_error_at(L->err, SPH_ERR_SYNTAX, L->file, line, col, NULL,
                        "document nests deeper than %d levels (recursive "
                        "alias?)",
                        MAX_DEPTH);
  sph_node *n = NULL;
  switch (y->type) {
  case YAML_SCALAR_NODE:
    n = node_new(SPH_NODE_SCALAR, L->file, line, col);
    if (!n || !(n->value = strndup((const char *)y->data.scalar.value,
                                   y->data.scalar.length)))
      break;
    n->quoted = y->data.scalar.style == YAML_SINGLE_QUOTED_SCALAR_STYLE ||
                y->data.scalar.style == YAML_DOUBLE_QUOTED_SCALAR_STYLE ||
                y->data.scalar.style == YAML_LITERAL_SCALAR_STYLE ||
                y->data.scalar.style == YAML_FOLDED_SCALAR_STYLE;
    *out = n;
    return SPH_OK;
  case YAML_SEQUENCE_NODE:
    n = node_new(SPH_NODE_SEQ, L->file, line, col);
    if (!n)
      break;
    for (yaml_node_item_t *it = y->data.sequence.items.start;
         it < y->data.sequence.items.top; ++it) {
      yaml_node_t *c = yaml_document_get_node(L->doc, *it);
      sph_status st = add_child(L, n, NULL, c, (int)c->start_mark.line + 1,
                                (int)c->start_mark.column + 1, depth + 1);
      if (st != SPH_OK) {
        sph_node_destroy(n);
        return st;
      }
    }
    *out = n;
    return SPH_OK;
  case YAML_MAPPING_NODE:
    n = node_new(SPH_NODE_MAP, L->file, line, col);
    if (!n)
      break;
    for (yaml_node_pair_t *pr = y->data.mapping.pairs.start;
         pr < y->data.mapping.pairs.top; ++pr) {
      yaml_node_t *k = yaml_document_get_node(L->doc, pr->key);
      yaml_node_t *v = yaml_document_get_node(L->doc, pr->value);
      int kl = (int)k->start_mark.line + 1, kc = (int)k->start_mark.column + 1;
      if (k->type != YAML_SCALAR_NODE) {
        sph_node_destroy(n);
        return sph_error_at(L->err, SPH_ERR_TYPE, L->file, kl, kc, NULL,
                            "mapping keys must be plain names");
      }
      const char *key = (const char *)k->data.scalar.value;
      for (size_t i = 0; i < n->count; ++i)
        if (strcmp(n->keys[i], key) == 0) {
          int first = n->items[i]->line;
          sph_node_destroy(n);
          return sph_error_at(L->err, SPH_ERR_DUPLICATE_KEY, L->file, kl, kc,
                              key,
                              "duplicate key '%s' (first given on line "
                              "%d)",
                              key, first);
        }
      sph_status st = add_child(L, n, key, v, kl, kc, depth + 1);
      if (st != SPH_OK) {
        sph_node_destroy(n);
        return st;
      }
    }
    *out = n;
    return SPH_OK;
  default:
    return sph_error_at(L->err, SPH_ERR_SYNTAX, L->file, line, col, NULL,
                        "empty node");
  }
  sph_node_destroy(n);
  return sph_error_set(L->err, SPH_ERR_NOMEM, "scene tree");
}

static sph_status load(yaml_parser_t *parser, const char *origin,
                       sph_node **root, sph_error *err) {
  yaml_document_t doc;
  if (!yaml_parser_load(parser, &doc)) {
    sph_status st = sph_error_at(
        err, SPH_ERR_SYNTAX, origin, (int)parser->problem_mark.line + 1,
        (int)parser->problem_mark.column + 1, NULL, "YAML syntax: %s%s%s",
        parser->problem ? parser->problem : "malformed document",
        parser->context ? " " : "", parser->context ? parser->context : "");
    return st;
  }
  yaml_node_t *top = yaml_document_get_root_node(&doc);
  sph_status st;
  if (!top) {
    st = sph_error_at(err, SPH_ERR_SYNTAX, origin, 1, 1, NULL,
                      "the document is empty");
  } else {
    loader L = {&doc, origin, err};
    st = convert(&L, top, (int)top->start_mark.line + 1,
                 (int)top->start_mark.column + 1, 0, root);
    if (st == SPH_OK && node_set_path(*root, "")) {
      sph_node_destroy(*root);
      *root = NULL;
      st = sph_error_set(err, SPH_ERR_NOMEM, "scene tree");
    }
  }
  yaml_document_delete(&doc);
  return st;
}

sph_status sph_node_load_file(sph_node **root, const char *path,
                              sph_error *err) {
  *root = NULL;
  FILE *f = fopen(path, "rb");
  if (!f)
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "cannot open the scene file");
  yaml_parser_t parser;
  yaml_parser_initialize(&parser);
  yaml_parser_set_input_file(&parser, f);
  sph_status st = load(&parser, path, root, err);
  yaml_parser_delete(&parser);
  fclose(f);
  return st;
}

sph_status sph_node_load_string(sph_node **root, const char *text,
                                const char *origin, sph_error *err) {
  *root = NULL;
  yaml_parser_t parser;
  yaml_parser_initialize(&parser);
  yaml_parser_set_input_string(&parser, (const unsigned char *)text,
                               strlen(text));
  sph_status st = load(&parser, origin, root, err);
  yaml_parser_delete(&parser);
  return st;
}

/* ---- lookups and errors -------------------------------------------------- */

sph_node *sph_node_child(const sph_node *map, const char *key) {
  if (!map || map->kind != SPH_NODE_MAP)
    return NULL;
  for (size_t i = 0; i < map->count; ++i)
    if (strcmp(map->keys[i], key) == 0)
      return map->items[i];
  return NULL;
}

sph_status sph_node_error(const sph_node *n, sph_error *err, sph_status code,
                          const char *fmt, ...) {
  char msg[768];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return sph_error_at(err, code, n->file, n->line, n->col, n->path, "%s", msg);
}

static const char *kind_name(sph_node_kind k) {
  return k == SPH_NODE_MAP ? "a mapping"
                           : (k == SPH_NODE_SEQ ? "a sequence" : "a scalar");
}

size_t sph_edit_distance(const char *a, const char *b) {
  size_t la = strlen(a), lb = strlen(b);
  size_t row[lb + 1];
  for (size_t j = 0; j <= lb; ++j)
    row[j] = j;
  for (size_t i = 1; i <= la; ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= lb; ++j) {
      size_t up = row[j];
      size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      size_t best = diag + cost;
      if (up + 1 < best)
        best = up + 1;
      if (row[j - 1] + 1 < best)
        best = row[j - 1] + 1;
      row[j] = best;
      diag = up;
    }
  }
  return row[lb];
}

const char *sph_suggest(const char *word, const char *const *candidates) {
  const char *best = NULL;
  size_t best_d = (size_t)-1, len = strlen(word);
  size_t limit = len / 3 > 2 ? len / 3 : 2;
  for (const char *const *c = candidates; *c; ++c) {
    size_t d = sph_edit_distance(word, *c);
    /* a prefix of a longer key ("poisson" for "poisson_ratio") counts too */
    if (len >= 3 && strncmp(word, *c, len) == 0)
      d = d < 1 ? d : 1;
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

/* ---- scalar conversions ----------------------------------------------------
 */

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
  sph_status st = need_scalar(n, "a number", err);
  if (st != SPH_OK)
    return st;
  const char *s = n->value;
  char *end;
  double v = strtod(s, &end);
  int bad = end == s || *end != '\0' || isspace((unsigned char)*s);
  /* strtod accepts "inf", "nan" and hex floats; YAML numbers are decimal */
  for (const char *c = s; *c && !bad; ++c)
    bad = !(isdigit((unsigned char)*c) || strchr("+-.eE", *c));
  if (bad || !isfinite(v))
    return sph_node_error(n, err, SPH_ERR_TYPE, "expected a number, got '%s'",
                          s);
  *out = v;
  return SPH_OK;
}

sph_status sph_node_as_int(const sph_node *n, long *out, sph_error *err) {
  sph_status st = need_scalar(n, "an integer", err);
  if (st != SPH_OK)
    return st;
  const char *s = n->value;
  char *end;
  long v = strtol(s, &end, 10);
  if (end == s || *end != '\0' || isspace((unsigned char)*s))
    return sph_node_error(n, err, SPH_ERR_TYPE, "expected an integer, got '%s'",
                          s);
  *out = v;
  return SPH_OK;
}

sph_status sph_node_as_bool(const sph_node *n, int *out, sph_error *err) {
  sph_status st = need_scalar(n, "true or false", err);
  if (st != SPH_OK)
    return st;
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

/* ---- getters
 * ----------------------------------------------------------------- */

static sph_status missing(sph_node *map, const char *key, sph_error *err) {
  char path[512];
  snprintf(path, sizeof path, "%s%s%s", map->path, *map->path ? "." : "", key);
  return sph_error_at(err, SPH_ERR_MISSING_KEY, map->file, map->line, map->col,
                      path, "missing required key '%s'", key);
}

/* Inserts a default scalar child and returns it (NULL on no memory). */
static sph_node *insert_default(sph_node *map, const char *key,
                                const char *text) {
  if (map->kind != SPH_NODE_MAP)
    return NULL;
  sph_node *n = node_new(SPH_NODE_SCALAR, map->file, map->line, map->col);
  if (!n || !(n->value = strdup(text)) || node_append(map, key, n)) {
    sph_node_destroy(n);
    return NULL;
  }
  size_t len = strlen(map->path) + strlen(key) + 2;
  char *p = malloc(len);
  if (p) {
    snprintf(p, len, "%s%s%s", map->path, *map->path ? "." : "", key);
    free(n->path);
    n->path = p;
  }
  n->is_default = 1;
  n->used = 1;
  return n;
}

static void format_double(double v, char *buf, size_t size) {
  for (int prec = 1; prec <= 17; ++prec) {
    snprintf(buf, size, "%.*g", prec, v);
    if (strtod(buf, NULL) == v)
      return;
  }
}

/* Finds key; NULL child with SPH_OK means absent and optional. */
static sph_status lookup(sph_node *map, const char *key, int required,
                         sph_node **child, sph_error *err) {
  *child = NULL;
  if (!map || map->kind != SPH_NODE_MAP)
    return map ? sph_node_error(map, err, SPH_ERR_TYPE,
                                "expected a mapping, got %s",
                                kind_name(map->kind))
               : sph_error_set(err, SPH_ERR_ARG, "no mapping for '%s'", key);
  *child = sph_node_child(map, key);
  if (!*child && required)
    return missing(map, key, err);
  if (*child)
    (*child)->used = 1;
  return SPH_OK;
}

sph_status sph_node_get_double(sph_node *map, const char *key, int required,
                               double def, double *out, sph_error *err) {
  sph_node *c;
  sph_status st = lookup(map, key, required, &c, err);
  if (st != SPH_OK)
    return st;
  if (!c) {
    char buf[40];
    format_double(def, buf, sizeof buf);
    if (!insert_default(map, key, buf))
      return sph_error_set(err, SPH_ERR_NOMEM, "default for %s", key);
    *out = def;
    return SPH_OK;
  }
  return sph_node_as_double(c, out, err);
}

sph_status sph_node_get_int(sph_node *map, const char *key, int required,
                            long def, long *out, sph_error *err) {
  sph_node *c;
  sph_status st = lookup(map, key, required, &c, err);
  if (st != SPH_OK)
    return st;
  if (!c) {
    char buf[32];
    snprintf(buf, sizeof buf, "%ld", def);
    if (!insert_default(map, key, buf))
      return sph_error_set(err, SPH_ERR_NOMEM, "default for %s", key);
    *out = def;
    return SPH_OK;
  }
  return sph_node_as_int(c, out, err);
}

sph_status sph_node_get_bool(sph_node *map, const char *key, int required,
                             int def, int *out, sph_error *err) {
  sph_node *c;
  sph_status st = lookup(map, key, required, &c, err);
  if (st != SPH_OK)
    return st;
  if (!c) {
    if (!insert_default(map, key, def ? "true" : "false"))
      return sph_error_set(err, SPH_ERR_NOMEM, "default for %s", key);
    *out = def;
    return SPH_OK;
  }
  return sph_node_as_bool(c, out, err);
}

sph_status sph_node_get_string(sph_node *map, const char *key, int required,
                               const char *def, const char **out,
                               sph_error *err) {
  sph_node *c;
  sph_status st = lookup(map, key, required, &c, err);
  if (st != SPH_OK)
    return st;
  if (!c) {
    *out = def;
    if (def) {
      sph_node *d = insert_default(map, key, def);
      if (!d)
        return sph_error_set(err, SPH_ERR_NOMEM, "default for %s", key);
      *out = d->value;
    }
    return SPH_OK;
  }
  if (c->kind != SPH_NODE_SCALAR)
    return sph_node_error(c, err, SPH_ERR_TYPE, "expected a name, got %s",
                          kind_name(c->kind));
  *out = c->value;
  return SPH_OK;
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
  if (c->kind != SPH_NODE_SEQ) {
    if (n)
      return sph_node_error(
          c, err, SPH_ERR_TYPE, "expected a sequence of %zu numbers, got %s", n,
          c->kind == SPH_NODE_SCALAR ? c->value : kind_name(c->kind));
    return sph_node_error(
        c, err, SPH_ERR_TYPE, "expected a sequence of numbers, got %s",
        c->kind == SPH_NODE_SCALAR ? c->value : kind_name(c->kind));
  }
  if (n && c->count != n)
    return sph_node_error(c, err, SPH_ERR_TYPE,
                          "expected a sequence of %zu numbers, got %zu", n,
                          c->count);
  if (!n && c->count > cap)
    return sph_node_error(c, err, SPH_ERR_RANGE,
                          "at most %zu numbers allowed, got %zu", cap,
                          c->count);
  for (size_t i = 0; i < c->count; ++i)
    if ((st = sph_node_as_double(c->items[i], &out[i], err)) != SPH_OK)
      return st;
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
                          c->kind == SPH_NODE_SCALAR ? "a scalar"
                                                     : "a sequence");
  *out = c;
  return SPH_OK;
}

sph_status sph_node_insert_default(sph_node *map, const char *key,
                                   const char *yaml, sph_node **out,
                                   sph_error *err) {
  *out = sph_node_child(map, key);
  if (*out) {
    (*out)->used = 1;
    return SPH_OK;
  }
  if (map->kind != SPH_NODE_MAP)
    return sph_node_error(map, err, SPH_ERR_TYPE, "expected a mapping, got %s",
                          kind_name(map->kind));
  sph_node *n = NULL;
  sph_status st = sph_node_load_string(&n, yaml, map->file, err);
  if (st != SPH_OK)
    return st;
  node_set_origin(n, map->file, map->line, map->col);
  n->is_default = 1;
  n->used = 1;
  size_t len = strlen(map->path) + strlen(key) + 2;
  char *p = malloc(len);
  if (!p || node_append(map, key, n)) {
    free(p);
    sph_node_destroy(n);
    return sph_error_set(err, SPH_ERR_NOMEM, "default for %s", key);
  }
  snprintf(p, len, "%s%s%s", map->path, *map->path ? "." : "", key);
  int rc = node_set_path(n, p);
  free(p);
  if (rc)
    return sph_error_set(err, SPH_ERR_NOMEM, "default for %s", key);
  *out = n;
  return SPH_OK;
}

/* ---- overrides
 * --------------------------------------------------------------- */

static int is_index(const char *s) {
  if (!*s)
    return 0;
  for (; *s; ++s)
    if (!isdigit((unsigned char)*s))
      return 0;
  return 1;
}

sph_status sph_node_set(sph_node *root, const char *assignment,
                        sph_error *err) {
  const char *eq = strchr(assignment, '=');
  if (!eq || eq == assignment)
    return sph_error_at(err, SPH_ERR_ARG, CMDLINE, 0, 0, NULL,
                        "--set expects key.path=value, got '%s'", assignment);
  size_t klen = (size_t)(eq - assignment);
  char key[512];
  if (klen >= sizeof key)
    return sph_error_set(err, SPH_ERR_ARG, "--set key is too long");
  memcpy(key, assignment, klen);
  key[klen] = '\0';
  const char *text = eq + 1;
  int col = (int)klen + 2;

  /* the value, parsed as YAML */
  sph_node *value = NULL;
  sph_error verr;
  if (*text == '\0') {
    value = node_new(SPH_NODE_SCALAR, CMDLINE, 1, col);
    if (!value || !(value->value = strdup(""))) {
      sph_node_destroy(value);
      return sph_error_set(err, SPH_ERR_NOMEM, "--set value");
    }
  } else if (sph_node_load_string(&value, text, CMDLINE, &verr) != SPH_OK) {
    return sph_error_at(err, SPH_ERR_SYNTAX, CMDLINE, 1, col, key,
                        "cannot read the value '%s': %s", text, verr.message);
  }
  node_set_origin(value, CMDLINE, 1, col);

  /* walk to the parent, creating maps */
  sph_node *cur = root;
  char *save = NULL, *part = strtok_r(key, ".", &save);
  char walked[512] = "";
  sph_status st = SPH_OK;
  while (part) {
    char *next = strtok_r(NULL, ".", &save);
    char here[512];
    snprintf(here, sizeof here, "%s%s%s", walked, *walked ? "." : "", part);
    if (cur->kind == SPH_NODE_SCALAR) {
      st = sph_error_at(err, SPH_ERR_TYPE, CMDLINE, 1, 1, here,
                        "cannot set '%s': '%s' is a scalar", assignment,
                        *walked ? walked : "(root)");
      break;
    }
    sph_node **slot = NULL;
    if (cur->kind == SPH_NODE_SEQ) {
      if (!is_index(part)) {
        st = sph_error_at(err, SPH_ERR_TYPE, CMDLINE, 1, 1, here,
                          "'%s' is a sequence: use an index, e.g. %s.0", walked,
                          walked);
        break;
      }
      size_t i = strtoul(part, NULL, 10);
      if (i >= cur->count) {
        st = sph_error_at(err, SPH_ERR_RANGE, CMDLINE, 1, 1, here,
                          "index %zu is past the end of '%s' (%zu entries)", i,
                          walked, cur->count);
        break;
      }
      slot = &cur->items[i];
    } else {
      for (size_t i = 0; i < cur->count; ++i)
        if (!strcmp(cur->keys[i], part))
          slot = &cur->items[i];
    }
    if (!next) {
      if (slot) {
        sph_node_destroy(*slot);
        *slot = value;
      } else if (node_append(cur, part, value)) {
        st = sph_error_set(err, SPH_ERR_NOMEM, "--set");
        break;
      }
      value = NULL;
      break;
    }
    if (!slot) {
      sph_node *m = node_new(SPH_NODE_MAP, CMDLINE, 1, 1);
      if (!m || node_append(cur, part, m)) {
        sph_node_destroy(m);
        st = sph_error_set(err, SPH_ERR_NOMEM, "--set");
        break;
      }
      slot = &cur->items[cur->count - 1];
    }
    cur = *slot;
    snprintf(walked, sizeof walked, "%s", here);
    part = next;
  }
  sph_node_destroy(value);
  if (st == SPH_OK && node_set_path(root, root->path))
    st = sph_error_set(err, SPH_ERR_NOMEM, "--set");
  return st;
}

/* ---- writing
 * ----------------------------------------------------------------- */

static int needs_quotes(const sph_node *n) {
  const char *s = n->value;
  if (n->quoted || !*s)
    return 1;
  if (strchr("-?:,[]{}#&*!|>'\"%@` ", s[0]))
    return !(s[0] == '-' && (isdigit((unsigned char)s[1]) || s[1] == '.'));
  if (s[strlen(s) - 1] == ' ' || strstr(s, ": ") || strstr(s, " #") ||
      strchr(s, '\n') || strchr(s, '\t'))
    return 1;
  return 0;
}

static void write_scalar(const sph_node *n, FILE *out) {
  if (!needs_quotes(n)) {
    fputs(n->value, out);
    return;
  }
  fputc('"', out);
  for (const char *c = n->value; *c; ++c) {
    if (*c == '"' || *c == '\\')
      fputc('\\', out);
    if (*c == '\n')
      fputs("\\n", out);
    else if (*c == '\t')
      fputs("\\t", out);
    else
      fputc(*c, out);
  }
  fputc('"', out);
}

static int all_scalars(const sph_node *n) {
  for (size_t i = 0; i < n->count; ++i)
    if (n->items[i]->kind != SPH_NODE_SCALAR)
      return 0;
  return 1;
}

static void write_node(const sph_node *n, int indent, FILE *out);

/* Writes the value part after "key:" or "- ". */
static void write_value(const sph_node *v, int indent, FILE *out) {
  if (v->kind == SPH_NODE_SCALAR) {
    fputc(' ', out);
    write_scalar(v, out);
    fputc('\n', out);
  } else if (v->count == 0) {
    fputs(v->kind == SPH_NODE_MAP ? " {}\n" : " []\n", out);
  } else if (v->kind == SPH_NODE_SEQ && all_scalars(v)) {
    fputs(" [", out);
    for (size_t i = 0; i < v->count; ++i) {
      if (i)
        fputs(", ", out);
      write_scalar(v->items[i], out);
    }
    fputs("]\n", out);
  } else {
    fputc('\n', out);
    write_node(v, indent + 2, out);
  }
}

static void write_node(const sph_node *n, int indent, FILE *out) {
  if (n->kind == SPH_NODE_MAP) {
    for (size_t i = 0; i < n->count; ++i) {
      fprintf(out, "%*s%s:", indent, "", n->keys[i]);
      write_value(n->items[i], indent, out);
    }
  } else if (n->kind == SPH_NODE_SEQ) {
    for (size_t i = 0; i < n->count; ++i) {
      const sph_node *it = n->items[i];
      if (it->kind == SPH_NODE_MAP && it->count > 0) {
        /* "- first: v" then the other keys aligned under it */
        fprintf(out, "%*s- %s:", indent, "", it->keys[0]);
        write_value(it->items[0], indent + 2, out);
        for (size_t k = 1; k < it->count; ++k) {
          fprintf(out, "%*s%s:", indent + 2, "", it->keys[k]);
          write_value(it->items[k], indent + 2, out);
        }
      } else {
        fprintf(out, "%*s-", indent, "");
        write_value(it, indent, out);
      }
    }
  } else {
    fprintf(out, "%*s", indent, "");
    write_scalar(n, out);
    fputc('\n', out);
  }
}

sph_status sph_node_write(const sph_node *root, FILE *out, sph_error *err) {
  write_node(root, 0, out);
  if (ferror(out))
    return sph_error_set(err, SPH_ERR_IO, "cannot write the scene tree");
  return SPH_OK;
}
