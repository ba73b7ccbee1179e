/* The method registry, generated from methods/method_list.h: the ops
 * tables in the list's order, lookup by scene name, and the error of an
 * unknown name (a suggestion, or the names known). */
#include "methods/registry_impl.h"
#include "scene/node.h"

#define SPH_METHOD_ENTRY(id) &id##_method_ops,
static const sph_method_ops *const methods[] = {SPH_METHOD_LIST(
    SPH_METHOD_ENTRY) SPH_METHOD_LIST_EXTRA(SPH_METHOD_ENTRY) NULL};
#undef SPH_METHOD_ENTRY

const sph_method_ops *const *sph_method_list(void) { return methods; }

const sph_method_ops *sph_method_find(const char *name) {
  for (const sph_method_ops *const *m = methods; *m; ++m)
    if (strcmp((*m)->name, name) == 0)
      return *m;
  return NULL;
}

void sph_method_known(char *known, size_t size) {
  size_t k = 0;
  if (!size)
    return;
  known[0] = '\0';
  for (const sph_method_ops *const *m = methods; *m && k < 15; ++m, ++k) {
    strncat(known, k ? ", " : "", size - strlen(known) - 1);
    strncat(known, (*m)->name, size - strlen(known) - 1);
  }
}

sph_status sph_method_unknown(const char *name, sph_node *at, sph_error *err) {
  const char *names[16];
  size_t k = 0;
  for (const sph_method_ops *const *m = methods; *m && k < 15; ++m)
    names[k++] = (*m)->name;
  names[k] = NULL;
  const char *hint = sph_suggest(name, names);
  if (hint)
    return sph_node_error(at, err, SPH_ERR_ARG,
                          "unknown method '%s'; did you mean '%s'?", name,
                          hint);
  char known[256];
  sph_method_known(known, sizeof known);
  return sph_node_error(at, err, SPH_ERR_ARG, "unknown method '%s' (known: %s)",
                        name, known);
}
