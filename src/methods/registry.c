/* The method registry: one line per method. */
#include "methods/registry_impl.h"

static const sph_method_ops *const methods[] = {
    &tl_jst_method_ops,  &tl_csph_method_ops, &ul_sph_method_ops,
    &ul_csph_method_ops, &tl_bond_method_ops, NULL,
};

const sph_method_ops *const *sph_method_list(void) { return methods; }

const sph_method_ops *sph_method_find(const char *name) {
  for (const sph_method_ops *const *m = methods; *m; ++m)
    if (strcmp((*m)->name, name) == 0)
      return *m;
  return NULL;
}
