/* The methods, one line each: X(id) names the ops table id_method_ops
 * defined in methods/<id>/. The registry's array, its externs and the list
 * of known names in an unknown method's error all come from this list.
 * SPH_METHOD_LIST_EXTRA(X) adds a build's own methods (none by default),
 * e.g. -D'SPH_METHOD_LIST_EXTRA(X)=X(my_method)' with my_method.c listed in
 * the methods library. */
#ifndef SPH_METHOD_LIST_H
#define SPH_METHOD_LIST_H

#define SPH_METHOD_LIST(X) X(tl_jst) X(tl_csph) X(ul_sph) X(ul_csph) X(tl_bond)

#ifndef SPH_METHOD_LIST_EXTRA
#define SPH_METHOD_LIST_EXTRA(X)
#endif

#endif
