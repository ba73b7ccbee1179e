/* Ops tables of the methods (each defined in its own folder). */
#ifndef SPH_REGISTRY_IMPL_H
#define SPH_REGISTRY_IMPL_H

#include <string.h>

#include "solver/sim.h"

extern const sph_method_ops tl_jst_method_ops;
extern const sph_method_ops tl_csph_method_ops;
extern const sph_method_ops ul_sph_method_ops;
extern const sph_method_ops ul_csph_method_ops;
extern const sph_method_ops tl_bond_method_ops;

#endif
