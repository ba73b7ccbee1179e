/* What node.c (the tree, its getters) and node_yaml.c (YAML in and out,
 * --set) share: node construction and the YAML reader. */
#ifndef SPH_NODE_IMPL_H
#define SPH_NODE_IMPL_H

#include "scene/node.h"

/* "parent.key" and "parent[i]" (malloc'd; NULL on no memory). */
char *sph_node_join_key(const char *parent, const char *key);
char *sph_node_join_index(const char *parent, size_t i);

/* A new node at file:line:col with the empty path; NULL on no memory. */
sph_node *sph_node_new(sph_node_kind kind, const char *file, int line, int col);
sph_node *sph_node_scalar_new(const char *text, const char *file, int line,
                              int col);

/* Appends a child (key ignored for sequences); takes ownership on success;
 * -1 on no memory. */
int sph_node_append(sph_node *parent, const char *key, sph_node *child);

/* Sets the path of n and, recursively, of its children; -1 on no memory. */
int sph_node_set_path(sph_node *n, const char *path);

/* Sets the origin of n and of its children. */
void sph_node_set_origin(sph_node *n, const char *file, int line, int col);

/* Parses one YAML document from text; an empty one is an error unless
 * allow_empty, which gives an empty scalar. */
sph_status sph_node_load_text(const char *text, size_t len, const char *origin,
                              int allow_empty, sph_node **root, sph_error *err);

#endif
