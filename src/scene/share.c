/* One MPI rank's share of a scene's particles without the whole set
 * (sph_scene_build_share, issue 20): the bodies' particles visited three
 * times (bounds and checks, counts per cell of the Morton order's grid,
 * storage indices), the overlap check among the share and the cells next
 * to it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/neighbors.h"
#include "scene/build_impl.h"
#include "scene/geometry.h"

/* the passes of sph_scene_build_share over every particle in creation order */
typedef struct share_pass {
  const sph_scene *s;
  int pass;       /* 1: bounds and checks, 2: count per cell, 3: keep */
  size_t b;       /* the body visited */
  int64_t id;     /* creation index of the next particle */
  build_checks c; /* pass 1 */
  double lo[3], hi[3], cell;
  size_t nc[3];  /* cells per axis */
  int64_t *grid; /* pass 2: particles per cell; pass 3: next storage index */
  int64_t first, last; /* storage indices kept: [first, last) */
  sph_particles *ps;
  int64_t *gidx;
  /* several bodies: the share's particles and those of the cells next to
   * its cells (the overlap check's neighbours), in creation order */
  char *mine; /* per cell: holds a particle of the share */
  double *nx;
  int32_t *nbody;
  int64_t *nid;
  char *nin; /* in the share */
  size_t nn, ncap;
  sph_body_slice **slices; /* per body: a relax body's slice on this rank */
} share_pass;

/* whether a cell next to q (or q) holds a particle of the share */
static int near_share(const share_pass *p, const uint32_t q[3]) {
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k) {
        long c[3] = {(long)q[0] + i, (long)q[1] + j, (long)q[2] + k};
        int in = 1;
        for (int e = 0; e < 3; ++e)
          in &= c[e] >= 0 && c[e] < (long)p->nc[e];
        if (in && p->mine[((size_t)c[2] * p->nc[1] + (size_t)c[1]) * p->nc[0] +
                          (size_t)c[0]])
          return 1;
      }
  return 0;
}

/* a point of the overlap check */
static sph_status keep_near(share_pass *p, const double X[3], int64_t id,
                            int in, sph_error *err) {
  if (p->nn == p->ncap) {
    size_t c = p->ncap ? 2 * p->ncap : 1024;
    double *x = realloc(p->nx, 3 * c * sizeof *x);
    if (x)
      p->nx = x;
    int32_t *b = realloc(p->nbody, c * sizeof *b);
    if (b)
      p->nbody = b;
    int64_t *i = realloc(p->nid, c * sizeof *i);
    if (i)
      p->nid = i;
    char *n = realloc(p->nin, c);
    if (n)
      p->nin = n;
    if (!x || !b || !i || !n)
      return sph_error_set(err, SPH_ERR_NOMEM, "overlap check");
    p->ncap = c;
  }
  memcpy(p->nx + 3 * p->nn, X, 3 * sizeof *X);
  p->nbody[p->nn] = (int32_t)p->b;
  p->nid[p->nn] = id;
  p->nin[p->nn++] = (char)in;
  return SPH_OK;
}

typedef struct share_cell {
  uint64_t key;
  size_t cell;
} share_cell;

static int cmp_share_cell(const void *pa, const void *pb) {
  const share_cell *a = pa, *b = pb;
  return (a->key > b->key) - (a->key < b->key);
}

static sph_status share_point(void *ctx, const double Xb[3], double volume,
                              sph_error *err) {
  share_pass *p = ctx;
  const sph_scene *s = p->s;
  double X[3], v[3];
  uint32_t flags, q[3];
  int64_t id = p->id++;
  if (p->pass == 1) {
    sph_build_particle_state(s, p->b, Xb, X, v, &flags, &p->c);
    for (int c = 0; c < 3; ++c) {
      p->lo[c] = fmin(p->lo[c], X[c]);
      p->hi[c] = fmax(p->hi[c], X[c]);
    }
    return SPH_OK;
  }
  sph_body_world(&s->bodies[p->b], Xb, X);
  sph_morton_cell(X, p->lo, p->cell, q);
  size_t cell = ((size_t)q[2] * p->nc[1] + q[1]) * p->nc[0] + q[0];
  if (p->pass == 2) {
    p->grid[cell]++;
    return SPH_OK;
  }
  /* particles of one cell in creation order: the sort's tie-break */
  int64_t g = p->grid[cell]++;
  int in = g >= p->first && g < p->last;
  if (p->mine && (in || near_share(p, q)))
    SPH_TRY(keep_near(p, X, id, in, err));
  if (!in)
    return SPH_OK;
  sph_particles *ps = p->ps;
  sph_build_particle_state(s, p->b, Xb, X, v, &flags, NULL);
  SPH_TRY(sph_particles_append(ps, X, volume, (int32_t)p->b, err));
  memcpy(ps->field[SPH_FIELD_VELOCITY] + 3 * (ps->n - 1), v, sizeof v);
  ps->flags[ps->n - 1] = flags;
  ps->id[ps->n - 1] = id;
  p->gidx[ps->n - 1] = g;
  return SPH_OK;
}

/* one pass over every body's particles */
static sph_status share_visit(share_pass *p, int pass, sph_error *err) {
  p->pass = pass;
  p->id = 0;
  for (p->b = 0; p->b < p->s->nbodies; ++p->b) {
    size_t n;
    sph_status st =
        sph_body_visit_share(&p->s->bodies[p->b], p->s->dimension,
                             &p->slices[p->b], share_point, p, &n, err);
    if (st != SPH_OK)
      return sph_build_body_error(p->s, p->b, st, err);
  }
  return SPH_OK;
}

/* grid[cell] = the storage index of the cell's first particle: the
 * occupied cells in Morton order */
static sph_status share_starts(share_pass *p, size_t cells, sph_error *err) {
  size_t m = 0;
  for (size_t k = 0; k < cells; ++k)
    m += p->grid[k] > 0;
  share_cell *occ = malloc((m ? m : 1) * sizeof *occ);
  if (!occ)
    return sph_error_set(err, SPH_ERR_NOMEM, "particle order (%zu cells)", m);
  m = 0;
  for (size_t k = 0; k < cells; ++k)
    if (p->grid[k] > 0) {
      uint32_t q[3] = {(uint32_t)(k % p->nc[0]),
                       (uint32_t)(k / p->nc[0] % p->nc[1]),
                       (uint32_t)(k / p->nc[0] / p->nc[1])};
      occ[m++] = (share_cell){sph_morton_key(q), k};
    }
  qsort(occ, m, sizeof *occ, cmp_share_cell);
  int64_t start = 0;
  for (size_t j = 0; j < m; ++j) {
    int64_t count = p->grid[occ[j].cell];
    p->grid[occ[j].cell] = start;
    if (p->mine)
      p->mine[occ[j].cell] = start < p->last && start + count > p->first;
    start += count;
  }
  free(occ);
  return SPH_OK;
}

static sph_status build_share(const sph_scene *s, double cell, int rank,
                              int size, sph_particles **out, int64_t **gidx,
                              size_t *total, int64_t *overlap,
                              sph_body_slice **slices, sph_error *err) {
  *out = NULL;
  *gidx = NULL;
  *total = 0;
  *overlap = INT64_MAX;
  share_pass p = {.s = s,
                  .cell = cell,
                  .slices = slices,
                  .lo = {INFINITY, INFINITY, INFINITY},
                  .hi = {-INFINITY, -INFINITY, -INFINITY}};
  /* pass 1: the bounds and the checks, as the whole set's (relax bodies
   * relaxed per rank on their first visit) */
  sph_status st = sph_build_checks_create(s, &p.c, err);
  if (st == SPH_OK)
    st = share_visit(&p, 1, err);
  size_t N = (size_t)p.id;
  if (st == SPH_OK)
    st = sph_build_checks_first(&p.c, err);
  /* the later checks' error comes after the overlap check's */
  sph_error later;
  sph_status rest =
      st == SPH_OK ? sph_build_checks_rest(s, &p.c, &later) : SPH_OK;
  sph_build_checks_destroy(&p.c);
  int several = s->nbodies > 1;
  if (st == SPH_OK && rest != SPH_OK && !several)
    *err = later, st = rest;
  if (st != SPH_OK)
    return st;
  /* the cell grid of the Morton order; a sparse one (far apart bodies)
   * larger than 2 cells a particle and 2^22 cells, or for the overlap check
   * cells clamped or smaller than its dp / 2: the whole set instead */
  double cells = 1.0;
  int clamped = 0;
  for (int c = 0; c < 3; ++c) {
    double q = floor((p.hi[c] - p.lo[c]) / cell);
    clamped |= q > 2097151.0;
    p.nc[c] = (size_t)fmin(q, 2097151.0) + 1;
    cells *= (double)p.nc[c];
  }
  if (!(cell > 0.0) || cells > fmax(2.0 * (double)N, 4194304.0) ||
      (several && (clamped || 0.5 * sph_scene_min_spacing(s) > cell)))
    return SPH_OK;
  p.grid = calloc((size_t)cells, sizeof *p.grid);
  if (several)
    p.mine = calloc((size_t)cells, 1);
  if (!p.grid || (several && !p.mine)) {
    free(p.grid);
    free(p.mine);
    return sph_error_set(err, SPH_ERR_NOMEM, "particle order (%.3g cells)",
                         cells);
  }
  /* pass 2: particles per cell; pass 3: storage indices, keeping the
   * share [rank N / size, (rank + 1) N / size) */
  p.first = (int64_t)(N * (size_t)rank / (size_t)size);
  p.last = (int64_t)(N * ((size_t)rank + 1) / (size_t)size);
  size_t m = (size_t)(p.last - p.first);
  st = share_visit(&p, 2, err);
  if (st == SPH_OK)
    st = share_starts(&p, (size_t)cells, err);
  if (st == SPH_OK)
    st = sph_particles_create(&p.ps, m, s->dimension, err);
  if (st == SPH_OK)
    st = sph_particles_require(p.ps, SPH_FIELD_VELOCITY, err);
  if (st == SPH_OK && !(p.gidx = malloc((m ? m : 1) * sizeof *p.gidx)))
    st = sph_error_set(err, SPH_ERR_NOMEM, "particle share (%zu)", m);
  if (st == SPH_OK)
    st = share_visit(&p, 3, err);
  free(p.grid);
  free(p.mine);
  /* bodies that overlap: the share's first particle with a neighbour of
   * another body closer than dp / 2 (its neighbours are in the share or
   * the cells next to its cells) */
  size_t bad = p.nn;
  if (st == SPH_OK && several)
    st = sph_build_find_overlap(s, p.nx, p.nbody, p.nin, p.nn, &bad, err);
  if (bad < p.nn)
    *overlap = p.nid[bad];
  if (st == SPH_OK && rest != SPH_OK)
    *err = later, st = rest;
  free(p.nx);
  free(p.nbody);
  free(p.nid);
  free(p.nin);
  if (st != SPH_OK) {
    sph_particles_destroy(p.ps);
    free(p.gidx);
    return st;
  }
  *out = p.ps;
  *gidx = p.gidx;
  *total = N;
  return SPH_OK;
}

sph_status sph_scene_build_share(const sph_scene *s, double cell, int rank,
                                 int size, sph_particles **out, int64_t **gidx,
                                 size_t *total, int64_t *overlap,
                                 sph_error *err) {
  sph_body_slice **slices = calloc(s->nbodies + 1, sizeof *slices);
  if (!slices)
    return sph_error_set(err, SPH_ERR_NOMEM, "bodies");
  sph_status st =
      build_share(s, cell, rank, size, out, gidx, total, overlap, slices, err);
  for (size_t b = 0; b < s->nbodies; ++b)
    sph_body_slice_destroy(slices[b]);
  free(slices);
  return st;
}
