/* The constitutive models' ops tables (one file each), declared from the
 * model list for the registry. */
#ifndef SPH_MATERIAL_IMPL_H
#define SPH_MATERIAL_IMPL_H

#include "materials/material.h"
#include "materials/material_list.h"

#define SPH_MATERIAL_EXTERN(id, name)                                          \
  extern const sph_material_ops sph_##id##_ops;
SPH_MATERIAL_LIST(SPH_MATERIAL_EXTERN)
#undef SPH_MATERIAL_EXTERN

#endif
