/* The terms, one line each: X(id) names the ops table id_term_ops defined
 * in terms/. Terms are created only by the methods (each through its
 * *_create in terms_impl.h, never looked up by name), so this list only
 * declares the tables and makes sph_term_list (terms.c), which the
 * conformance test walks. SPH_TERM_LIST_EXTRA(X) adds a build's own (none
 * by default). */
#ifndef SPH_TERM_LIST_H
#define SPH_TERM_LIST_H

#define SPH_TERM_LIST(X)                                                       \
  X(angular_momentum_projection)                                               \
  X(jst_p)                                                                     \
  X(jst_p_sym)                                                                 \
  X(jst_j) X(body_force) X(contact) X(essential_bc) X(lagrange_projection)

#ifndef SPH_TERM_LIST_EXTRA
#define SPH_TERM_LIST_EXTRA(X)
#endif

#endif
