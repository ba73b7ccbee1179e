/* Outline files of 2D bodies (shape: {outline: {file}}), read into rings
 * for polygon.h: CSV (x, y per line, a blank line between rings) and SVG
 * through expat (polygon, polyline, rect, circle and ellipse elements, and
 * paths of straight segments: M, L, H, V, Z, absolute or relative; a
 * circle or ellipse as 64 segments). SVG's y runs down: it is turned up. */
#include "scene/outline_read.h"

#include <ctype.h>
#include <expat.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "text_lines.h"

#define OUTLINE_MAX_BYTES (64L << 20)

typedef struct rings {
  double *xy;
  size_t n, cap;
  size_t *start, nr, rcap; /* start[r] of each ring begun */
  sph_error *err;
  sph_status st;
  XML_Parser p;
  const char *path;
} rings;

static int push(rings *R, double x, double y) {
  if (R->n == R->cap) {
    size_t c = R->cap ? 2 * R->cap : 256;
    double *g = realloc(R->xy, 2 * c * sizeof *g);
    if (!g)
      return 0;
    R->xy = g;
    R->cap = c;
  }
  R->xy[2 * R->n] = x;
  R->xy[2 * R->n + 1] = y;
  R->n++;
  return 1;
}

/* ends the ring being read (an empty one is dropped) and begins the next */
static int ring_break(rings *R) {
  if (R->nr > 0 && R->start[R->nr - 1] == R->n)
    return 1;
  if (R->nr + 1 >= R->rcap) {
    size_t c = R->rcap ? 2 * R->rcap : 16;
    size_t *g = realloc(R->start, c * sizeof *g);
    if (!g)
      return 0;
    R->start = g;
    R->rcap = c;
  }
  R->start[R->nr++] = R->n;
  return 1;
}

static sph_status fail(rings *R, sph_status st, long line, const char *what) {
  if (R->st == SPH_OK)
    R->st = line > 0
                ? sph_error_set(R->err, st, "%s:%ld: %s", R->path, line, what)
                : sph_error_set(R->err, st, "%s: %s", R->path, what);
  if (R->p)
    XML_StopParser(R->p, XML_FALSE);
  return R->st;
}

/* ---- CSV ----------------------------------------------------------------- */

static void read_csv(rings *R, char *text) {
  long line = 0;
  int numbers_seen = 0, header = 0;
  for (char *s = text; s && R->st == SPH_OK;) {
    char *q = sph_text_line(&s, &line);
    if (!*q) {
      if (!ring_break(R))
        fail(R, SPH_ERR_NOMEM, 0, "outline");
      continue;
    }
    double v[2];
    int k = 0;
    for (char *end; k < 2; q = end) {
      while (*q == ',' || *q == ';' || isspace((unsigned char)*q))
        ++q;
      v[k] = strtod(q, &end);
      if (end == q || !isfinite(v[k]))
        break;
      ++k;
    }
    if (k < 2 && !numbers_seen && !header) {
      header = 1; /* the first line with text may name the columns */
      continue;
    }
    if (k < 2)
      fail(R, SPH_ERR_SYNTAX, line, "expected x, y");
    else if ((R->nr == 0 && !ring_break(R)) || !push(R, v[0], v[1]))
      fail(R, SPH_ERR_NOMEM, 0, "outline");
    numbers_seen = 1;
  }
}

/* ---- SVG ----------------------------------------------------------------- */

static const char *attr(const XML_Char **a, const char *name) {
  for (; a[0]; a += 2)
    if (!strcmp(a[0], name))
      return a[1];
  return NULL;
}

static int number(const char **s, double *v) {
  while (**s == ',' || isspace((unsigned char)**s))
    ++*s;
  char *end;
  *v = strtod(*s, &end);
  if (end == *s || !isfinite(*v))
    return 0;
  *s = end;
  return 1;
}

static void svg_points(rings *R, const char *s, long line) {
  double x, y;
  if (!ring_break(R))
    fail(R, SPH_ERR_NOMEM, 0, "outline");
  while (R->st == SPH_OK && number(&s, &x))
    if (!number(&s, &y))
      fail(R, SPH_ERR_SYNTAX, line, "points: an x without its y");
    else if (!push(R, x, -y))
      fail(R, SPH_ERR_NOMEM, 0, "outline");
}

static void svg_path(rings *R, const char *s, long line) {
  double x = 0, y = 0, x0 = 0, y0 = 0, a, b;
  char cmd = 0;
  while (R->st == SPH_OK) {
    while (*s == ',' || isspace((unsigned char)*s))
      ++s;
    if (!*s)
      break;
    if (isalpha((unsigned char)*s)) {
      cmd = *s++;
      if (!strchr("MmLlHhVvZz", cmd)) {
        fail(R, SPH_ERR_SYNTAX, line,
             "a path with curves (C, S, Q, T, A): flatten them to straight "
             "segments first (Inkscape: Extensions > Modify Path > Flatten "
             "Beziers)");
        break;
      }
      if (cmd == 'Z' || cmd == 'z') {
        x = x0;
        y = y0;
        if (!ring_break(R))
          fail(R, SPH_ERR_NOMEM, 0, "outline");
        continue;
      }
    }
    int rel = islower((unsigned char)cmd);
    switch (toupper((unsigned char)cmd)) {
    case 'M':
    case 'L':
      if (!number(&s, &a) || !number(&s, &b)) {
        fail(R, SPH_ERR_SYNTAX, line, "path: expected x, y");
        continue;
      }
      x = rel ? x + a : a;
      y = rel ? y + b : b;
      if (toupper((unsigned char)cmd) == 'M') {
        x0 = x;
        y0 = y;
        if (!ring_break(R))
          fail(R, SPH_ERR_NOMEM, 0, "outline");
        cmd = rel ? 'l' : 'L'; /* further pairs are lines */
      }
      break;
    case 'H':
    case 'V':
      if (!number(&s, &a)) {
        fail(R, SPH_ERR_SYNTAX, line, "path: expected a number");
        continue;
      }
      if (toupper((unsigned char)cmd) == 'H')
        x = rel ? x + a : a;
      else
        y = rel ? y + a : a;
      break;
    default:
      fail(R, SPH_ERR_SYNTAX, line, "path: a number before any command");
      continue;
    }
    if (R->st == SPH_OK && !push(R, x, -y))
      fail(R, SPH_ERR_NOMEM, 0, "outline");
  }
}

static double num_attr(const XML_Char **a, const char *name, int *ok) {
  const char *v = attr(a, name);
  double x = 0.0;
  if (!v)
    return 0.0;
  *ok = *ok && number(&v, &x);
  return x;
}

static void XMLCALL on_start(void *ctx, const XML_Char *el,
                             const XML_Char **a) {
  rings *R = ctx;
  long line = (long)XML_GetCurrentLineNumber(R->p);
  int shape = !strcmp(el, "polygon") || !strcmp(el, "polyline") ||
              !strcmp(el, "path") || !strcmp(el, "rect") ||
              !strcmp(el, "circle") || !strcmp(el, "ellipse");
  if (attr(a, "transform") && (shape || !strcmp(el, "g"))) {
    fail(R, SPH_ERR_SYNTAX, line,
         "a transform attribute: sph does not apply them (Inkscape: Path > "
         "Object to Path, then save with transforms applied)");
    return;
  }
  int ok = 1;
  if (!strcmp(el, "polygon") || !strcmp(el, "polyline")) {
    svg_points(R, attr(a, "points") ? attr(a, "points") : "", line);
  } else if (!strcmp(el, "path")) {
    svg_path(R, attr(a, "d") ? attr(a, "d") : "", line);
  } else if (!strcmp(el, "rect")) {
    double x = num_attr(a, "x", &ok), y = num_attr(a, "y", &ok);
    double w = num_attr(a, "width", &ok), h = num_attr(a, "height", &ok);
    if (!ring_break(R) || !push(R, x, -y) || !push(R, x + w, -y) ||
        !push(R, x + w, -y - h) || !push(R, x, -y - h))
      fail(R, SPH_ERR_NOMEM, 0, "outline");
  } else if (!strcmp(el, "circle") || !strcmp(el, "ellipse")) {
    double cx = num_attr(a, "cx", &ok), cy = num_attr(a, "cy", &ok);
    int circle = !strcmp(el, "circle");
    double rx = num_attr(a, circle ? "r" : "rx", &ok);
    double ry = circle ? rx : num_attr(a, "ry", &ok);
    if (!ring_break(R))
      fail(R, SPH_ERR_NOMEM, 0, "outline");
    for (int k = 0; k < 64 && R->st == SPH_OK; ++k) {
      double t = 2.0 * M_PI * k / 64.0;
      if (!push(R, cx + rx * cos(t), -(cy + ry * sin(t))))
        fail(R, SPH_ERR_NOMEM, 0, "outline");
    }
  }
  if (!ok)
    fail(R, SPH_ERR_SYNTAX, line, "an attribute that is not a number");
  if (shape && R->st == SPH_OK && !ring_break(R))
    fail(R, SPH_ERR_NOMEM, 0, "outline");
}

static void read_svg(rings *R, const char *text, size_t len) {
  R->p = XML_ParserCreate(NULL);
  if (!R->p) {
    fail(R, SPH_ERR_NOMEM, 0, "XML parser");
    return;
  }
  XML_SetUserData(R->p, R);
  XML_SetStartElementHandler(R->p, on_start);
  if (XML_Parse(R->p, text, (int)len, 1) == XML_STATUS_ERROR &&
      R->st == SPH_OK) {
    char msg[256];
    snprintf(msg, sizeof msg, "not SVG that sph can read (%s)",
             XML_ErrorString(XML_GetErrorCode(R->p)));
    XML_Parser p = R->p;
    R->p = NULL;
    fail(R, SPH_ERR_SYNTAX, (long)XML_GetCurrentLineNumber(p), msg);
    R->p = p;
  }
  XML_ParserFree(R->p);
  R->p = NULL;
}

/* ---- the file ------------------------------------------------------------ */

sph_status sph_outline_read(const char *path, double **xy, size_t **start,
                            size_t *nrings, sph_error *err) {
  *xy = NULL;
  *start = NULL;
  *nrings = 0;
  size_t len = strlen(path);
  int svg = len > 4 && !strcasecmp(path + len - 4, ".svg");
  if (!svg && !(len > 4 && (!strcasecmp(path + len - 4, ".csv") ||
                            !strcasecmp(path + len - 4, ".txt"))))
    return sph_error_set(err, SPH_ERR_IO,
                         "%s: an outline is a .svg or a .csv file", path);
  FILE *f = fopen(path, "rb");
  if (!f)
    return sph_error_set(err, SPH_ERR_IO, "%s: no such file", path);
  char *text = malloc(OUTLINE_MAX_BYTES + 1);
  size_t got = text ? fread(text, 1, OUTLINE_MAX_BYTES + 1, f) : 0;
  fclose(f);
  if (!text)
    return sph_error_set(err, SPH_ERR_NOMEM, "outline %s", path);
  if (got > OUTLINE_MAX_BYTES || got == 0) {
    free(text);
    return sph_error_set(err, SPH_ERR_IO, "%s: %s", path,
                         got ? "larger than 64 MiB" : "the file is empty");
  }
  text[got] = '\0';
  rings R = {.err = err, .st = SPH_OK, .path = path};
  if (svg)
    read_svg(&R, text, got);
  else
    read_csv(&R, text);
  free(text);
  if (R.st == SPH_OK && !ring_break(&R))
    fail(&R, SPH_ERR_NOMEM, 0, "outline");
  if (R.st == SPH_OK && R.nr < 2)
    fail(&R, SPH_ERR_GEOMETRY, 0,
         svg ? "no polygon, polyline, path, rect, circle or ellipse"
             : "no points");
  if (R.st != SPH_OK) {
    free(R.xy);
    free(R.start);
    return R.st;
  }
  /* start[nr - 1] == n closes the last ring */
  *xy = R.xy;
  *start = R.start;
  *nrings = R.nr - 1;
  return SPH_OK;
}
