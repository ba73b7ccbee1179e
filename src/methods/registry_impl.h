/* Ops tables of the methods (each defined in its own folder), declared from
 * methods/method_list.h. */
#ifndef SPH_REGISTRY_IMPL_H
#define SPH_REGISTRY_IMPL_H

#include <string.h>

#include "methods/method_list.h"
#include "solver/sim.h"

#define SPH_METHOD_EXTERN(id) extern const sph_method_ops id##_method_ops;
SPH_METHOD_LIST(SPH_METHOD_EXTERN)
SPH_METHOD_LIST_EXTRA(SPH_METHOD_EXTERN)
#undef SPH_METHOD_EXTERN

#endif
