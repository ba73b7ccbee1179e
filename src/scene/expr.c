/* Scene expressions of x, y, z, t through GNU libmatheval. */
#include "sph/expr.h"

#include <matheval.h>
#include <stdlib.h>
#include <string.h>

struct sph_expr {
  void *eval;
  char *text;
};

sph_status sph_expr_create(sph_expr **out, const char *text, sph_error *err) {
  *out = NULL;
  /* libmatheval's parser takes a mutable string */
  char *copy = strdup(text);
  if (!copy)
    return sph_error_set(err, SPH_ERR_NOMEM, "expression");
  void *ev = evaluator_create(copy);
  if (!ev) {
    free(copy);
    return sph_error_set(err, SPH_ERR_SYNTAX, "cannot parse expression '%s'",
                         text);
  }
  char **names;
  int count;
  evaluator_get_variables(ev, &names, &count);
  for (int i = 0; i < count; ++i)
    if (strcmp(names[i], "x") && strcmp(names[i], "y") &&
        strcmp(names[i], "z") && strcmp(names[i], "t")) {
      sph_status st = sph_error_set(err, SPH_ERR_ARG,
                                    "expression '%s' uses '%s'; only x, y, "
                                    "z and t are defined",
                                    text, names[i]);
      evaluator_destroy(ev);
      free(copy);
      return st;
    }
  sph_expr *e = malloc(sizeof *e);
  if (!e) {
    evaluator_destroy(ev);
    free(copy);
    return sph_error_set(err, SPH_ERR_NOMEM, "expression");
  }
  e->eval = ev;
  e->text = copy;
  *out = e;
  return SPH_OK;
}

void sph_expr_destroy(sph_expr *e) {
  if (!e)
    return;
  evaluator_destroy(e->eval);
  free(e->text);
  free(e);
}

double sph_expr_eval(const sph_expr *e, double x, double y, double z,
                     double t) {
  static char *names[] = {"x", "y", "z", "t"};
  double values[4] = {x, y, z, t};
  return evaluator_evaluate(e->eval, 4, names, values);
}

const char *sph_expr_text(const sph_expr *e) { return e->text; }
