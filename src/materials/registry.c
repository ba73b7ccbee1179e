/* The material registry, made from the model list (material_list.h): the
 * ops tables, their names, the "known: ..." list, and the keys a material
 * block may hold (the common ones, then each model's own). */
#include <stdio.h>
#include <string.h>

#include "materials/material_impl.h"

#define SPH_MATERIAL_OPS(id, name) &sph_##id##_ops,
static const sph_material_ops *const models[] = {
    SPH_MATERIAL_LIST(SPH_MATERIAL_OPS) NULL};

#define SPH_MATERIAL_NAME(id, name) name,
static const char *const model_names[] = {SPH_MATERIAL_LIST(SPH_MATERIAL_NAME)
                                              NULL};

/* ", a, b, c": the list without its first two characters */
#define SPH_MATERIAL_KNOWN(id, name) ", " name
static const char known[] = "" SPH_MATERIAL_LIST(SPH_MATERIAL_KNOWN);

/* what every model takes: sph_material_params' common fields */
static const char *const common_keys[] = {"model",
                                          "density",
                                          "youngs_modulus",
                                          "poisson_ratio",
                                          "shear_modulus",
                                          "bulk_modulus",
                                          NULL};

const char *const *sph_material_models(void) { return model_names; }

const char *sph_material_known(void) { return known + 2; }

const sph_material_ops *sph_material_find(const char *name) {
  for (const sph_material_ops *const *o = models; name && *o; ++o)
    if (strcmp((*o)->name, name) == 0)
      return *o;
  return NULL;
}

static int listed(const char *const *list, size_t n, const char *key) {
  for (size_t i = 0; i < n; ++i)
    if (!strcmp(list[i], key))
      return 1;
  return 0;
}

size_t sph_material_keys(const char **out, size_t cap, size_t *ncommon) {
  size_t n = 0;
  for (const char *const *k = common_keys; *k && n + 1 < cap; ++k)
    out[n++] = *k;
  *ncommon = n;
  for (const sph_material_ops *const *o = models; *o; ++o)
    for (const char *const *k = (*o)->keys; k && *k && n + 1 < cap; ++k)
      if (!listed(out, n, *k))
        out[n++] = *k;
  out[n] = NULL;
  return n;
}

void sph_material_owners(const char *key, char *buf, size_t size) {
  buf[0] = '\0';
  for (const sph_material_ops *const *o = models; *o; ++o)
    for (const char *const *k = (*o)->keys; k && *k; ++k)
      if (!strcmp(*k, key)) {
        size_t len = strlen(buf);
        snprintf(buf + len, size - len, "%s%s", len ? ", " : "", (*o)->name);
      }
}
