/* The scene tree in and out of YAML (no paper: input handling, docs/design.md
 * sec. 6): a document read with libyaml's document API and copied into
 * nodes (duplicate keys rejected, aliases bounded, flow nesting limited
 * before the parser); --set overrides "a.b=value"; a block YAML writer on
 * libyaml's emitter. */
#include <ctype.h>
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <yaml.h>

#include "scene/node.h"
#include "scene/node_impl.h"

#define SPH_SCENE_MAX_BYTES (1 << 20)
#define MAX_DEPTH 64
#define MAX_NODES 1000000
/* bytes the copies made through aliases may take (scalars, paths and a
 * node's own size): a billion-laughs scene of 100 kB took 1.1 GB (issue 36) */
#define MAX_ALIAS_BYTES (16 << 20)
#define NODE_BYTES 96
#define CMDLINE "<command line>"

/* ---- loading ---- */

typedef struct loader {
  yaml_document_t *doc;
  const char *file;
  size_t nodes;
  yaml_node_t *open[MAX_DEPTH + 1]; /* the nodes being converted */
  unsigned char *seen;       /* per document node: converted once already */
  size_t alias_bytes;        /* what the copies through aliases took */
  int alias_line, alias_col; /* the outermost alias being copied (0: none) */
  sph_error *err;
} loader;

static sph_status convert(loader *L, yaml_node_t *y, const char *path, int line,
                          int col, int depth, sph_node **out);

/* Converts y at `path` and appends it to parent under key (NULL in seqs). */
static sph_status add_child(loader *L, sph_node *parent, const char *key,
                            yaml_node_t *y, int line, int col, int depth) {
  char *path = key ? sph_node_join_key(parent->path, key)
                   : sph_node_join_index(parent->path, parent->count);
  if (!path)
    return sph_error_set(L->err, SPH_ERR_NOMEM, "no memory for the scene tree");
  sph_node *child;
  sph_status st = convert(L, y, path, line, col, depth, &child);
  free(path);
  if (st != SPH_OK)
    return st;
  if (sph_node_append(parent, key, child)) {
    sph_node_destroy(child);
    return sph_error_set(L->err, SPH_ERR_NOMEM, "no memory for the scene tree");
  }
  return SPH_OK;
}

/* FNV-1a: the slot of a key in a mapping's set of keys. */
static uint64_t key_hash(const char *key) {
  uint64_t h = 14695981039346656037u;
  for (const unsigned char *c = (const unsigned char *)key; *c; ++c)
    h = (h ^ *c) * 1099511628211u;
  return h;
}

/* The earlier index of key among n->keys, or -1 after adding it (index
 * n->count) to the open-addressed set (cap a power of two, over twice the
 * pairs): one look-up per key, so a mapping of n keys is checked in O(n). */
static long key_seen(const sph_node *n, size_t *set, size_t cap,
                     const char *key) {
  for (size_t s = key_hash(key) & (cap - 1);; s = (s + 1) & (cap - 1)) {
    if (!set[s]) {
      set[s] = n->count + 1;
      return -1;
    }
    if (strcmp(n->keys[set[s] - 1], key) == 0)
      return (long)(set[s] - 1);
  }
}

static sph_status convert_map(loader *L, yaml_node_t *y, sph_node *n,
                              int depth) {
  size_t pairs =
             (size_t)(y->data.mapping.pairs.top - y->data.mapping.pairs.start),
         cap = 8;
  while (cap < 2 * pairs + 2)
    cap *= 2;
  size_t *set = calloc(cap, sizeof *set); /* index + 1 of a key, 0 free */
  if (!set)
    return sph_error_set(L->err, SPH_ERR_NOMEM, "scene tree");
  sph_status st = SPH_OK;
  for (yaml_node_pair_t *pr = y->data.mapping.pairs.start;
       pr < y->data.mapping.pairs.top && st == SPH_OK; ++pr) {
    yaml_node_t *k = yaml_document_get_node(L->doc, pr->key);
    yaml_node_t *v = yaml_document_get_node(L->doc, pr->value);
    int kl = (int)k->start_mark.line + 1, kc = (int)k->start_mark.column + 1;
    if (k->type != YAML_SCALAR_NODE) {
      st =
          sph_error_at(L->err, SPH_ERR_SYNTAX, L->file, kl, kc, n->path,
                       "mapping keys must be plain names, not %s",
                       k->type == YAML_MAPPING_NODE ? "mappings" : "sequences");
      break;
    }
    const char *key = (const char *)k->data.scalar.value;
    long first = key_seen(n, set, cap, key);
    if (first >= 0) {
      char *path = sph_node_join_key(n->path, key);
      st = sph_error_at(L->err, SPH_ERR_DUPLICATE_KEY, L->file, kl, kc,
                        path ? path : key,
                        "duplicate key '%s' (first given on line %d)", key,
                        n->items[first]->line);
      free(path);
      break;
    }
    st = add_child(L, n, key, v, kl, kc, depth + 1);
  }
  free(set);
  return st;
}

static sph_status convert(loader *L, yaml_node_t *y, const char *path, int line,
                          int col, int depth, sph_node **out) {
  *out = NULL;
  /* aliases share nodes: refuse cycles and bound the copy */
  for (int d = 0; d < depth; ++d)
    if (L->open[d] == y)
      return sph_error_at(L->err, SPH_ERR_SYNTAX, L->file, line, col, path,
                          "recursive alias: the node from line %d, column %d "
                          "contains itself",
                          (int)y->start_mark.line + 1,
                          (int)y->start_mark.column + 1);
  if (depth > MAX_DEPTH)
    return sph_error_at(L->err, SPH_ERR_SYNTAX, L->file, line, col, path,
                        "nesting deeper than %d levels", MAX_DEPTH);
  L->open[depth] = y;
  if (++L->nodes > MAX_NODES)
    return sph_error_at(L->err, SPH_ERR_RANGE, L->file, line, col, path,
                        "more than %d nodes (aliases expanding?)", MAX_NODES);
  /* a node met again is a copy through an alias: bound the bytes copied */
  size_t id = (size_t)(y - L->doc->nodes.start);
  int outer = 0;
  if (L->seen[id] && !L->alias_line) {
    outer = 1;
    L->alias_line = line;
    L->alias_col = col;
  }
  if (L->alias_line) {
    L->alias_bytes += NODE_BYTES + strlen(path) +
                      (y->type == YAML_SCALAR_NODE ? y->data.scalar.length : 0);
    if (L->alias_bytes > MAX_ALIAS_BYTES)
      return sph_error_at(L->err, SPH_ERR_RANGE, L->file, L->alias_line,
                          L->alias_col, NULL,
                          "aliases expand the scene past %d MB (the alias "
                          "here and those it contains): copy less",
                          MAX_ALIAS_BYTES >> 20);
  }
  L->seen[id] = 1;
  sph_node_kind kind = y->type == YAML_MAPPING_NODE    ? SPH_NODE_MAP
                       : y->type == YAML_SEQUENCE_NODE ? SPH_NODE_SEQ
                                                       : SPH_NODE_SCALAR;
  sph_node *n = sph_node_new(kind, L->file, line, col);
  char *p = strdup(path);
  if (!n || !p) {
    free(p);
    sph_node_destroy(n);
    return sph_error_set(L->err, SPH_ERR_NOMEM, "no memory for the scene tree");
  }
  free(n->path);
  n->path = p;
  sph_status st = SPH_OK;
  if (y->type == YAML_SCALAR_NODE) {
    size_t len = y->data.scalar.length;
    if (!(n->value = malloc(len + 1))) {
      sph_node_destroy(n);
      return sph_error_set(L->err, SPH_ERR_NOMEM,
                           "no memory for the scene tree");
    }
    memcpy(n->value, y->data.scalar.value, len);
    n->value[len] = '\0';
    yaml_scalar_style_t s = y->data.scalar.style;
    n->quoted = s == YAML_SINGLE_QUOTED_SCALAR_STYLE ||
                s == YAML_DOUBLE_QUOTED_SCALAR_STYLE ||
                s == YAML_LITERAL_SCALAR_STYLE || s == YAML_FOLDED_SCALAR_STYLE;
  } else if (y->type == YAML_SEQUENCE_NODE) {
    for (yaml_node_item_t *it = y->data.sequence.items.start;
         it < y->data.sequence.items.top && st == SPH_OK; ++it) {
      yaml_node_t *c = yaml_document_get_node(L->doc, *it);
      st = add_child(L, n, NULL, c, (int)c->start_mark.line + 1,
                     (int)c->start_mark.column + 1, depth + 1);
    }
  } else if (y->type == YAML_MAPPING_NODE) {
    st = convert_map(L, y, n, depth);
  } else {
    st = sph_error_at(L->err, SPH_ERR_SYNTAX, L->file, line, col, path,
                      "empty node");
  }
  if (outer)
    L->alias_line = L->alias_col = 0;
  if (st != SPH_OK) {
    sph_node_destroy(n);
    return st;
  }
  *out = n;
  return SPH_OK;
}

/* libyaml's problem as an error at its position. */
static sph_status parse_error(const yaml_parser_t *p, const char *text,
                              size_t len, const char *origin, sph_error *err) {
  if (p->error == YAML_MEMORY_ERROR)
    return sph_error_set(err, SPH_ERR_NOMEM, "no memory for the YAML parser");
  const char *problem = p->problem ? p->problem : "malformed document";
  if (p->error == YAML_READER_ERROR) {
    /* reader errors carry a byte offset: count lines and characters */
    int line = 1, col = 1;
    for (size_t i = 0; i < p->problem_offset && i < len; ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else if (((unsigned char)text[i] & 0xC0) != 0x80) {
        ++col;
      }
    }
    return sph_error_at(err, SPH_ERR_SYNTAX, origin, line, col, NULL,
                        "YAML syntax: %s", problem);
  }
  int line = (int)p->problem_mark.line + 1;
  int col = (int)p->problem_mark.column + 1;
  if (p->context)
    return sph_error_at(err, SPH_ERR_SYNTAX, origin, line, col, NULL,
                        "YAML syntax: %s (%s at line %d, column %d)", problem,
                        p->context, (int)p->context_mark.line + 1,
                        (int)p->context_mark.column + 1);
  return sph_error_at(err, SPH_ERR_SYNTAX, origin, line, col, NULL,
                      "YAML syntax: %s", problem);
}

/* Flow collections ([ ], { }) nested deeper than MAX_DEPTH, found before
 * the YAML parser, whose time grows with the square of such nesting (80 kB
 * of brackets took 1.9 s): SPH_OK or the error at the first one too deep. */
static sph_status flow_depth(const char *text, size_t len, const char *origin,
                             sph_error *err) {
  int depth = 0, line = 1, col = 0;
  char quote = 0;
  for (size_t i = 0; i < len; ++i) {
    char c = text[i];
    ++col;
    if (c == '\n') {
      line++, col = 0;
      continue;
    }
    if (quote) {
      quote = c == quote ? 0 : quote;
      continue;
    }
    if (c == '"' || c == '\'')
      quote = c;
    else if (c == '#' && (i == 0 || text[i - 1] == ' ' || col == 1))
      while (i + 1 < len && text[i + 1] != '\n')
        ++i;
    else if (c == '[' || c == '{') {
      if (++depth > MAX_DEPTH)
        return sph_error_at(err, SPH_ERR_RANGE, origin, line, col, NULL,
                            "nesting deeper than %d levels", MAX_DEPTH);
    } else if ((c == ']' || c == '}') && depth > 0)
      depth--;
  }
  return SPH_OK;
}

/* (node_impl.h) */
sph_status sph_node_load_text(const char *text, size_t len, const char *origin,
                              int allow_empty, sph_node **root,
                              sph_error *err) {
  *root = NULL;
  SPH_TRY(flow_depth(text, len, origin, err));
  yaml_parser_t parser;
  if (!yaml_parser_initialize(&parser))
    return sph_error_set(err, SPH_ERR_NOMEM, "no memory for the YAML parser");
  yaml_parser_set_input_string(&parser, (const unsigned char *)text, len);
  yaml_document_t doc;
  if (!yaml_parser_load(&parser, &doc)) {
    sph_status st = parse_error(&parser, text, len, origin, err);
    yaml_parser_delete(&parser);
    return st;
  }
  yaml_node_t *top = yaml_document_get_root_node(&doc);
  int empty = !top || (top->type == YAML_SCALAR_NODE &&
                       top->data.scalar.style == YAML_PLAIN_SCALAR_STYLE &&
                       top->data.scalar.length == 0);
  sph_status st = SPH_OK;
  if (empty && allow_empty) {
    if (!(*root = sph_node_scalar_new("", origin, 1, 1)))
      st = sph_error_set(err, SPH_ERR_NOMEM, "no memory for the scene tree");
  } else if (empty) {
    st = sph_error_at(err, SPH_ERR_SYNTAX, origin, 1, 1, NULL,
                      "the document is empty");
  } else {
    loader L = {.doc = &doc, .file = origin, .err = err};
    L.seen = calloc((size_t)(doc.nodes.top - doc.nodes.start) + 1, 1);
    st = L.seen ? convert(&L, top, "", (int)top->start_mark.line + 1,
                          (int)top->start_mark.column + 1, 0, root)
                : sph_error_set(err, SPH_ERR_NOMEM,
                                "no memory for the scene "
                                "tree");
    free(L.seen);
  }
  yaml_document_delete(&doc);

  /* a second document would be ignored silently: refuse it */
  if (st == SPH_OK) {
    if (!yaml_parser_load(&parser, &doc)) {
      st = parse_error(&parser, text, len, origin, err);
    } else {
      yaml_node_t *next = yaml_document_get_root_node(&doc);
      if (next)
        st = sph_error_at(err, SPH_ERR_SYNTAX, origin,
                          (int)next->start_mark.line + 1,
                          (int)next->start_mark.column + 1, NULL,
                          "YAML syntax: only one document is allowed");
      yaml_document_delete(&doc);
    }
    if (st != SPH_OK) {
      sph_node_destroy(*root);
      *root = NULL;
    }
  }
  yaml_parser_delete(&parser);
  return st;
}

sph_status sph_node_load_file(sph_node **root, const char *path,
                              sph_error *err) {
  *root = NULL;
  struct stat sb; /* a FIFO would hang the read (issue 36) */
  if (stat(path, &sb) == 0 && !S_ISREG(sb.st_mode))
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "not a regular file (a folder, FIFO or device); a "
                        "scene is a file");
  FILE *f = fopen(path, "rb");
  if (!f)
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "cannot open the scene file: %s", strerror(errno));
  /* read it whole: reader errors are reported by offset into the text; a
   * scene is a few kB, so anything beyond SPH_SCENE_MAX_BYTES (a device, a
   * mistaken file) is refused before it fills the memory */
  size_t len = 0, cap = 4096;
  char *text = malloc(cap);
  while (text) {
    len += fread(text + len, 1, cap - len, f);
    if (len > SPH_SCENE_MAX_BYTES) {
      free(text);
      fclose(f);
      return sph_error_at(err, SPH_ERR_RANGE, path, 0, 0, NULL,
                          "not a scene: more than 1 MiB (%d bytes)",
                          SPH_SCENE_MAX_BYTES);
    }
    if (len < cap)
      break;
    /* the last read asks for one byte past the limit: a file of exactly
     * SPH_SCENE_MAX_BYTES is read whole, one byte more is refused */
    cap = cap * 2 > SPH_SCENE_MAX_BYTES ? SPH_SCENE_MAX_BYTES + 1 : cap * 2;
    char *t = realloc(text, cap);
    if (!t)
      free(text);
    text = t;
  }
  int bad = !text || ferror(f);
  fclose(f);
  if (bad) {
    free(text);
    return text ? sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                               "cannot read the scene file")
                : sph_error_set(err, SPH_ERR_NOMEM, "reading %s", path);
  }
  sph_status st = sph_node_load_text(text, len, path, 0, root, err);
  free(text);
  return st;
}

sph_status sph_node_load_string(sph_node **root, const char *text,
                                const char *origin, sph_error *err) {
  return sph_node_load_text(text, strlen(text), origin, 0, root, err);
}

/* ---- overrides ---- */

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
  const char *eq = root && assignment ? strchr(assignment, '=') : NULL;
  if (!eq || eq == assignment)
    return sph_error_at(err, SPH_ERR_ARG, CMDLINE, 0, 0, NULL,
                        "--set expects key.path=value, got '%s'",
                        assignment ? assignment : "(null)");
  char key[512];
  size_t klen = (size_t)(eq - assignment);
  if (klen >= sizeof key)
    return sph_error_at(err, SPH_ERR_ARG, CMDLINE, 0, 0, NULL,
                        "--set key is longer than %zu characters",
                        sizeof key - 1);
  memcpy(key, assignment, klen);
  key[klen] = '\0';
  if (key[0] == '.' || key[klen - 1] == '.' || strstr(key, ".."))
    return sph_error_at(err, SPH_ERR_ARG, CMDLINE, 1, 1, NULL,
                        "--set key '%s' has an empty part", key);

  /* the value, parsed as YAML; it sits at column klen + 2 */
  const char *text = eq + 1;
  int col = (int)klen + 2;
  sph_node *value = NULL;
  sph_error verr;
  sph_error_clear(&verr);
  sph_status st =
      sph_node_load_text(text, strlen(text), CMDLINE, 1, &value, &verr);
  if (st != SPH_OK)
    return sph_error_at(
        err, st, CMDLINE, 1,
        verr.line == 1 && verr.col > 0 ? col + verr.col - 1 : col, NULL,
        "cannot read the value of %s: %s", key, verr.message);
  sph_node_set_origin(value, CMDLINE, 1, col);

  /* walk to the parent, creating maps */
  sph_node *cur = root;
  /* key (< 512) with each index part "i." as "[i]": under 768 */
  char here[1024];
  snprintf(here, sizeof here, "%s", root->path);
  for (char *part = key; part && st == SPH_OK;) {
    char *next = strchr(part, '.');
    if (next)
      *next++ = '\0';
    char walked[1024];
    snprintf(walked, sizeof walked, "%s", *here ? here : "(root)");
    sph_node **slot = NULL;
    if (cur->kind == SPH_NODE_SCALAR) {
      st =
          sph_error_at(err, SPH_ERR_TYPE, CMDLINE, 1, 1, here,
                       "cannot set '%s': '%s' is a scalar", assignment, walked);
      break;
    }
    if (cur->kind == SPH_NODE_SEQ) {
      size_t len = strlen(here);
      snprintf(here + len, sizeof here - len, "[%s]", part);
      if (!is_index(part)) {
        st = sph_error_at(err, SPH_ERR_TYPE, CMDLINE, 1, 1, walked,
                          "'%s' is a sequence: index it by number, e.g. "
                          "%s.0",
                          walked, walked);
        break;
      }
      errno = 0;
      unsigned long i = strtoul(part, NULL, 10);
      if (errno == ERANGE || i >= cur->count) {
        st = sph_error_at(err, SPH_ERR_RANGE, CMDLINE, 1, 1, here,
                          "index %s is past the end of '%s' (%zu entries)",
                          part, walked, cur->count);
        break;
      }
      slot = &cur->items[i];
    } else {
      size_t len = strlen(here);
      snprintf(here + len, sizeof here - len, "%s%s", len ? "." : "", part);
      for (size_t i = 0; i < cur->count && !slot; ++i)
        if (!strcmp(cur->keys[i], part))
          slot = &cur->items[i];
    }
    if (!next) {
      /* last part: replace or add */
      if (slot) {
        sph_node_destroy(*slot);
        *slot = value;
      } else if (sph_node_append(cur, part, value)) {
        st = sph_error_set(err, SPH_ERR_NOMEM, "--set");
        break;
      }
      value = NULL;
      if (sph_node_set_path(slot ? *slot : cur->items[cur->count - 1], here))
        st = sph_error_set(err, SPH_ERR_NOMEM, "--set");
      break;
    }
    if (!slot) {
      sph_node *m = sph_node_new(SPH_NODE_MAP, CMDLINE, 1, 1);
      if (!m || sph_node_set_path(m, here) || sph_node_append(cur, part, m)) {
        sph_node_destroy(m);
        st = sph_error_set(err, SPH_ERR_NOMEM, "--set");
        break;
      }
      slot = &cur->items[cur->count - 1];
    }
    cur = *slot;
    part = next;
  }
  sph_node_destroy(value);
  return st;
}

/* ---- writing (libyaml's emitter picks a safe quoting for each scalar) ---- */

static int emit_scalar(yaml_emitter_t *e, const char *text, int quoted) {
  yaml_event_t ev;
  if (!yaml_scalar_event_initialize(
          &ev, NULL, NULL, (yaml_char_t *)text, (int)strlen(text), 1, 1,
          quoted ? YAML_DOUBLE_QUOTED_SCALAR_STYLE : YAML_ANY_SCALAR_STYLE))
    return 0;
  return yaml_emitter_emit(e, &ev);
}

static int all_scalars(const sph_node *n) {
  for (size_t i = 0; i < n->count; ++i)
    if (n->items[i]->kind != SPH_NODE_SCALAR)
      return 0;
  return 1;
}

static int emit_node(yaml_emitter_t *e, const sph_node *n) {
  yaml_event_t ev;
  if (n->kind == SPH_NODE_SCALAR)
    return emit_scalar(e, n->value, n->quoted);
  /* empty collections and lists of scalars in flow style: "[1, 2, 3]" */
  int flow = n->count == 0 || (n->kind == SPH_NODE_SEQ && all_scalars(n));
  int ok;
  if (n->kind == SPH_NODE_MAP)
    ok = yaml_mapping_start_event_initialize(&ev, NULL, NULL, 1,
                                             flow ? YAML_FLOW_MAPPING_STYLE
                                                  : YAML_BLOCK_MAPPING_STYLE);
  else
    ok = yaml_sequence_start_event_initialize(&ev, NULL, NULL, 1,
                                              flow ? YAML_FLOW_SEQUENCE_STYLE
                                                   : YAML_BLOCK_SEQUENCE_STYLE);
  if (!ok || !yaml_emitter_emit(e, &ev))
    return 0;
  for (size_t i = 0; i < n->count; ++i) {
    if (n->kind == SPH_NODE_MAP && !emit_scalar(e, n->keys[i], 0))
      return 0;
    if (!emit_node(e, n->items[i]))
      return 0;
  }
  if (n->kind == SPH_NODE_MAP)
    ok = yaml_mapping_end_event_initialize(&ev);
  else
    ok = yaml_sequence_end_event_initialize(&ev);
  return ok && yaml_emitter_emit(e, &ev);
}

sph_status sph_node_write(const sph_node *root, FILE *out, sph_error *err) {
  yaml_emitter_t e;
  if (!yaml_emitter_initialize(&e))
    return sph_error_set(err, SPH_ERR_NOMEM, "YAML emitter");
  yaml_emitter_set_output_file(&e, out);
  yaml_emitter_set_unicode(&e, 1);
  yaml_emitter_set_indent(&e, 2);
  yaml_emitter_set_width(&e, -1);
  yaml_event_t ev;
  int ok = yaml_stream_start_event_initialize(&ev, YAML_UTF8_ENCODING) &&
           yaml_emitter_emit(&e, &ev) &&
           yaml_document_start_event_initialize(&ev, NULL, NULL, NULL, 1) &&
           yaml_emitter_emit(&e, &ev) && emit_node(&e, root) &&
           yaml_document_end_event_initialize(&ev, 1) &&
           yaml_emitter_emit(&e, &ev) &&
           yaml_stream_end_event_initialize(&ev) &&
           yaml_emitter_emit(&e, &ev) && yaml_emitter_flush(&e);
  sph_status st = SPH_OK;
  if (!ok || ferror(out))
    st = sph_error_set(err, SPH_ERR_IO, "cannot write the scene tree: %s",
                       e.problem ? e.problem : "output error");
  yaml_emitter_delete(&e);
  return st;
}
