/* Particle files as body shapes: a CSV with a header (x, y[, z][, volume])
 * or a .vtp/.pvtp that sph wrote (io/vtk_read.c), checked value by value,
 * for duplicates (sorted by position) and for the scene's dimension, and
 * their median nearest-neighbour distance (a grid of cells of the mean
 * spacing, searched in growing shells). */
#include "scene/cloud.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "io/vtk_read.h"
#include "text_lines.h"

#define CLOUD_MAX_BYTES (1L << 30)

/* the file's particles as read, with a CSV's line of each */
typedef struct reader {
  sph_cloud *c;
  size_t cap;
  long *line; /* CSV: the line of each particle; NULL for a .vtp */
  const char *path;
  sph_error *err;
} reader;

static sph_status fail(const reader *R, long line, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static sph_status fail(const reader *R, long line, const char *fmt, ...) {
  char msg[256];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return line > 0
             ? sph_error_set(R->err, SPH_ERR_GEOMETRY, "%s:%ld: %s", R->path,
                             line, msg)
             : sph_error_set(R->err, SPH_ERR_GEOMETRY, "%s: %s", R->path, msg);
}

static int push(reader *R, const double X[3], double v, long line) {
  sph_cloud *c = R->c;
  if (c->n == R->cap) {
    size_t cap = R->cap ? 2 * R->cap : 1024;
    double *x = realloc(c->x, 3 * cap * sizeof *x);
    if (!x)
      return 0;
    c->x = x;
    double *vv = realloc(c->v, cap * sizeof *vv);
    if (!vv)
      return 0;
    c->v = vv;
    long *l = realloc(R->line, cap * sizeof *l);
    if (!l)
      return 0;
    R->line = l;
    R->cap = cap;
  }
  memcpy(c->x + 3 * c->n, X, 3 * sizeof *X);
  c->v[c->n] = v;
  R->line[c->n++] = line;
  return 1;
}

/* ---- CSV ----------------------------------------------------------------- */

/* the next field of a line (comma, semicolon or whitespace separated) into
 * [*b, *e); 0 at the line's end */
static int next_field(char **s, char **b, char **e) {
  char *q = *s;
  while (*q == ' ' || *q == '\t' || *q == '\r')
    ++q;
  if (!*q)
    return 0;
  *b = q;
  while (*q && *q != ',' && *q != ';' && *q != ' ' && *q != '\t' && *q != '\r')
    ++q;
  *e = q;
  while (*q == ' ' || *q == '\t' || *q == '\r')
    ++q;
  if (*q == ',' || *q == ';')
    ++q;
  *s = q;
  return 1;
}

enum { COL_X, COL_Y, COL_Z, COL_V, NCOL };
static const char *const col_names[NCOL] = {"x", "y", "z", "volume"};

static sph_status csv_header(reader *R, char *s, long line, int col[NCOL],
                             int *nfields) {
  char *b, *e;
  int k = 0;
  for (int j = 0; j < NCOL; ++j)
    col[j] = -1;
  while (next_field(&s, &b, &e)) {
    char save = *e;
    *e = '\0';
    char *end;
    strtod(b, &end);
    if (end != b && !*end) {
      *e = save;
      return fail(R, line,
                  "the first line must name the columns (x, y[, z][, "
                  "volume]), not hold numbers");
    }
    for (int j = 0; j < NCOL; ++j)
      if (!strcasecmp(b, col_names[j]) && col[j] < 0)
        col[j] = k;
    *e = save;
    ++k;
  }
  *nfields = k;
  for (int j = 0; j < 2; ++j)
    if (col[j] < 0)
      return fail(R, line, "no column '%s' in the header", col_names[j]);
  return SPH_OK;
}

static sph_status csv_row(reader *R, char *s, long line, const int col[NCOL],
                          int nfields) {
  double val[NCOL] = {0.0, 0.0, 0.0, 0.0};
  char *b, *e;
  int k = 0;
  while (next_field(&s, &b, &e)) {
    for (int j = 0; j < NCOL; ++j) {
      if (col[j] != k)
        continue;
      char save = *e, *end;
      *e = '\0';
      val[j] = strtod(b, &end);
      int number = end != b && !*end;
      *e = save;
      if (!number)
        return fail(R, line, "column '%s': not a number", col_names[j]);
      if (!isfinite(val[j]))
        return fail(R, line, "column '%s' is %g", col_names[j], val[j]);
    }
    ++k;
  }
  if (k != nfields)
    return sph_error_set(R->err, SPH_ERR_GEOMETRY,
                         "%s:%ld: %d values, the header names %d columns",
                         R->path, line, k, nfields);
  if (col[COL_V] >= 0 && !(val[COL_V] > 0.0))
    return fail(R, line, "column '%s' is %g: volumes must be positive",
                col_names[COL_V], val[COL_V]);
  if (!push(R, val, col[COL_V] >= 0 ? val[COL_V] : 0.0, line))
    return sph_error_set(R->err, SPH_ERR_NOMEM, "%s", R->path);
  return SPH_OK;
}

static sph_status read_csv(reader *R, char *text, int *has_z) {
  long line = 0;
  int col[NCOL] = {0}, nfields = 0, header = 0; /* col: set by csv_header */
  sph_status st = SPH_OK;
  for (char *s = text; s && st == SPH_OK;) {
    char *q = sph_text_line(&s, &line);
    if (!*q)
      continue;
    if (!header) {
      st = csv_header(R, q, line, col, &nfields);
      header = 1;
    } else {
      st = csv_row(R, q, line, col, nfields);
    }
  }
  if (st == SPH_OK && !header)
    st = fail(R, 0, "the file is empty");
  R->c->has_volume = header && col[COL_V] >= 0;
  *has_z = header && col[COL_Z] >= 0;
  return st;
}

static sph_status load_csv(reader *R, int *has_z) {
  FILE *f = fopen(R->path, "rb");
  if (!f)
    return sph_error_set(R->err, SPH_ERR_IO, "%s: no such file", R->path);
  char *text = malloc(CLOUD_MAX_BYTES + 1);
  size_t got = text ? fread(text, 1, CLOUD_MAX_BYTES + 1, f) : 0;
  fclose(f);
  if (!text)
    return sph_error_set(R->err, SPH_ERR_NOMEM, "%s", R->path);
  sph_status st = SPH_OK;
  if (got > CLOUD_MAX_BYTES || got == 0)
    st = sph_error_set(R->err, SPH_ERR_IO, "%s: %s", R->path,
                       got ? "larger than 1 GiB" : "the file is empty");
  else {
    text[got] = '\0';
    st = read_csv(R, text, has_z);
  }
  free(text);
  return st;
}

/* ---- .vtp ---------------------------------------------------------------- */

/* vtk_read's error (its file and line apart) as one message naming them */
static sph_status vtk_error(const reader *R, sph_status st) {
  if (st == SPH_OK || !R->err || !R->err->file[0])
    return st;
  char msg[sizeof R->err->message], file[sizeof R->err->file];
  int line = R->err->line;
  snprintf(msg, sizeof msg, "%s", R->err->message);
  snprintf(file, sizeof file, "%s", R->err->file);
  return line > 0 ? sph_error_set(R->err, st, "%s:%d: %s", file, line, msg)
                  : sph_error_set(R->err, st, "%s: %s", file, msg);
}

static sph_status load_vtp(reader *R) {
  sph_cloud *c = R->c;
  size_t n;
  int has;
  SPH_TRY(vtk_error(R, sph_vtp_count(R->path, "volume", &n, &has, R->err)));
  if (n == 0)
    return fail(R, 0, "no points");
  c->x = malloc(3 * n * sizeof *c->x);
  c->v = calloc(n, sizeof *c->v);
  if (!c->x || !c->v)
    return sph_error_set(R->err, SPH_ERR_NOMEM, "%s", R->path);
  double t;
  SPH_TRY(vtk_error(R, sph_vtp_read(R->path, n, c->x, has ? "volume" : NULL, 1,
                                    c->v, &t, R->err)));
  c->n = n;
  c->has_volume = has;
  int hasj = 0;
  SPH_TRY(vtk_error(R, sph_vtp_count(R->path, "J", &n, &hasj, R->err)));
  if (has && hasj) { /* a deformed state's volumes: J V0 */
    double *J = malloc(n * sizeof *J);
    if (!J)
      return sph_error_set(R->err, SPH_ERR_NOMEM, "%s", R->path);
    sph_status st = sph_vtp_read(R->path, n, c->x, "J", 1, J, &t, R->err);
    for (size_t i = 0; st == SPH_OK && i < n; ++i)
      c->v[i] *= J[i];
    free(J);
    SPH_TRY(vtk_error(R, st));
  }
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k)
      if (!isfinite(c->x[3 * i + k]))
        return sph_error_set(R->err, SPH_ERR_GEOMETRY,
                             "%s: point %zu: %s is %g", R->path, i,
                             col_names[k], c->x[3 * i + k]);
    if (has && !(c->v[i] > 0.0))
      return sph_error_set(R->err, SPH_ERR_GEOMETRY,
                           "%s: point %zu: volume is %g: volumes must be "
                           "positive",
                           R->path, i, c->v[i]);
  }
  return SPH_OK;
}

/* ---- checks -------------------------------------------------------------- */

/* where particle i is named: a CSV's line or a .vtp's point */
static void where(const reader *R, size_t i, char *buf, size_t size) {
  if (R->line)
    snprintf(buf, size, "line %ld", R->line[i]);
  else
    snprintf(buf, size, "point %zu", i);
}

typedef struct keyed {
  double x[3];
  size_t i;
} keyed;

static int cmp_keyed(const void *pa, const void *pb) {
  const keyed *a = pa, *b = pb;
  for (int k = 0; k < 3; ++k)
    if (a->x[k] != b->x[k])
      return a->x[k] < b->x[k] ? -1 : 1;
  return a->i < b->i ? -1 : a->i > b->i;
}

static sph_status check_distinct(const reader *R) {
  const sph_cloud *c = R->c;
  keyed *k = malloc(c->n * sizeof *k);
  if (!k)
    return sph_error_set(R->err, SPH_ERR_NOMEM, "%s", R->path);
  for (size_t i = 0; i < c->n; ++i) {
    memcpy(k[i].x, c->x + 3 * i, sizeof k[i].x);
    k[i].i = i;
  }
  qsort(k, c->n, sizeof *k, cmp_keyed);
  sph_status st = SPH_OK;
  for (size_t j = 1; j < c->n && st == SPH_OK; ++j)
    if (k[j].x[0] == k[j - 1].x[0] && k[j].x[1] == k[j - 1].x[1] &&
        k[j].x[2] == k[j - 1].x[2]) {
      char a[64], b[64];
      where(R, k[j - 1].i, a, sizeof a);
      where(R, k[j].i, b, sizeof b);
      st = sph_error_set(R->err, SPH_ERR_GEOMETRY,
                         "%s: two particles at one position (%g, %g, %g): "
                         "%s and %s",
                         R->path, k[j].x[0], k[j].x[1], k[j].x[2], a, b);
    }
  free(k);
  return st;
}

static sph_status check_dimension(const reader *R, int dim, int has_z) {
  const sph_cloud *c = R->c;
  size_t flat = 0;
  while (flat < c->n && c->x[3 * flat + 2] == 0.0)
    ++flat;
  if (dim == 3 && (!has_z || flat == c->n))
    return fail(R, 0, "a 2D file (%s) for a 3D body",
                has_z ? "every z is 0" : "no column 'z'");
  if (dim == 2 && flat < c->n) {
    char at[64];
    where(R, flat, at, sizeof at);
    return sph_error_set(R->err, SPH_ERR_GEOMETRY,
                         "%s: a 3D file (z is %g at %s) for a 2D body", R->path,
                         c->x[3 * flat + 2], at);
  }
  return SPH_OK;
}

/* ---- nearest neighbours -------------------------------------------------- */

typedef struct grid {
  long g[3];
  double lo[3], cell;
  size_t *start, *idx;
} grid;

static long cell_of(const grid *G, const double *X, int k) {
  long c = (long)floor((X[k] - G->lo[k]) / G->cell);
  return c < 0 ? 0 : c >= G->g[k] ? G->g[k] - 1 : c;
}

static size_t cell_id(const grid *G, const long c[3]) {
  return ((size_t)c[0] * (size_t)G->g[1] + (size_t)c[1]) * (size_t)G->g[2] +
         (size_t)c[2];
}

static int grid_build(grid *G, const sph_cloud *c, int dim) {
  double ext[3], box = 1.0, big = 0.0;
  for (int k = 0; k < 3; ++k) {
    G->lo[k] = c->lo[k];
    ext[k] = c->hi[k] - c->lo[k];
    big = fmax(big, ext[k]);
  }
  for (int k = 0; k < dim; ++k)
    box *= fmax(ext[k], 1e-6 * big);
  G->cell = pow(box / (double)c->n, 1.0 / dim);
  double cells;
  do {
    cells = 1.0;
    for (int k = 0; k < 3; ++k) {
      G->g[k] = k < dim ? (long)floor(ext[k] / G->cell) + 1 : 1;
      cells *= (double)G->g[k];
    }
    if (cells > 4.0 * (double)c->n + 64.0)
      G->cell *= 1.5;
  } while (cells > 4.0 * (double)c->n + 64.0);
  size_t nc = (size_t)cells;
  G->start = calloc(nc + 1, sizeof *G->start);
  G->idx = malloc(c->n * sizeof *G->idx);
  size_t *cid = malloc(c->n * sizeof *cid);
  if (!G->start || !G->idx || !cid) {
    free(cid);
    return 0;
  }
  for (size_t i = 0; i < c->n; ++i) {
    long cc[3];
    for (int k = 0; k < 3; ++k)
      cc[k] = cell_of(G, c->x + 3 * i, k);
    cid[i] = cell_id(G, cc);
    G->start[cid[i] + 1]++;
  }
  for (size_t q = 0; q < nc; ++q)
    G->start[q + 1] += G->start[q];
  for (size_t i = 0; i < c->n; ++i) /* counting sort, stable */
    G->idx[G->start[cid[i]]++] = i;
  for (size_t q = nc; q > 0; --q)
    G->start[q] = G->start[q - 1];
  G->start[0] = 0;
  free(cid);
  return 1;
}

/* the distance from particle i to its nearest neighbour: shells of cells
 * at growing Chebyshev distance r until the best is within r cells */
static double nearest(const grid *G, const sph_cloud *c, size_t i) {
  const double *X = c->x + 3 * i;
  long ci[3], gmax = 0;
  for (int k = 0; k < 3; ++k) {
    ci[k] = cell_of(G, X, k);
    gmax = G->g[k] > gmax ? G->g[k] : gmax;
  }
  double best2 = INFINITY;
  for (long r = 0; r <= gmax; ++r) {
    long a[3];
    for (a[0] = ci[0] - r; a[0] <= ci[0] + r; ++a[0])
      for (a[1] = ci[1] - r; a[1] <= ci[1] + r; ++a[1])
        for (a[2] = ci[2] - r; a[2] <= ci[2] + r; ++a[2]) {
          long m = 0;
          int ok = 1;
          for (int k = 0; k < 3; ++k) {
            long d = labs(a[k] - ci[k]);
            m = d > m ? d : m;
            ok = ok && a[k] >= 0 && a[k] < G->g[k];
          }
          if (!ok || m != r)
            continue;
          size_t q = cell_id(G, a);
          for (size_t s = G->start[q]; s < G->start[q + 1]; ++s) {
            size_t j = G->idx[s];
            const double *Y = c->x + 3 * j;
            double d2 = (X[0] - Y[0]) * (X[0] - Y[0]) +
                        (X[1] - Y[1]) * (X[1] - Y[1]) +
                        (X[2] - Y[2]) * (X[2] - Y[2]);
            if (j != i && d2 < best2)
              best2 = d2;
          }
        }
    if (sqrt(best2) <= (double)r * G->cell)
      break;
  }
  return sqrt(best2);
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static sph_status nn_median(const reader *R, int dim) {
  sph_cloud *c = R->c;
  c->nn_median = 0.0;
  if (c->n < 2)
    return SPH_OK;
  grid G = {0};
  double *d = malloc(c->n * sizeof *d);
  sph_status st = d && grid_build(&G, c, dim)
                      ? SPH_OK
                      : sph_error_set(R->err, SPH_ERR_NOMEM, "%s", R->path);
  for (size_t i = 0; st == SPH_OK && i < c->n; ++i)
    d[i] = nearest(&G, c, i);
  if (st == SPH_OK) {
    qsort(d, c->n, sizeof *d, cmp_double);
    c->nn_median = d[(c->n - 1) / 2];
  }
  free(d);
  free(G.start);
  free(G.idx);
  return st;
}

/* ---- lattice steps ------------------------------------------------------- */

/* the file's lattice, if it is one: on each axis the smallest gap between
 * coordinates, every coordinate a whole number of them from the lowest
 * (to 1e-6); else step[] stays 0 */
static sph_status lattice_steps(const reader *R, int dim) {
  sph_cloud *c = R->c;
  double *v = malloc(c->n * sizeof *v), step[3] = {0.0, 0.0, 0.0};
  if (!v)
    return sph_error_set(R->err, SPH_ERR_NOMEM, "%s", R->path);
  int lattice = 1;
  for (int k = 0; k < dim && lattice; ++k) {
    for (size_t i = 0; i < c->n; ++i)
      v[i] = c->x[3 * i + k];
    qsort(v, c->n, sizeof *v, cmp_double);
    step[k] = INFINITY;
    for (size_t i = 1; i < c->n; ++i)
      if (v[i] > v[i - 1])
        step[k] = fmin(step[k], v[i] - v[i - 1]);
    lattice = isfinite(step[k]);
    for (size_t i = 0; i < c->n && lattice; ++i) {
      double r = (v[i] - v[0]) / step[k];
      lattice = fabs(r - round(r)) <= 1e-6;
    }
  }
  for (int k = 0; k < 3; ++k)
    c->step[k] = lattice ? step[k] : 0.0;
  free(v);
  return SPH_OK;
}

/* ---- the file ------------------------------------------------------------ */

static int has_ext(const char *path, const char *ext) {
  size_t len = strlen(path), e = strlen(ext);
  return len > e && !strcasecmp(path + len - e, ext);
}

sph_status sph_cloud_read(const char *path, int dim, double scale,
                          sph_cloud **out, sph_error *err) {
  *out = NULL;
  int vtp = has_ext(path, ".vtp") || has_ext(path, ".pvtp");
  if (!vtp && !has_ext(path, ".csv") && !has_ext(path, ".txt"))
    return sph_error_set(err, SPH_ERR_IO,
                         "%s: a particle file is a .csv or a .vtp", path);
  sph_cloud *c = calloc(1, sizeof *c);
  if (!c)
    return sph_error_set(err, SPH_ERR_NOMEM, "%s", path);
  reader R = {.c = c, .path = path, .err = err};
  int has_z = 1;
  sph_status st = vtp ? load_vtp(&R) : load_csv(&R, &has_z);
  if (st == SPH_OK && c->n == 0)
    st = fail(&R, 0, "no particles");
  if (st == SPH_OK)
    st = check_dimension(&R, dim, has_z);
  if (st == SPH_OK)
    st = check_distinct(&R);
  double vs = scale * scale * (dim == 3 ? scale : 1.0);
  for (size_t i = 0; st == SPH_OK && i < c->n; ++i) {
    for (int k = 0; k < 3; ++k)
      c->x[3 * i + k] *= scale;
    c->v[i] *= vs;
  }
  for (int k = 0; k < 3 && st == SPH_OK; ++k) {
    c->lo[k] = INFINITY;
    c->hi[k] = -INFINITY;
    for (size_t i = 0; i < c->n; ++i) {
      c->lo[k] = fmin(c->lo[k], c->x[3 * i + k]);
      c->hi[k] = fmax(c->hi[k], c->x[3 * i + k]);
    }
  }
  if (st == SPH_OK)
    st = nn_median(&R, dim);
  if (st == SPH_OK)
    st = lattice_steps(&R, dim);
  free(R.line);
  if (st != SPH_OK) {
    sph_cloud_destroy(c);
    return st;
  }
  *out = c;
  return SPH_OK;
}

void sph_cloud_set_volumes(sph_cloud *c, int dim, double dp) {
  if (c->has_volume)
    return;
  for (size_t i = 0; i < c->n; ++i)
    c->v[i] = dim == 3 ? dp * dp * dp : dp * dp;
}

double sph_cloud_volume(const sph_cloud *c) {
  double v = 0.0;
  for (size_t i = 0; i < c->n; ++i)
    v += c->v[i];
  return v;
}

void sph_cloud_destroy(sph_cloud *c) {
  if (!c)
    return;
  free(c->x);
  free(c->v);
  free(c);
}
