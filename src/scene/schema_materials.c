/* The scene's `materials:` block: each material's model (the registry of
 * src/materials), its density and elastic constants, and the model's own
 * keys, which the materials module and the model check. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/schema_impl.h"

/* An error of the material's checks (sph_material_elastic, _own) at the
 * key it names, else at the material. */
static sph_status material_error(sph_node *n, sph_status st, sph_error *err) {
  sph_node *at = err->key[0] ? sph_node_child(n, err->key) : NULL;
  char msg[768];
  snprintf(msg, sizeof msg, "%s", err->message);
  return sph_node_error(at ? at : n, err, st, "%s", msg);
}

/* density and either (E, nu) or (mu, kappa), each read and checked */
static sph_status parse_elastic(sph_material_params *p, sph_node *n,
                                sph_error *err) {
  SPH_TRY(sph_node_get_positive(n, "density", 1, 0, &p->density, err));
  p->has_youngs =
      sph_node_child(n, "youngs_modulus") || sph_node_child(n, "poisson_ratio");
  p->has_moduli =
      sph_node_child(n, "shear_modulus") || sph_node_child(n, "bulk_modulus");
  if (p->has_youngs && p->has_moduli)
    return sph_node_error(n, err, SPH_ERR_ARG,
                          "give youngs_modulus and poisson_ratio, or "
                          "shear_modulus and bulk_modulus, not both");
  if (!p->has_youngs && !p->has_moduli)
    return sph_node_error(n, err, SPH_ERR_MISSING_KEY,
                          "give youngs_modulus and poisson_ratio (or "
                          "shear_modulus and bulk_modulus)");
  if (p->has_youngs) {
    SPH_TRY(sph_node_get_positive(n, "youngs_modulus", 1, 0, &p->youngs_modulus,
                                  err));
    return sph_node_get_double(n, "poisson_ratio", 1, 0, &p->poisson_ratio,
                               err);
  }
  SPH_TRY(
      sph_node_get_positive(n, "shear_modulus", 1, 0, &p->shear_modulus, err));
  return sph_node_get_positive(n, "bulk_modulus", 1, 0, &p->bulk_modulus, err);
}

/* A material: its model (the registry's), the common parameters, then the
 * model's own keys, checked by the materials module and the model. */
static sph_status parse_material(sph_material *m, const char *name, sph_node *n,
                                 sph_error *err) {
  if (n->kind != SPH_NODE_MAP)
    return sph_node_error(n, err, SPH_ERR_TYPE,
                          "expected a mapping of material parameters");
  const char *keys[SPH_MATERIAL_KEYS_MAX];
  size_t ncommon,
      nkeys = sph_material_keys(keys, sizeof keys / sizeof *keys, &ncommon);
  SPH_TRY(sph_node_check_keys(n, keys, err));
  sph_material_params p = {0};
  SPH_TRY(sph_node_get_string(n, "model", 0, "neo-hookean", &p.model, err));
  m->ops = sph_material_find(p.model);
  if (!m->ops) {
    const char *hint = sph_suggest(p.model, sph_material_models());
    if (hint)
      return sph_node_error(sph_node_child(n, "model"), err, SPH_ERR_RANGE,
                            "unknown model '%s'; did you mean '%s'?", p.model,
                            hint);
    return sph_node_error(sph_node_child(n, "model"), err, SPH_ERR_RANGE,
                          "unknown model '%s' (known: %s)", p.model,
                          sph_material_known());
  }
  SPH_TRY(parse_elastic(&p, n, err));
  sph_status st = sph_material_elastic(m, &p, err);
  if (st != SPH_OK)
    return material_error(n, st, err);
  for (size_t k = ncommon; k < nkeys && p.nown < SPH_MATERIAL_GIVEN_MAX; ++k) {
    if (!sph_node_child(n, keys[k]))
      continue;
    p.own_key[p.nown] = keys[k];
    SPH_TRY(sph_node_get_double(n, keys[k], 1, 0, &p.own_value[p.nown], err));
    p.nown++;
  }
  st = sph_material_own(m, &p, err);
  if (st != SPH_OK)
    return material_error(n, st, err);
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
