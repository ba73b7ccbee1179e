/* What the scene schema's files share (schema.c, schema_materials.c,
 * schema_bodies.c, schema_boundaries.c, schema_output.c): the readers of
 * axes, directions, lists and one-of choices, and each section's parser,
 * called by the loader in schema.c in the order of the scene's checks. */
#ifndef SPH_SCHEMA_IMPL_H
#define SPH_SCHEMA_IMPL_H

#include "scene/node.h"
#include "scene/scene.h"
#include "sph/status.h"

/* "x", "y", "z", NULL */
extern const char *const sph_axis_names[];

/* The sequence at key (NULL with SPH_OK when absent and not required). */
sph_status sph_schema_get_seq(sph_node *map, const char *key, int required,
                              sph_node **out, sph_error *err);

/* A direction: x, y or z (default axis def), or a non-zero vector of n
 * numbers (n = 2 leaves z = 0), scaled to unit length. */
sph_status sph_schema_get_direction(sph_node *map, const char *key,
                                    int required, int def, int n, double out[3],
                                    sph_error *err);

/* The one key of `map` among `choices`; errors when none or several. */
sph_status sph_schema_one_of(sph_node *map, const char *const *choices,
                             const char *what, int *which, sph_error *err);

/* src into a name of SPH_NAME_MAX bytes. */
void sph_schema_copy_name(char *dst, const char *src);

/* A file the scene names (fn: its node): relative to the scene file's
 * folder, to the working one when --set gave it; into path[size]. */
void sph_schema_file_path(const sph_node *fn, const char *file, char *path,
                          size_t size);
/* fn's value made the absolute path of the file read (the resolved scene
 * names it wherever it is read from). */
void sph_schema_name_absolute(sph_node *fn, const char *path);
/* The `units` of files: m, cm, mm, um, in, ft (NULL-terminated) and their
 * lengths in metres. */
extern const char *const sph_length_units[];
extern const double sph_length_scale[];

/* The placement of the body a selection names, or NULL (world frame). */
const sph_transform *sph_schema_selection_frame(const sph_scene *s,
                                                const sph_selection *sel);

/* The sections, each filling its part of s from the tree under root. */
sph_status sph_schema_materials(sph_scene *s, sph_node *root, sph_error *err);
sph_status sph_schema_bodies(sph_scene *s, sph_node *root, sph_error *err);
sph_status sph_schema_boundaries(sph_scene *s, sph_node *root, sph_error *err);
sph_status sph_schema_contact(sph_scene *s, sph_node *root, sph_error *err);
sph_status sph_schema_output(sph_scene *s, sph_node *root, sph_error *err);

#endif
