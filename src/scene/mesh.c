/* Triangle meshes as body shapes (mesh.h): size, signed volume (divergence
 * theorem, sum of (a x b) . c / 6 about the box centre), open edges
 * (corners welded where they are equal) and the inside test: ray parity
 * along x, y and z, the majority of the three deciding. A ray at (u, v)
 * across the axis is moved to (u + d, v + d^2), d -> 0 (simulation of
 * simplicity, Edelsbrunner and Muecke 1990): each edge is evaluated with its
 * ends in one order, so a ray on an edge or a vertex crosses exactly one of
 * the triangles that share it. */
#include "scene/mesh.h"

#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* the triangles of one axis's 2D grid of projected boxes (CSR) */
typedef struct axis_grid {
  int a, u, v;   /* ray axis, the two across it */
  long g[2];     /* cells along u and v */
  double lo[2];  /* grid origin */
  double h[2];   /* cell sizes */
  size_t *start; /* g0 g1 + 1 */
  uint32_t *tri;
  size_t maxcell; /* most triangles in one cell */
} axis_grid;

struct sph_mesh {
  double *tri; /* 9 a triangle */
  size_t n;
  sph_mesh_info info;
  axis_grid grid[3];
};

/* ---- exact-on-edges tests ------------------------------------------------ */

/* which side of edge ab the ray p + (d, d^2) passes: +1 or -1 (0 only for
 * a == b); the ends taken in lexicographic order, the sign restored after */
static int side(const double a[2], const double b[2], const double p[2]) {
  int swap = a[0] > b[0] || (a[0] == b[0] && a[1] > b[1]);
  const double *s = swap ? b : a, *t = swap ? a : b;
  double e = (t[0] - s[0]) * (p[1] - s[1]) - (t[1] - s[1]) * (p[0] - s[0]);
  int sg;
  if (e != 0.0)
    sg = e > 0.0 ? 1 : -1;
  else if (t[1] != s[1]) /* the d term: -(t1 - s1) d */
    sg = t[1] < s[1] ? 1 : -1;
  else if (t[0] != s[0]) /* the d^2 term: (t0 - s0) d^2, t0 > s0 */
    sg = 1;
  else
    sg = 0;
  return swap ? -sg : sg;
}

static double orient(const double a[2], const double b[2], const double p[2]) {
  return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
}

/* whether the ray along axis g->a through p (across it) crosses triangle
 * T, and where (*x, along the axis) */
static int crossing(const axis_grid *g, const double *T, const double p[2],
                    double *x) {
  int u = g->u, v = g->v, a = g->a;
  const double A[2] = {T[u], T[v]}, B[2] = {T[3 + u], T[3 + v]},
               C[2] = {T[6 + u], T[6 + v]};
  int s0 = side(B, C, p), s1 = side(C, A, p), s2 = side(A, B, p);
  if (s0 == 0 || s0 != s1 || s1 != s2)
    return 0;
  double w0 = orient(B, C, p), w1 = orient(C, A, p), w2 = orient(A, B, p);
  double sum = w0 + w1 + w2;
  *x = sum != 0.0 ? (w0 * T[a] + w1 * T[3 + a] + w2 * T[6 + a]) / sum
                  : (T[a] + T[3 + a] + T[6 + a]) / 3.0;
  return 1;
}

/* ---- grids --------------------------------------------------------------- */

static long cell_of(double x, double lo, double h, long g) {
  double f = floor((x - lo) / h);
  if (!(f >= 0.0))
    return 0;
  return f >= (double)g ? g - 1 : (long)f;
}

/* the cell ranges of triangle t's projected box; 0 when its projection has
 * no area (no ray crosses it) */
static int tri_cells(const axis_grid *g, const double *T, long c0[2],
                     long c1[2]) {
  const double A[2] = {T[g->u], T[g->v]}, B[2] = {T[3 + g->u], T[3 + g->v]},
               C[2] = {T[6 + g->u], T[6 + g->v]};
  if (orient(A, B, C) == 0.0)
    return 0;
  for (int k = 0; k < 2; ++k) {
    double lo = fmin(A[k], fmin(B[k], C[k])), hi = fmax(A[k], fmax(B[k], C[k]));
    c0[k] = cell_of(lo, g->lo[k], g->h[k], g->g[k]);
    c1[k] = cell_of(hi, g->lo[k], g->h[k], g->g[k]);
  }
  return 1;
}

static sph_status grid_build(sph_mesh *m, int a, sph_error *err) {
  axis_grid *g = &m->grid[a];
  g->a = a;
  g->u = (a + 1) % 3;
  g->v = (a + 2) % 3;
  int ax[2] = {g->u, g->v};
  double L[2], cells = 2.0 * (double)m->n;
  for (int k = 0; k < 2; ++k) {
    g->lo[k] = m->info.lo[ax[k]];
    L[k] = m->info.hi[ax[k]] - g->lo[k];
  }
  for (int k = 0; k < 2; ++k) {
    double want =
        L[0] > 0.0 && L[1] > 0.0 ? sqrt(cells * L[k] / L[1 - k]) : 1.0;
    g->g[k] = want < 1.0 ? 1 : want > 2048.0 ? 2048 : (long)want;
    g->h[k] = L[k] > 0.0 ? L[k] / (double)g->g[k] : 1.0;
  }
  size_t ncell = (size_t)(g->g[0] * g->g[1]);
  g->start = calloc(ncell + 1, sizeof *g->start);
  if (!g->start)
    return sph_error_set(err, SPH_ERR_NOMEM, "mesh grid");
  long c0[2], c1[2];
  for (size_t t = 0; t < m->n; ++t)
    if (tri_cells(g, m->tri + 9 * t, c0, c1))
      for (long i = c0[0]; i <= c1[0]; ++i)
        for (long j = c0[1]; j <= c1[1]; ++j)
          g->start[(size_t)(i * g->g[1] + j) + 1]++;
  for (size_t c = 0; c < ncell; ++c) {
    g->maxcell = g->start[c + 1] > g->maxcell ? g->start[c + 1] : g->maxcell;
    g->start[c + 1] += g->start[c];
  }
  g->tri = malloc((g->start[ncell] + 1) * sizeof *g->tri);
  size_t *fill = malloc(ncell * sizeof *fill);
  if (!g->tri || !fill) {
    free(fill);
    return sph_error_set(err, SPH_ERR_NOMEM, "mesh grid");
  }
  memcpy(fill, g->start, ncell * sizeof *fill);
  for (size_t t = 0; t < m->n; ++t)
    if (tri_cells(g, m->tri + 9 * t, c0, c1))
      for (long i = c0[0]; i <= c1[0]; ++i)
        for (long j = c0[1]; j <= c1[1]; ++j)
          g->tri[fill[i * g->g[1] + j]++] = (uint32_t)t;
  free(fill);
  return SPH_OK;
}

/* the crossings of the ray through p (across axis g->a) into buf */
static size_t ray_crossings(const sph_mesh *m, const axis_grid *g,
                            const double p[2], double *buf) {
  long i = cell_of(p[0], g->lo[0], g->h[0], g->g[0]);
  long j = cell_of(p[1], g->lo[1], g->h[1], g->g[1]);
  size_t c = (size_t)(i * g->g[1] + j), k = 0;
  for (size_t q = g->start[c]; q < g->start[c + 1]; ++q)
    k += crossing(g, m->tri + 9 * (size_t)g->tri[q], p, buf + k);
  return k;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* ---- size and soundness -------------------------------------------------- */

typedef struct corner {
  double p[3];
  size_t i;
} corner;

static int cmp_corner(const void *a, const void *b) {
  const corner *x = a, *y = b;
  for (int c = 0; c < 3; ++c)
    if (x->p[c] != y->p[c])
      return x->p[c] < y->p[c] ? -1 : 1;
  return (x->i > y->i) - (x->i < y->i);
}

typedef struct edge {
  size_t a, b;
} edge;

static int cmp_edge(const void *x, const void *y) {
  const edge *e = x, *f = y;
  if (e->a != f->a)
    return e->a < f->a ? -1 : 1;
  return (e->b > f->b) - (e->b < f->b);
}

/* edges of exactly one triangle, corners welded where equal */
static sph_status count_open_edges(sph_mesh *m, sph_error *err) {
  size_t nc = 3 * m->n;
  corner *cs = malloc(nc * sizeof *cs);
  size_t *id = malloc(nc * sizeof *id);
  edge *es = malloc(nc * sizeof *es);
  if (!cs || !id || !es) {
    free(cs);
    free(id);
    free(es);
    return sph_error_set(err, SPH_ERR_NOMEM, "mesh edges");
  }
  for (size_t k = 0; k < nc; ++k) {
    memcpy(cs[k].p, m->tri + 3 * k, sizeof cs[k].p);
    cs[k].i = k;
  }
  qsort(cs, nc, sizeof *cs, cmp_corner);
  size_t next = 0;
  for (size_t k = 0; k < nc; ++k) {
    if (k > 0 && memcmp(cs[k].p, cs[k - 1].p, sizeof cs[k].p) != 0)
      ++next;
    id[cs[k].i] = next;
  }
  size_t ne = 0;
  for (size_t t = 0; t < m->n; ++t)
    for (int e = 0; e < 3; ++e) {
      size_t p = id[3 * t + e], q = id[3 * t + (e + 1) % 3];
      if (p != q)
        es[ne++] = (edge){p < q ? p : q, p < q ? q : p};
    }
  qsort(es, ne, sizeof *es, cmp_edge);
  m->info.open_edges = 0;
  for (size_t k = 0; k < ne;) {
    size_t r = k + 1;
    while (r < ne && es[r].a == es[k].a && es[r].b == es[k].b)
      ++r;
    m->info.open_edges += r - k == 1;
    k = r;
  }
  free(cs);
  free(id);
  free(es);
  return SPH_OK;
}

static void measure(sph_mesh *m) {
  sph_mesh_info *in = &m->info;
  for (int c = 0; c < 3; ++c) {
    in->lo[c] = INFINITY;
    in->hi[c] = -INFINITY;
  }
  for (size_t k = 0; k < 3 * m->n; ++k)
    for (int c = 0; c < 3; ++c) {
      in->lo[c] = fmin(in->lo[c], m->tri[3 * k + c]);
      in->hi[c] = fmax(in->hi[c], m->tri[3 * k + c]);
    }
  double o[3], vol = 0.0;
  for (int c = 0; c < 3; ++c)
    o[c] = 0.5 * (in->lo[c] + in->hi[c]);
  for (size_t t = 0; t < m->n; ++t) {
    const double *T = m->tri + 9 * t;
    double a[3], b[3], c[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = T[k] - o[k];
      b[k] = T[3 + k] - o[k];
      c[k] = T[6 + k] - o[k];
    }
    vol += (a[1] * b[2] - a[2] * b[1]) * c[0] +
           (a[2] * b[0] - a[0] * b[2]) * c[1] +
           (a[0] * b[1] - a[1] * b[0]) * c[2];
  }
  in->volume = vol / 6.0;
}

/* ---- life cycle ---------------------------------------------------------- */

sph_status sph_mesh_create(sph_mesh **out, const double *tri, size_t n,
                           double scale, int flip, sph_error *err) {
  *out = NULL;
  if (n == 0)
    return sph_error_set(err, SPH_ERR_GEOMETRY, "the mesh has no triangles");
  if (n > UINT32_MAX / 2)
    return sph_error_set(err, SPH_ERR_GEOMETRY,
                         "the mesh has %zu triangles, more than sph takes", n);
  sph_mesh *m = calloc(1, sizeof *m);
  if (!m || !(m->tri = malloc(9 * n * sizeof *m->tri))) {
    free(m);
    return sph_error_set(err, SPH_ERR_NOMEM, "mesh");
  }
  m->n = n;
  m->info.triangles = n;
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) {
      int from = flip && k ? 3 - k : k; /* flipped: a, c, b */
      for (int c = 0; c < 3; ++c) {
        double x = tri[9 * t + 3 * from + c] * scale;
        if (!isfinite(x)) {
          sph_mesh_destroy(m);
          return sph_error_set(err, SPH_ERR_GEOMETRY,
                               "triangle %zu has a coordinate that is not a "
                               "finite number",
                               t + 1);
        }
        m->tri[9 * t + 3 * k + c] = x;
      }
    }
  measure(m);
  sph_status st = count_open_edges(m, err);
  for (int a = 0; st == SPH_OK && a < 3; ++a)
    st = grid_build(m, a, err);
  if (st != SPH_OK) {
    sph_mesh_destroy(m);
    return st;
  }
  *out = m;
  return SPH_OK;
}

void sph_mesh_destroy(sph_mesh *m) {
  if (!m)
    return;
  for (int a = 0; a < 3; ++a) {
    free(m->grid[a].start);
    free(m->grid[a].tri);
  }
  free(m->tri);
  free(m);
}

const sph_mesh_info *sph_mesh_get_info(const sph_mesh *m) { return &m->info; }

/* ---- inside -------------------------------------------------------------- */

int sph_mesh_inside(const sph_mesh *m, const double X[3]) {
  int votes = 0;
  for (int a = 0; a < 3; ++a) {
    const axis_grid *g = &m->grid[a];
    double p[2] = {X[g->u], X[g->v]};
    long i = cell_of(p[0], g->lo[0], g->h[0], g->g[0]);
    long j = cell_of(p[1], g->lo[1], g->h[1], g->g[1]);
    size_t c = (size_t)(i * g->g[1] + j);
    int odd = 0;
    for (size_t q = g->start[c]; q < g->start[c + 1]; ++q) {
      double x;
      if (crossing(g, m->tri + 9 * (size_t)g->tri[q], p, &x) && x > X[a])
        odd ^= 1;
    }
    votes += odd;
  }
  return votes >= 2;
}

sph_status sph_mesh_inside_lattice(const sph_mesh *m, const long n[3],
                                   const double *const x[3],
                                   unsigned char *inside, sph_error *err) {
  size_t total = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
  memset(inside, 0, total);
  size_t maxcell = 1;
  for (int a = 0; a < 3; ++a)
    maxcell = m->grid[a].maxcell > maxcell ? m->grid[a].maxcell : maxcell;
  int nt = omp_get_max_threads();
  double *bufs = malloc((size_t)nt * maxcell * sizeof *bufs);
  if (!bufs)
    return sph_error_set(err, SPH_ERR_NOMEM, "mesh rays");
  const size_t stride[3] = {(size_t)n[1] * (size_t)n[2], (size_t)n[2], 1};
  for (int a = 0; a < 3; ++a) {
    const axis_grid *g = &m->grid[a];
    long rows = n[g->u] * n[g->v];
#pragma omp parallel num_threads(nt)
    {
      double *buf = bufs + (size_t)omp_get_thread_num() * maxcell;
#pragma omp for schedule(dynamic, 64)
      for (long r = 0; r < rows; ++r) {
        long iu = r / n[g->v], iv = r % n[g->v];
        double p[2] = {x[g->u][iu], x[g->v][iv]};
        size_t k = ray_crossings(m, g, p, buf), past = 0;
        qsort(buf, k, sizeof *buf, cmp_double);
        size_t base = (size_t)iu * stride[g->u] + (size_t)iv * stride[g->v];
        for (long ia = 0; ia < n[a]; ++ia) {
          while (past < k && buf[past] <= x[a][ia])
            ++past;
          inside[base + (size_t)ia * stride[a]] += (k - past) & 1;
        }
      }
    }
  }
  for (size_t q = 0; q < total; ++q)
    inside[q] = inside[q] >= 2;
  free(bufs);
  return SPH_OK;
}

/* ---- distance ------------------------------------------------------------ */

static double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* squared distance from p to triangle abc (closest point by its Voronoi
 * regions, Ericson, Real-Time Collision Detection, sec. 5.1.5) */
static double tri_dist2(const double p[3], const double *T) {
  const double *a = T, *b = T + 3, *c = T + 6;
  double ab[3], ac[3], ap[3], bp[3], cp[3], q[3];
  for (int k = 0; k < 3; ++k) {
    ab[k] = b[k] - a[k];
    ac[k] = c[k] - a[k];
    ap[k] = p[k] - a[k];
    bp[k] = p[k] - b[k];
    cp[k] = p[k] - c[k];
  }
  double d1 = dot3(ab, ap), d2 = dot3(ac, ap), d3 = dot3(ab, bp),
         d4 = dot3(ac, bp), d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
  double u = 0.0, w = 0.0; /* q = a + u ab + w ac */
  if (d1 <= 0.0 && d2 <= 0.0) {
  } else if (d3 >= 0.0 && d4 <= d3) {
    u = 1.0;
  } else if (d6 >= 0.0 && d5 <= d6) {
    w = 1.0;
  } else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    u = d1 / (d1 - d3);
  } else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    w = d2 / (d2 - d6);
  } else if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    u = 1.0 - w;
  } else {
    double den = va + vb + vc;
    u = den != 0.0 ? vb / den : 0.0;
    w = den != 0.0 ? vc / den : 0.0;
  }
  double d2sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    q[k] = a[k] + u * ab[k] + w * ac[k] - p[k];
    d2sum += q[k] * q[k];
  }
  return d2sum;
}

double sph_mesh_distance(const sph_mesh *m, const double X[3]) {
  double best = INFINITY;
  for (size_t t = 0; t < m->n; ++t) {
    const double *T = m->tri + 9 * t;
    double out = 0.0; /* to the triangle's box: a lower bound */
    for (int c = 0; c < 3; ++c) {
      double lo = fmin(T[c], fmin(T[3 + c], T[6 + c]));
      double hi = fmax(T[c], fmax(T[3 + c], T[6 + c]));
      double d = X[c] < lo ? lo - X[c] : X[c] > hi ? X[c] - hi : 0.0;
      out += d * d;
    }
    if (out < best)
      best = fmin(best, tri_dist2(X, T));
  }
  return sqrt(best);
}
