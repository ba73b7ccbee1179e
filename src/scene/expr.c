/* Scene expressions of x, y, z, t through GNU libmatheval (see
 * include/sph/expr.h).
 *
 * The text is checked here first against libmatheval's grammar (its token
 * rules and operand/operator structure): libmatheval leaks its partial parse
 * tree on a syntax error and echoes unknown characters to stdout, so it is
 * only given text that parses, and errors can name a position. Its parser
 * keeps global state and evaluation writes the variable values into the
 * evaluator, so neither step is thread-safe. */
#include "scene/expr.h"

#include <matheval.h>
#include <stdlib.h>
#include <string.h>

static const char *const expr_vars[4] = {"x", "y", "z", "t"};

struct sph_expr {
  void *eval;
  char *text;
  int nvars;       /* variables the expression uses */
  int which[4];    /* their index in expr_vars */
  char *names[4];  /* their names, as libmatheval takes them */
  char buffer[16]; /* storage of names[] */
};

/* ---- syntax check (libmatheval 1.1 grammar) ----------------------------- */

static const char *const expr_functions[] = {
    "exp",   "log",   "sqrt",     "sin",   "cos",   "tan",   "cot",
    "sec",   "csc",   "asin",     "acos",  "atan",  "acot",  "asec",
    "acsc",  "sinh",  "cosh",     "tanh",  "coth",  "sech",  "csch",
    "asinh", "acosh", "atanh",    "acoth", "asech", "acsch", "abs",
    "step",  "delta", "nandelta", "erf",   NULL};

/* constants whose names start with a digit (the others scan as names) */
static const char *const expr_digit_constants[] = {"1_pi", "2_pi", "2_sqrtpi",
                                                   NULL};

#define EXPR_MAX_DEPTH 200

typedef struct scan {
  const char *text, *p;
  int depth;
  const char *why; /* set on the first error, at p */
} scan;

static int is_digit(char c) { return c >= '0' && c <= '9'; }
static int is_alpha(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}

static void skip_blanks(scan *s) {
  while (*s->p == ' ' || *s->p == '\t')
    ++s->p;
}

/* length of ([0-9]+ | [0-9]+.[0-9]* | [0-9]*.[0-9]+)([Ee][+-]?[0-9]+)? */
static size_t number_length(const char *p) {
  size_t n = 0, whole = 0, frac = 0;
  while (is_digit(p[n]))
    ++n, ++whole;
  if (p[n] == '.') {
    ++n;
    while (is_digit(p[n]))
      ++n, ++frac;
  }
  if (whole == 0 && frac == 0)
    return 0;
  if (p[n] == 'e' || p[n] == 'E') {
    size_t m = n + 1;
    if (p[m] == '+' || p[m] == '-')
      ++m;
    if (is_digit(p[m])) {
      while (is_digit(p[m]))
        ++m;
      n = m;
    }
  }
  return n;
}

static int in_list(const char *word, size_t len, const char *const *list) {
  for (; *list; ++list)
    if (strlen(*list) == len && !strncmp(word, *list, len))
      return 1;
  return 0;
}

static int fail(scan *s, const char *why) {
  if (!s->why)
    s->why = why;
  return 0;
}

static int scan_expression(scan *s);

/* the rest of a parenthesised group, after its '(' */
static int scan_group(scan *s) {
  if (!scan_expression(s))
    return 0;
  skip_blanks(s);
  if (*s->p != ')')
    return fail(s, "expected ')'");
  ++s->p;
  return 1;
}

/* operand: '-' operand | number | constant | variable | function '('
 * expression ')' | '(' expression ')' */
static int scan_operand(scan *s) {
  if (++s->depth > EXPR_MAX_DEPTH)
    return fail(s, "nested too deeply");
  int ok = 1;
  skip_blanks(s);
  const char *p = s->p;
  if (*p == '-') {
    ++s->p;
    ok = scan_operand(s);
  } else if (*p == '(') {
    ++s->p;
    ok = scan_group(s);
  } else if (is_digit(*p) || *p == '.') {
    size_t n = number_length(p);
    for (const char *const *c = expr_digit_constants; *c; ++c)
      if (!strncmp(p, *c, strlen(*c)) && strlen(*c) > n)
        n = strlen(*c);
    if (n == 0)
      ok = fail(s, "expected a number");
    s->p += n;
  } else if (is_alpha(*p)) {
    size_t n = 0;
    while (is_alpha(p[n]) || is_digit(p[n]))
      ++n;
    s->p += n;
    if (in_list(p, n, expr_functions)) {
      skip_blanks(s);
      if (*s->p != '(') {
        ok = fail(s, "expected '(' after a function name");
      } else {
        ++s->p;
        ok = scan_group(s);
      }
    }
  } else {
    ok = fail(s, *p ? "expected a number, a name or '('"
                    : "unexpected end of expression");
  }
  --s->depth;
  return ok;
}

/* expression: operand (('+' | '-' | '*' | '/' | '^') operand)* */
static int scan_expression(scan *s) {
  if (!scan_operand(s))
    return 0;
  for (;;) {
    skip_blanks(s);
    if (!*s->p || !strchr("+-*/^", *s->p))
      return 1;
    ++s->p;
    if (!scan_operand(s))
      return 0;
  }
}

static sph_status check_syntax(const char *text, sph_error *err) {
  scan s = {text, text, 0, NULL};
  if (scan_expression(&s)) {
    skip_blanks(&s);
    if (!*s.p)
      return SPH_OK;
    s.why = *s.p == ')' ? "unbalanced ')'" : "expected an operator";
  }
  if (*s.p && !strchr("_. \t+-*/^()", *s.p) && !is_alpha(*s.p) &&
      !is_digit(*s.p))
    return sph_error_set(err, SPH_ERR_SYNTAX,
                         "cannot parse expression '%s': unexpected "
                         "character at position %d",
                         text, (int)(s.p - text) + 1);
  return sph_error_set(err, SPH_ERR_SYNTAX,
                       "cannot parse expression '%s': %s at position %d", text,
                       s.why, (int)(s.p - text) + 1);
}

/* ---- expressions --------------------------------------------------------- */

sph_status sph_expr_create(sph_expr **out, const char *text, sph_error *err) {
  *out = NULL;
  SPH_TRY(check_syntax(text, err));
  sph_expr *e = calloc(1, sizeof *e);
  char *scratch = strdup(text);
  if (!e || !scratch || !(e->text = strdup(text))) {
    free(scratch);
    sph_expr_destroy(e);
    return sph_error_set(err, SPH_ERR_NOMEM, "expression '%s'", text);
  }
  /* the parser takes a mutable string */
  e->eval = evaluator_create(scratch);
  free(scratch);
  if (!e->eval) {
    sph_expr_destroy(e);
    return sph_error_set(err, SPH_ERR_SYNTAX, "cannot parse expression '%s'",
                         text);
  }
  char **names;
  int count;
  evaluator_get_variables(e->eval, &names, &count);
  char *slot = e->buffer;
  for (int i = 0; i < count; ++i) {
    int k = 0;
    while (k < 4 && strcmp(names[i], expr_vars[k]))
      ++k;
    if (k == 4) {
      sph_status st = sph_error_set(
          err, SPH_ERR_ARG,
          "expression '%s' uses the unknown variable '%s'; the variables "
          "are x, y, z (reference coordinates) and t",
          text, names[i]);
      sph_expr_destroy(e);
      return st;
    }
    /* our own copy of the name: libmatheval's API takes char ** */
    strcpy(slot, expr_vars[k]);
    e->names[e->nvars] = slot;
    e->which[e->nvars++] = k;
    slot += strlen(expr_vars[k]) + 1;
  }
  *out = e;
  return SPH_OK;
}

void sph_expr_destroy(sph_expr *e) {
  if (!e)
    return;
  if (e->eval)
    evaluator_destroy(e->eval);
  free(e->text);
  free(e);
}

double sph_expr_eval(const sph_expr *e, double x, double y, double z,
                     double t) {
  const double all[4] = {x, y, z, t};
  double values[4];
  for (int i = 0; i < e->nvars; ++i)
    values[i] = all[e->which[i]];
  return evaluator_evaluate(e->eval, e->nvars, (char **)e->names, values);
}

const char *sph_expr_text(const sph_expr *e) { return e->text; }
