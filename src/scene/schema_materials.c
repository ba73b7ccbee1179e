/* The scene's `materials:` block: each material's model and parameters. */
#include <stdlib.h>
#include <string.h>

#include "scene/schema_impl.h"

static sph_status parse_material(sph_material *m, const char *name, sph_node *n,
                                 sph_error *err) {
  if (n->kind != SPH_NODE_MAP)
    return sph_node_error(n, err, SPH_ERR_TYPE,
                          "expected a mapping of material parameters");
  static const char *const keys[] = {"model",
                                     "density",
                                     "youngs_modulus",
                                     "poisson_ratio",
                                     "shear_modulus",
                                     "bulk_modulus",
                                     "xi",
                                     NULL};
  SPH_TRY(sph_node_check_keys(n, keys, err));
  sph_material_params p = {0};
  SPH_TRY(sph_node_get_string(n, "model", 0, "neo-hookean", &p.model, err));
  int known = 0;
  for (const char *const *mname = sph_material_models(); *mname; ++mname)
    known |= !strcmp(*mname, p.model);
  if (!known) {
    const char *hint = sph_suggest(p.model, sph_material_models());
    return sph_node_error(sph_node_child(n, "model"), err, SPH_ERR_RANGE,
                          "unknown model '%s'%s%s%s", p.model,
                          hint ? "; did you mean '"
                               : " (known: linear-"
                                 "elastic, neo-hookean, "
                                 "mooney-rivlin)",
                          hint ? hint : "", hint ? "'?" : "");
  }
  SPH_TRY(sph_node_get_positive(n, "density", 1, 0, &p.density, err));
  p.has_youngs =
      sph_node_child(n, "youngs_modulus") || sph_node_child(n, "poisson_ratio");
  p.has_moduli =
      sph_node_child(n, "shear_modulus") || sph_node_child(n, "bulk_modulus");
  if (p.has_youngs && p.has_moduli)
    return sph_node_error(n, err, SPH_ERR_ARG,
                          "give youngs_modulus and poisson_ratio, or "
                          "shear_modulus and bulk_modulus, not both");
  if (!p.has_youngs && !p.has_moduli)
    return sph_node_error(n, err, SPH_ERR_MISSING_KEY,
                          "give youngs_modulus and poisson_ratio (or "
                          "shear_modulus and bulk_modulus)");
  if (p.has_youngs) {
    SPH_TRY(sph_node_get_positive(n, "youngs_modulus", 1, 0, &p.youngs_modulus,
                                  err));
    SPH_TRY(
        sph_node_get_double(n, "poisson_ratio", 1, 0, &p.poisson_ratio, err));
    if (!(p.poisson_ratio > -1.0 && p.poisson_ratio < 0.5))
      return sph_node_error(sph_node_child(n, "poisson_ratio"), err,
                            SPH_ERR_RANGE, "must be in (-1, 0.5), got %g",
                            p.poisson_ratio);
  } else {
    SPH_TRY(
        sph_node_get_positive(n, "shear_modulus", 1, 0, &p.shear_modulus, err));
    SPH_TRY(
        sph_node_get_positive(n, "bulk_modulus", 1, 0, &p.bulk_modulus, err));
  }
  if (sph_node_child(n, "xi")) {
    p.has_xi = 1;
    SPH_TRY(sph_node_get_double(n, "xi", 1, 0, &p.xi, err));
  }
  sph_status st = sph_material_create(m, &p, err);
  if (st != SPH_OK) {
    sph_node *at = sph_node_child(n, "xi") ? sph_node_child(n, "xi") : n;
    char msg[768];
    snprintf(msg, sizeof msg, "%s", err->message);
    return sph_node_error(at, err, st, "%s", msg);
  }
  sph_schema_copy_name(m->name, name);
  return SPH_OK;
}

sph_status sph_schema_materials(sph_scene *s, sph_node *root, sph_error *err) {
  sph_node *mats;
  SPH_TRY(sph_node_get_map(root, "materials", 1, &mats, err));
  if (mats->count == 0)
    return sph_node_error(mats, err, SPH_ERR_MISSING_KEY,
                          "define at least one material");
  s->materials = calloc(mats->count, sizeof *s->materials);
  if (!s->materials)
    return sph_error_set(err, SPH_ERR_NOMEM, "materials");
  for (size_t i = 0; i < mats->count; ++i) {
    SPH_TRY(
        parse_material(&s->materials[i], mats->keys[i], mats->items[i], err));
    mats->items[i]->used = 1;
    s->nmaterials++;
  }
  return SPH_OK;
}
