/* The constitutive models, one X(id, name) line each: the ops table
 * sph_<id>_ops (defined in src/materials/<id>.c) and its scene name. The
 * registry array, the externs, the model names and every "known: ..."
 * message are made from this list: adding a model is one line here plus
 * its file. A build may append models with SPH_MATERIAL_LIST_EXTRA(X)
 * (tests/unit/test_material_plugin.c compiles the registry with a toy). */
#ifndef SPH_MATERIAL_LIST_H
#define SPH_MATERIAL_LIST_H

#ifndef SPH_MATERIAL_LIST_EXTRA
#define SPH_MATERIAL_LIST_EXTRA(X)
#endif

#define SPH_MATERIAL_LIST(X)                                                   \
  X(linear_elastic, "linear-elastic")                                          \
  X(neo_hookean, "neo-hookean")                                                \
  X(mooney_rivlin, "mooney-rivlin")                                            \
  SPH_MATERIAL_LIST_EXTRA(X)

#endif
