/* Neighbour search: cell lists (cell size >= search radius) into compact CSR
 * lists, deterministic for any thread count (each particle's list is sorted
 * by index). docs/design.md sec. 5. */
#include "core/neighbors.h"

#include "core/check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Cells per particle beyond which the cell size grows (bounds memory for
 * sparse clouds). */
#define CELLS_PER_PARTICLE_MAX 8

sph_status sph_neighbors_create(sph_neighbors **out, sph_error *err) {
  *out = calloc(1, sizeof **out);
  if (!*out)
    return sph_error_set(err, SPH_ERR_NOMEM, "neighbour list");
  return SPH_OK;
}

void sph_neighbors_destroy(sph_neighbors *nl) {
  if (!nl)
    return;
  free(nl->offset);
  free(nl->index);
  free(nl->cell_start);
  free(nl->cell_particles);
  free(nl->particle_cell);
  free(nl);
}

static int cmp_int32(const void *a, const void *b) {
  int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
  return (x > y) - (x < y);
}

/* ascending; insertion sort for the usual list of tens of entries */
static void sort_list(int32_t *v, size_t k) {
  if (k > 256) {
    qsort(v, k, sizeof *v, cmp_int32);
    return;
  }
  for (size_t i = 1; i < k; ++i) {
    int32_t x = v[i];
    size_t j = i;
    for (; j > 0 && v[j - 1] > x; --j)
      v[j] = v[j - 1];
    v[j] = x;
  }
}

static sph_status grow(void **p, size_t *cap, size_t need, size_t elem,
                       sph_error *err, const char *what) {
  if (need <= *cap && *p)
    return SPH_OK;
  size_t c = need + need / 4 + 16;
  void *q = realloc(*p, c * elem);
  if (!q)
    return sph_error_set(err, SPH_ERR_NOMEM, "neighbour %s (%zu entries)", what,
                         c);
  *p = q;
  *cap = c;
  return SPH_OK;
}

static sph_status check_args(size_t n, int dim, double radius,
                             const int32_t *body, sph_pair_filter filter,
                             sph_error *err) {
  if (dim < 1 || dim > 3)
    return sph_error_set(err, SPH_ERR_ARG, "dimension %d is not 1, 2 or 3",
                         dim);
  if (!(radius > 0.0) || !isfinite(radius))
    return sph_error_set(err, SPH_ERR_ARG, "search radius %g is not positive",
                         radius);
  if (filter != SPH_PAIRS_ALL && !body)
    return sph_error_set(err, SPH_ERR_ARG, "a body filter needs body ids");
  if (n > (size_t)INT32_MAX)
    return sph_error_set(err, SPH_ERR_ARG, "%zu particles exceed 2^31", n);
  return SPH_OK;
}

static inline int pair_kept(const int32_t *body, sph_pair_filter filter,
                            size_t a, size_t b) {
  return filter == SPH_PAIRS_ALL ||
         (filter == SPH_PAIRS_SAME_BODY) == (body[a] == body[b]);
}

static inline double dist2(const double *x, size_t a, size_t b, int dim) {
  double s = 0.0;
  for (int c = 0; c < dim; ++c) {
    double d = x[3 * a + c] - x[3 * b + c];
    s += d * d;
  }
  return s;
}

/* Offsets from per-particle counts stored in offset[1..n]. */
static sph_status finish_offsets(sph_neighbors *nl, size_t n, sph_error *err) {
  nl->offset[0] = 0;
  for (size_t a = 0; a < n; ++a)
    nl->offset[a + 1] += nl->offset[a];
  nl->n = n;
  nl->count = nl->offset[n];
  SPH_TRY(grow((void **)&nl->index, &nl->capacity, nl->count ? nl->count : 1,
               sizeof *nl->index, err, "indices"));
  SPH_CHECK(nl->n <= nl->capacity_n && nl->count <= nl->capacity, err,
            "neighbour lists of %zu particles, %zu pairs exceed their "
            "buffers (%zu, %zu)",
            nl->n, nl->count, nl->capacity_n, nl->capacity);
  return SPH_OK;
}

static sph_status reserve_offsets(sph_neighbors *nl, size_t n, sph_error *err) {
  size_t cap = nl->capacity_n ? nl->capacity_n + 1 : 0;
  sph_status st = grow((void **)&nl->offset, &cap, n + 1, sizeof *nl->offset,
                       err, "offsets");
  if (st == SPH_OK)
    nl->capacity_n = cap - 1;
  return st;
}

sph_status sph_neighbors_build_brute(sph_neighbors *nl, const double *x,
                                     size_t n, int dim, double radius,
                                     const int32_t *body,
                                     sph_pair_filter filter, sph_error *err) {
  sph_status st = check_args(n, dim, radius, body, filter, err);
  if (st == SPH_OK)
    st = reserve_offsets(nl, n, err);
  if (st != SPH_OK)
    return st;
  double r2 = radius * radius;
  for (size_t a = 0; a < n; ++a) {
    size_t k = 0;
    for (size_t b = 0; b < n; ++b)
      if (b != a && pair_kept(body, filter, a, b) && dist2(x, a, b, dim) < r2)
        ++k;
    nl->offset[a + 1] = k;
  }
  if ((st = finish_offsets(nl, n, err)) != SPH_OK)
    return st;
  for (size_t a = 0; a < n; ++a) {
    size_t k = nl->offset[a];
    for (size_t b = 0; b < n; ++b)
      if (b != a && pair_kept(body, filter, a, b) && dist2(x, a, b, dim) < r2)
        nl->index[k++] = (int32_t)b;
  }
  SPH_DEBUG_TRY(sph_neighbors_check(nl, x, dim, radius, err));
  return SPH_OK;
}

double sph_neighbors_grid(const double lo[3], const double hi[3], size_t n,
                          int dim, double radius, long nc[3]) {
  /* cell counts in double first: a span of 1e19 m over a 1 mm cell does
   * not fit a long */
  double cell = radius, limit = (double)(CELLS_PER_PARTICLE_MAX * n + 64);
  double count[3];
  for (;;) {
    double total = 1.0;
    for (int c = 0; c < 3; ++c) {
      count[c] = c < dim ? floor((hi[c] - lo[c]) / cell) + 1.0 : 1.0;
      total *= count[c];
    }
    if (total <= limit)
      break;
    cell *= 1.5;
  }
  for (int c = 0; c < 3; ++c)
    nc[c] = (long)count[c];
  return cell;
}

/* Grid over the bounding box; cell size >= radius. */
typedef struct grid {
  double lo[3];
  double cell;
  long nc[3];
} grid;

static sph_status grid_setup(grid *g, const double *x, size_t n, int dim,
                             double radius, sph_error *err) {
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int c = 0; c < dim; ++c) {
    lo[c] = n ? x[c] : 0.0;
    hi[c] = lo[c];
  }
  for (size_t i = 1; i < n; ++i)
    for (int c = 0; c < dim; ++c) {
      double v = x[3 * i + c];
      lo[c] = v < lo[c] ? v : lo[c];
      hi[c] = v > hi[c] ? v : hi[c];
    }
  for (int c = 0; c < dim; ++c)
    if (!isfinite(hi[c] - lo[c]))
      return sph_error_set(err, SPH_ERR_NUMERIC,
                           "neighbour search: particle positions are not "
                           "finite or span more than a double can hold");
  g->cell = sph_neighbors_grid(lo, hi, n, dim, radius, g->nc);
  memcpy(g->lo, lo, sizeof lo);
  return SPH_OK;
}

static inline long grid_coord(const grid *g, double v, int c) {
  double k = floor((v - g->lo[c]) / g->cell);
  if (!(k > 0.0)) /* also NaN */
    return 0;
  return k >= (double)g->nc[c] ? g->nc[c] - 1 : (long)k;
}

/* Visits the particles of the 3^dim cells around a, in a fixed order,
 * counting (out == NULL) or writing the kept neighbours. */
static size_t scan(const sph_neighbors *nl, const grid *g, const double *x,
                   size_t a, int dim, double r2, const int32_t *body,
                   sph_pair_filter filter, int32_t *out) {
  long ca[3] = {0, 0, 0};
  for (int c = 0; c < dim; ++c)
    ca[c] = grid_coord(g, x[3 * a + c], c);
  long lo[3], hi[3];
  for (int c = 0; c < 3; ++c) {
    lo[c] = ca[c] > 0 ? ca[c] - 1 : 0;
    hi[c] = ca[c] + 1 < g->nc[c] ? ca[c] + 1 : g->nc[c] - 1;
  }
  size_t k = 0;
  for (long i = lo[0]; i <= hi[0]; ++i)
    for (long j = lo[1]; j <= hi[1]; ++j)
      for (long l = lo[2]; l <= hi[2]; ++l) {
        size_t cell = (size_t)((i * g->nc[1] + j) * g->nc[2] + l);
        for (size_t s = nl->cell_start[cell]; s < nl->cell_start[cell + 1];
             ++s) {
          size_t b = (size_t)nl->cell_particles[s];
          if (b == a || !pair_kept(body, filter, a, b) ||
              dist2(x, a, b, dim) >= r2)
            continue;
          if (out)
            out[k] = (int32_t)b;
          ++k;
        }
      }
  return k;
}

sph_status sph_neighbors_build(sph_neighbors *nl, const double *x, size_t n,
                               int dim, double radius, const int32_t *body,
                               sph_pair_filter filter, sph_error *err) {
  sph_status st = check_args(n, dim, radius, body, filter, err);
  if (st == SPH_OK)
    st = reserve_offsets(nl, n, err);
  if (st != SPH_OK)
    return st;
  grid g;
  if ((st = grid_setup(&g, x, n, dim, radius, err)) != SPH_OK)
    return st;
  size_t ncell = (size_t)(g.nc[0] * g.nc[1] * g.nc[2]);

  /* counting sort of particles into cells (stable: ascending within a cell) */
  size_t cap = nl->ncell_alloc;
  st = grow((void **)&nl->cell_start, &cap, ncell + 1, sizeof(size_t), err,
            "cells");
  if (st != SPH_OK)
    return st;
  nl->ncell_alloc = cap;
  size_t pcap = nl->np_alloc, pcap2 = nl->np_alloc;
  st = grow((void **)&nl->particle_cell, &pcap, n ? n : 1, sizeof(int32_t), err,
            "cell ids");
  if (st == SPH_OK)
    st = grow((void **)&nl->cell_particles, &pcap2, n ? n : 1, sizeof(int32_t),
              err, "cell members");
  if (st != SPH_OK)
    return st;
  nl->np_alloc = pcap < pcap2 ? pcap : pcap2;

  memset(nl->cell_start, 0, (ncell + 1) * sizeof(size_t));
  for (size_t a = 0; a < n; ++a) {
    long c3[3] = {0, 0, 0};
    for (int c = 0; c < dim; ++c)
      c3[c] = grid_coord(&g, x[3 * a + c], c);
    size_t cell = (size_t)((c3[0] * g.nc[1] + c3[1]) * g.nc[2] + c3[2]);
    nl->particle_cell[a] = (int32_t)cell;
    nl->cell_start[cell + 1]++;
  }
  for (size_t c = 0; c < ncell; ++c)
    nl->cell_start[c + 1] += nl->cell_start[c];
  /* place particles, advancing each cell's start, then shift starts back */
  for (size_t a = 0; a < n; ++a) {
    size_t cell = (size_t)nl->particle_cell[a];
    nl->cell_particles[nl->cell_start[cell]++] = (int32_t)a;
  }
  for (size_t c = ncell; c > 0; --c)
    nl->cell_start[c] = nl->cell_start[c - 1];
  nl->cell_start[0] = 0;

  double r2 = radius * radius;
  long nn = (long)n;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < nn; ++a)
    nl->offset[a + 1] = scan(nl, &g, x, (size_t)a, dim, r2, body, filter, NULL);
  if ((st = finish_offsets(nl, n, err)) != SPH_OK)
    return st;
  long short_list = nn; /* the first list whose fill differs from its count */
#pragma omp parallel for schedule(static) reduction(min : short_list)
  for (long a = 0; a < nn; ++a) {
    int32_t *list = nl->index + nl->offset[a];
    size_t k = scan(nl, &g, x, (size_t)a, dim, r2, body, filter, list);
    if (k != nl->offset[a + 1] - nl->offset[a])
      short_list = a < short_list ? a : short_list;
    sort_list(list, k);
  }
  SPH_CHECK(short_list == nn, err,
            "neighbour list of particle %ld: the fill found other "
            "neighbours than the count",
            short_list);
  SPH_DEBUG_TRY(sph_neighbors_check(nl, x, dim, radius, err));
  return SPH_OK;
}

/* whether `v` is in the ascending list v[0..k) */
static int listed(const int32_t *list, size_t k, int32_t v) {
  size_t lo = 0, hi = k;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (list[mid] == v)
      return 1;
    if (list[mid] < v)
      lo = mid + 1;
    else
      hi = mid;
  }
  return 0;
}

sph_status sph_neighbors_check(const sph_neighbors *nl, const double *x,
                               int dim, double radius, sph_error *err) {
  size_t n = nl->n;
  SPH_CHECK(nl->offset && nl->offset[0] == 0 && nl->offset[n] == nl->count, err,
            "neighbour offsets: first %zu, last %zu for %zu pairs",
            nl->offset ? nl->offset[0] : 0, nl->offset ? nl->offset[n] : 0,
            nl->count);
  double r2 = radius * radius;
  for (size_t a = 0; a < n; ++a) {
    size_t lo = nl->offset[a], hi = nl->offset[a + 1];
    SPH_CHECK(lo <= hi && hi <= nl->count, err,
              "neighbour offsets of particle %zu: [%zu, %zu) of %zu pairs", a,
              lo, hi, nl->count);
    for (size_t k = lo; k < hi; ++k) {
      int32_t b = nl->index[k];
      SPH_CHECK(b >= 0 && (size_t)b < n && (size_t)b != a, err,
                "neighbour list of particle %zu holds %d (of %zu particles)", a,
                (int)b, n);
      int32_t prev = k > lo ? nl->index[k - 1] : -1;
      SPH_CHECK(prev < b, err,
                "neighbour list of particle %zu is not strictly ascending "
                "(%d after %d)",
                a, (int)b, (int)prev);
      double d2 = dist2(x, a, (size_t)b, dim);
      SPH_CHECK(d2 < r2, err,
                "neighbour %d of particle %zu is %g away, beyond the radius "
                "%g",
                (int)b, a, sqrt(d2), radius);
    }
  }
  /* symmetry, once every list is known to be sorted */
  for (size_t a = 0; a < n; ++a)
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      int32_t b = nl->index[k];
      SPH_CHECK(listed(nl->index + nl->offset[b],
                       nl->offset[b + 1] - nl->offset[b], (int32_t)a),
                err,
                "neighbour lists not symmetric: %d is in the list of %zu, "
                "not %zu in that of %d",
                (int)b, a, a, (int)b);
    }
  return SPH_OK;
}
