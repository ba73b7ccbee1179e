/* The constitutive models' ops tables (one file each) for the registry. */
#ifndef SPH_MATERIAL_IMPL_H
#define SPH_MATERIAL_IMPL_H

#include "materials/material.h"

extern const sph_material_ops sph_linear_elastic_ops;
extern const sph_material_ops sph_neo_hookean_ops;
extern const sph_material_ops sph_mooney_rivlin_ops;

#endif
