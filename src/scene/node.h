/* A parsed YAML document as a tree that remembers where every node came
 * from (file, line, column) and its dotted path ("materials.rubber.density",
 * "bodies[0].shape"). Built from libyaml's document API; duplicate mapping
 * keys are rejected (libyaml accepts them silently). The scene schema and
 * each method validate their part of the tree with the typed getters below,
 * which fill defaults into the tree (so the resolved scene can be written
 * back) and mark consumed keys (so unknown keys can be reported with a
 * "did you mean" suggestion). */
#ifndef SPH_NODE_H
#define SPH_NODE_H

#include <stddef.h>
#include <stdio.h>

#include "sph/status.h"

typedef enum sph_node_kind {
  SPH_NODE_SCALAR,
  SPH_NODE_MAP,
  SPH_NODE_SEQ
} sph_node_kind;

typedef struct sph_node sph_node;
struct sph_node {
  sph_node_kind kind;
  char *value;      /* scalar text (NULL for maps and sequences) */
  int quoted;       /* scalar was quoted in the source: always a string */
  char *file;       /* origin: scene path or "<command line>" */
  int line, col;    /* 1-based position of the node (of its key in a map) */
  char *path;       /* dotted path from the root, "" for the root */
  size_t count;     /* children */
  char **keys;      /* map keys (count entries) */
  sph_node **items; /* children (count entries) */
  int used;         /* consumed by a schema */
  int is_default;   /* inserted as a default by a getter */
};

sph_status sph_node_load_file(sph_node **root, const char *path,
                              sph_error *err);
sph_status sph_node_load_string(sph_node **root, const char *text,
                                const char *origin, sph_error *err);
void sph_node_destroy(sph_node *n);

/* Child of a map by key, or NULL (does not mark it used). */
sph_node *sph_node_child(const sph_node *map, const char *key);

/* Applies "a.b.c=value" (the value is parsed as YAML, so "[1,2,3]" is a
 * sequence); a numeric part indexes a sequence ("bodies.0.material=steel").
 * Missing map keys are created; the new nodes carry origin "<command line>". */
sph_status sph_node_set(sph_node *root, const char *assignment, sph_error *err);

/* Every key of `map` must be in `allowed` (NULL-terminated); the first that
 * is not gives SPH_ERR_UNKNOWN_KEY with a "did you mean" suggestion. */
sph_status sph_node_check_keys(const sph_node *map, const char *const *allowed,
                               sph_error *err);

/* The first node at or under n that --set gave (origin "<command line>"),
 * or NULL; sph_node_error reports at it. */
const sph_node *sph_node_from_command_line(const sph_node *n);
/* An error placed in `file` at a key (err->key, a node's path) that holds
 * a value --set gave: re-placed at that value (set-up errors found after
 * the tree, e.g. a probe outside every body). */
void sph_node_blame_set(const sph_node *root, const char *file, sph_error *err);
/* Error at a node: fills file, line, col and key (the node's path); at the
 * node --set gave when one is at or under it (never for the root). */
sph_status sph_node_error(const sph_node *n, sph_error *err, sph_status code,
                          const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* SPH_ERR_MISSING_KEY at map for its required key `key`. */
sph_status sph_node_missing(const sph_node *map, const char *key,
                            sph_error *err);

/* Typed reads of a map's key. `required` != 0 makes a missing key an error
 * at the map; otherwise the default is inserted into the tree and returned
 * (a non-finite double default, "none", is returned but not inserted: no
 * scene can hold it, and the resolved tree must load again). Wrong types
 * are errors at the value. */
sph_status sph_node_get_double(sph_node *map, const char *key, int required,
                               double def, double *out, sph_error *err);
/* A double that must be > 0 ("must be positive, got %g" at the key). */
sph_status sph_node_get_positive(sph_node *map, const char *key, int required,
                                 double def, double *out, sph_error *err);
sph_status sph_node_get_int(sph_node *map, const char *key, int required,
                            long def, long *out, sph_error *err);
sph_status sph_node_get_bool(sph_node *map, const char *key, int required,
                             int def, int *out, sph_error *err);
/* The returned string points into the tree. */
sph_status sph_node_get_string(sph_node *map, const char *key, int required,
                               const char *def, const char **out,
                               sph_error *err);
/* A string that must be one of the NULL-terminated `values` (default
 * `def`); *out receives its index. Other strings are errors at the value
 * listing the allowed ones. */
sph_status sph_node_get_choice(sph_node *map, const char *key,
                               const char *const *values, const char *def,
                               int *out, sph_error *err);
/* A sequence of exactly n numbers; with n = 0 any length up to *got on
 * entry (the capacity of out). *got (if not NULL) receives the count; an
 * absent optional key gives count 0. */
sph_status sph_node_get_doubles(sph_node *map, const char *key, int required,
                                size_t n, double *out, size_t *got,
                                sph_error *err);
/* The child map (or NULL with SPH_OK when absent and not required). */
sph_status sph_node_get_map(sph_node *map, const char *key, int required,
                            sph_node **out, sph_error *err);

/* Inserts `yaml` (parsed as YAML, e.g. "{}" or "[a, b]") under `key` as a
 * default (it takes the map's origin) and returns it in *out; when the key
 * exists, returns the existing child instead. */
sph_status sph_node_insert_default(sph_node *map, const char *key,
                                   const char *yaml, sph_node **out,
                                   sph_error *err);

/* Scalar conversions of a single node. */
sph_status sph_node_as_double(const sph_node *n, double *out, sph_error *err);
sph_status sph_node_as_int(const sph_node *n, long *out, sph_error *err);
sph_status sph_node_as_bool(const sph_node *n, int *out, sph_error *err);

/* Writes the tree as block YAML. */
sph_status sph_node_write(const sph_node *root, FILE *out, sph_error *err);

/* Levenshtein distance, for suggestions. */
size_t sph_edit_distance(const char *a, const char *b);
/* The candidate closest to `word` if it is close enough, else NULL. */
const char *sph_suggest(const char *word, const char *const *candidates);

#endif
