/* Expressions of the reference coordinates x, y, z (and t) in scene files,
 * e.g. a twist profile "sin(pi*y/(2*6))". Parsed and evaluated by GNU
 * libmatheval (Debian libmatheval-dev). Neither parsing nor evaluation is
 * thread-safe (an evaluator stores the variable values it is given): create
 * and evaluate expressions from one thread, e.g. while generating bodies. */
#ifndef SPH_EXPR_H
#define SPH_EXPR_H

#include "sph/status.h"

typedef struct sph_expr sph_expr;

/* Fails with SPH_ERR_SYNTAX for a malformed expression and SPH_ERR_ARG for a
 * variable other than x, y, z, t. */
sph_status sph_expr_create(sph_expr **out, const char *text, sph_error *err);
void sph_expr_destroy(sph_expr *e);
double sph_expr_eval(const sph_expr *e, double x, double y, double z, double t);
const char *sph_expr_text(const sph_expr *e);

#endif
