/* Relaxation of a body's particles to the uniform, irregular distributions
 * of seed 002 sec. 6.3-6.4 (there made by level-set pre-processing, its
 * ref. [55]): particles shift down the gradient of the kernel sum
 * C = sum_b V W_ab (particle shifting in the manner of Lind et al. 2012,
 * without flow), with the kernel support cut by a face replaced by the plane
 * integral of W (exact for a plane, since grad C over a half-space is the
 * integral of W over its boundary), and kept dp/2 inside the faces; over MPI
 * ranks each rank relaxes a slice of the points, with the serial neighbour
 * lists and sums (issue 20), and streams them (sph_body_visit_share). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/kernel.h"
#include "core/neighbors.h"
#include "parallel/domain.h"
#include "parallel/relax_share.h"
#include "scene/geometry.h"
#include "scene/geometry_impl.h"

/* ---- walls: the shape's faces near a point, as planes -------------------- */

typedef struct wall {
  double d;    /* signed distance to the face (negative inside) */
  double n[3]; /* outward unit normal */
} wall;

/* radial face of a disc, sphere, shell or tube; sign -1 for an inner face */
static int radial_wall(const double rel[3], double r, double radius, int sign,
                       wall *w) {
  if (!(r > 0.0))
    return 0; /* on the centre: the normal is undefined and the face far */
  w->d = sign * (r - radius);
  for (int c = 0; c < 3; ++c)
    w->n[c] = sign * rel[c] / r;
  return 1;
}

static int axial_wall(const double n[3], double d, int sign, wall *w) {
  w->d = d;
  for (int c = 0; c < 3; ++c)
    w->n[c] = sign * n[c];
  return 1;
}

/* Fills up to 6 faces of the shape as seen from X; returns their number. */
static int shape_walls(const sph_shape *s, int dim, const double X[3],
                       wall w[6]) {
  int k = 0;
  double rel[3] = {X[0] - s->center[0], X[1] - s->center[1],
                   dim == 3 ? X[2] - s->center[2] : 0.0};
  switch (s->kind) {
  case SPH_SHAPE_BOX:
    for (int c = 0; c < dim; ++c) {
      const double e[3] = {c == 0, c == 1, c == 2};
      k += axial_wall(e, s->min[c] - X[c], -1, &w[k]);
      k += axial_wall(e, X[c] - s->max[c], +1, &w[k]);
    }
    return k;
  case SPH_SHAPE_DISC:
  case SPH_SHAPE_SPHERE:
  case SPH_SHAPE_SHELL:
  case SPH_SHAPE_RING:
  case SPH_SHAPE_CYLINDER: {
    int axial = shape_is_axial(s, dim);
    double along = 0.0;
    if (axial) {
      along = rel[0] * s->axis[0] + rel[1] * s->axis[1] + rel[2] * s->axis[2];
      for (int c = 0; c < 3; ++c)
        rel[c] -= along * s->axis[c];
    }
    if (s->kind == SPH_SHAPE_DISC)
      rel[2] = 0.0;
    double r = hypot3(rel[0], rel[1], rel[2]);
    if (s->kind == SPH_SHAPE_DISC || s->kind == SPH_SHAPE_SPHERE ||
        s->kind == SPH_SHAPE_CYLINDER) {
      k += radial_wall(rel, r, s->radius, +1, &w[k]);
    } else {
      k += radial_wall(rel, r, s->outer_radius, +1, &w[k]);
      if (s->inner_radius > 0.0)
        k += radial_wall(rel, r, s->inner_radius, -1, &w[k]);
    }
    if (axial) {
      k += axial_wall(s->axis, -along, -1, &w[k]);
      k += axial_wall(s->axis, along - s->length, +1, &w[k]);
    }
    return k;
  }
  case SPH_SHAPE_MESH: /* not relaxed (the scene refuses it) */
  case SPH_SHAPE_POLYGON:
  case SPH_SHAPE_PARTICLES:
    return 0;
  }
  return 0;
}

/* ---- relaxation ---------------------------------------------------------- */

#define WALL_TABLE 256

/* P(s): integral of W over a plane at distance s from its centre, i.e. the
 * kernel gradient integrated over the half-space beyond a wall. Tabulated on
 * [0, support] by Simpson's rule. */
static void wall_table(const sph_kernel *k, int dim, double *P) {
  const int m = 400; /* Simpson intervals, even */
  for (int i = 0; i <= WALL_TABLE; ++i) {
    double s = k->support * i / WALL_TABLE, sum = 0.0;
    double top = sqrt(fmax(k->support * k->support - s * s, 0.0));
    for (int j = 0; j <= m; ++j) {
      double t = top * j / m,
             w = (j == 0 || j == m) ? 1.0 : (j % 2 ? 4.0 : 2.0);
      /* 2D: line integral over t; 3D: 2 pi rho drho over the plane */
      double r = sqrt(s * s + t * t);
      sum += w * sph_kernel_eval(k, r) * (dim == 2 ? 2.0 : 2.0 * M_PI * t);
    }
    P[i] = sum * top / (3.0 * m);
  }
}

static double wall_lookup(const double *P, double support, double s) {
  double u = (s < 0 ? 0 : s) / support * WALL_TABLE;
  if (u >= WALL_TABLE)
    return 0.0;
  int i = (int)u;
  double f = u - i;
  return (1.0 - f) * P[i] + f * P[i + 1];
}

/* Moves X to `margin` inside every face that is closer than that. */
static void wall_project(const sph_shape *s, int dim, double X[3],
                         double margin) {
  for (int pass = 0; pass < 2; ++pass) {
    wall w[6];
    int nw = shape_walls(s, dim, X, w);
    for (int i = 0; i < nw; ++i)
      if (w[i].d > -margin) {
        for (int c = 0; c < dim; ++c)
          X[c] -= (w[i].d + margin) * w[i].n[c];
        nw = shape_walls(s, dim, X, w);
      }
  }
}

/* the relaxation's constants for a body of n points */
typedef struct relax_par {
  const sph_shape *s;
  int dim;
  double vol, dp;   /* equal volumes that fill the shape, their spacing */
  double diff, cap; /* shift = -D grad C, D = h^2 / 2, at most 0.2 dp */
  double skin;      /* Verlet lists: rebuilt once a point may move skin/2 */
  double radius;    /* their search radius, support + skin */
  double reach2;    /* the support squared */
  sph_kernel k;
  double P[WALL_TABLE + 1];
} relax_par;

static sph_status relax_par_init(relax_par *r, const sph_body *b, int dim,
                                 size_t n, sph_error *err) {
  r->s = &b->shape;
  r->dim = dim;
  r->vol = sph_shape_measure(r->s, dim) / (double)n;
  r->dp = pow(r->vol, 1.0 / dim);
  SPH_TRY(
      sph_kernel_create(&r->k, SPH_KERNEL_WENDLAND_C2, dim, 1.3 * r->dp, err));
  wall_table(&r->k, dim, r->P);
  r->diff = 0.5 * r->k.h * r->k.h;
  r->cap = 0.2 * r->dp;
  r->skin = 0.6 * r->dp;
  r->radius = r->k.support + r->skin;
  r->reach2 = r->k.support * r->k.support;
  return SPH_OK;
}

/* the shift of point a of x from its neighbours list[0 .. m), summed in
 * the list's order */
static void relax_shift(const relax_par *r, const double *x, size_t a,
                        const int32_t *list, size_t m, double shift[3]) {
  int dim = r->dim;
  const double *Xa = x + 3 * a;
  double g[3] = {0, 0, 0};
  /* grad C: the neighbours ... */
  for (size_t j = 0; j < m; ++j) {
    const double *Xb = x + 3 * (size_t)list[j];
    double rab[3] = {Xa[0] - Xb[0], Xa[1] - Xb[1], Xa[2] - Xb[2]}, gw[3];
    double r2 = rab[0] * rab[0] + rab[1] * rab[1] + rab[2] * rab[2];
    if (r2 >= r->reach2)
      continue;
    sph_kernel_gradient(&r->k, rab, sqrt(r2), gw);
    for (int c = 0; c < dim; ++c)
      g[c] += r->vol * gw[c];
  }
  /* ... and the continuum beyond each wall within reach */
  wall w[6];
  int nw = shape_walls(r->s, dim, Xa, w);
  for (int i = 0; i < nw; ++i) {
    double Pw = wall_lookup(r->P, r->k.support, -w[i].d);
    for (int c = 0; c < dim; ++c)
      g[c] += Pw * w[i].n[c];
  }
  double len = 0.0;
  for (int c = 0; c < dim; ++c)
    len += g[c] * g[c];
  len = r->diff * sqrt(len);
  double scale = -r->diff * (len > r->cap ? r->cap / len : 1.0);
  for (int c = 0; c < 3; ++c)
    shift[c] = c < dim ? scale * g[c] : 0.0;
}

/* X moved by shift and kept inside the faces; its distance from B */
static double relax_move(const relax_par *r, double X[3], const double shift[3],
                         const double B[3]) {
  double Y[3] = {X[0], X[1], X[2]};
  for (int c = 0; c < r->dim; ++c)
    Y[c] += shift[c];
  wall_project(r->s, r->dim, Y, 0.5 * r->dp);
  /* a shape thinner than dp cannot hold the margin: stay put */
  if (sph_shape_distance(r->s, r->dim, Y) < 0.0)
    memcpy(X, Y, sizeof Y);
  return hypot3(X[0] - B[0], X[1] - B[1], X[2] - B[2]);
}

sph_status sph_body_relax(const sph_body *b, int dim, pointset *p,
                          sph_error *err) {
  if (b->relax_steps <= 0)
    return SPH_OK;
  relax_par r;
  SPH_TRY(relax_par_init(&r, b, dim, p->n, err));
  sph_neighbors *nl = NULL;
  double *shift = NULL, *built = NULL;
  sph_status st = sph_neighbors_create(&nl, err);
  if (st == SPH_OK && (!(shift = calloc(3 * p->n, sizeof *shift)) ||
                       !(built = malloc(3 * p->n * sizeof *built))))
    st = sph_error_set(err, SPH_ERR_NOMEM, "relaxation of body '%s'", b->name);
  double moved = INFINITY;
  for (int it = 0; st == SPH_OK && it < b->relax_steps; ++it) {
    if (moved > 0.5 * r.skin) {
      st = sph_neighbors_build(nl, p->x, p->n, dim, r.radius, NULL,
                               SPH_PAIRS_ALL, err);
      if (st != SPH_OK)
        break;
      memcpy(built, p->x, 3 * p->n * sizeof *built);
      moved = 0.0;
    }
    long n = (long)p->n;
#pragma omp parallel for schedule(static)
    for (long a = 0; a < n; ++a)
      relax_shift(&r, p->x, (size_t)a, nl->index + nl->offset[a],
                  nl->offset[a + 1] - nl->offset[a], shift + 3 * a);
    for (size_t a = 0; a < p->n; ++a) {
      double m = relax_move(&r, p->x + 3 * a, shift + 3 * a, built + 3 * a);
      moved = m > moved ? m : moved;
    }
  }
  free(built);
  free(shift);
  sph_neighbors_destroy(nl);
  return st;
}

/* ---- relaxation per MPI rank --------------------------------------------- */

/* The cell grid sph_neighbors_build lays over the N points of the body
 * (sph_neighbors_grid, the bounds reduced over the ranks). */
typedef struct slice_grid {
  double lo[3], cell;
  long nc[3];
} slice_grid;

static sph_status slice_grid_setup(slice_grid *g, const double *x, size_t n,
                                   size_t N, int dim, double radius,
                                   sph_error *err) {
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int c = 0; c < dim; ++c) {
    lo[c] = INFINITY;
    hi[c] = -INFINITY;
  }
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < dim; ++c) {
      double v = x[3 * i + c];
      lo[c] = v < lo[c] ? v : lo[c];
      hi[c] = v > hi[c] ? v : hi[c];
    }
  sph_relax_share_bounds(lo, hi, dim);
  for (int c = 0; c < dim; ++c)
    if (!isfinite(hi[c] - lo[c]))
      return sph_error_set(err, SPH_ERR_NUMERIC,
                           "neighbour search: particle positions are not "
                           "finite or span more than a double can hold");
  g->cell = sph_neighbors_grid(lo, hi, N, dim, radius, g->nc);
  memcpy(g->lo, lo, sizeof lo);
  return SPH_OK;
}

static long slice_coord(const slice_grid *g, double v, int c) {
  double k = floor((v - g->lo[c]) / g->cell);
  if (!(k > 0.0)) /* also NaN */
    return 0;
  return k >= (double)g->nc[c] ? g->nc[c] - 1 : (long)k;
}

/* a point of the lists' search: its cell, creation index and slot */
typedef struct slice_entry {
  uint64_t cell;
  int64_t id;
  int32_t slot;
} slice_entry;

static int cmp_slice_entry(const void *pa, const void *pb) {
  const slice_entry *a = pa, *b = pb;
  if (a->cell != b->cell)
    return a->cell < b->cell ? -1 : 1;
  return (a->id > b->id) - (a->id < b->id);
}

/* Verlet lists of the owned points 0 .. n - 1 of x (owned, then ghosts; m
 * in all) as sph_neighbors_build makes them over the whole body: the points
 * of the 3^dim cells around a closer than the radius, in creation order. */
typedef struct slice_lists {
  slice_grid g;
  slice_entry *e; /* m, sorted by cell, then creation index */
  size_t *offset; /* n + 1 */
  int32_t *index;
  size_t ecap, ncap, cap;
} slice_lists;

/* the neighbours of a (counted, or written to out when given) */
static size_t slice_scan(const slice_lists *L, const double *x,
                         const int64_t *id, size_t m, size_t a, int dim,
                         double r2, int32_t *out) {
  const slice_grid *g = &L->g;
  long lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int c = 0; c < dim; ++c) {
    long ca = slice_coord(g, x[3 * a + c], c);
    lo[c] = ca > 0 ? ca - 1 : 0;
    hi[c] = ca + 1 < g->nc[c] ? ca + 1 : g->nc[c] - 1;
  }
  size_t k = 0;
  for (long i = lo[0]; i <= hi[0]; ++i)
    for (long j = lo[1]; j <= hi[1]; ++j)
      for (long l = lo[2]; l <= hi[2]; ++l) {
        uint64_t cell = (uint64_t)((i * g->nc[1] + j) * g->nc[2] + l);
        size_t s = 0, e = m; /* the first entry of the cell */
        while (s < e) {
          size_t mid = s + (e - s) / 2;
          if (L->e[mid].cell < cell)
            s = mid + 1;
          else
            e = mid;
        }
        for (; s < m && L->e[s].cell == cell; ++s) {
          size_t b = (size_t)L->e[s].slot;
          double d2 = 0.0;
          for (int c = 0; c < dim; ++c) {
            double d = x[3 * a + c] - x[3 * b + c];
            d2 += d * d;
          }
          if (b == a || d2 >= r2)
            continue;
          /* in creation order: inserted by creation index */
          if (out) {
            size_t q = k;
            for (; q > 0 && id[out[q - 1]] > id[b]; --q)
              out[q] = out[q - 1];
            out[q] = (int32_t)b;
          }
          ++k;
        }
      }
  return k;
}

static sph_status slice_lists_build(slice_lists *L, const double *x,
                                    const int64_t *id, size_t n, size_t m,
                                    size_t N, int dim, double radius,
                                    sph_error *err) {
  sph_status st = SPH_OK;
  if (m + 1 > L->ecap) {
    free(L->e);
    L->ecap = m + m / 4 + 1;
    if (!(L->e = malloc(L->ecap * sizeof *L->e)))
      L->ecap = 0;
  }
  if (n + 1 > L->ncap) {
    free(L->offset);
    L->ncap = n + 1;
    if (!(L->offset = malloc(L->ncap * sizeof *L->offset)))
      L->ncap = 0;
  }
  st = sph_domain_world_agree(
      L->e && L->offset ? SPH_OK
                        : sph_error_set(err, SPH_ERR_NOMEM, "relaxation lists"),
      err);
  if (st == SPH_OK)
    st = slice_grid_setup(&L->g, x, n, N, dim, radius, err);
  if (st != SPH_OK)
    return st;
  for (size_t i = 0; i < m; ++i) {
    long q[3] = {0, 0, 0};
    for (int c = 0; c < dim; ++c)
      q[c] = slice_coord(&L->g, x[3 * i + c], c);
    L->e[i] = (slice_entry){
        (uint64_t)((q[0] * L->g.nc[1] + q[1]) * L->g.nc[2] + q[2]), id[i],
        (int32_t)i};
  }
  qsort(L->e, m, sizeof *L->e, cmp_slice_entry);
  double r2 = radius * radius;
  long nn = (long)n;
  L->offset[0] = 0;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < nn; ++a)
    L->offset[a + 1] = slice_scan(L, x, id, m, (size_t)a, dim, r2, NULL);
  for (size_t a = 0; a < n; ++a)
    L->offset[a + 1] += L->offset[a];
  if (L->offset[n] > L->cap) {
    free(L->index);
    L->cap = L->offset[n] + L->offset[n] / 4 + 1;
    if (!(L->index = malloc(L->cap * sizeof *L->index)))
      L->cap = 0;
  }
  st = sph_domain_world_agree(
      L->index ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "relaxation lists"),
      err);
  if (st != SPH_OK)
    return st;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < nn; ++a)
    slice_scan(L, x, id, m, (size_t)a, dim, r2, L->index + L->offset[a]);
  return SPH_OK;
}

/* A relax body's slice on this rank: creation indices first .. first +
 * p.n - 1 of the body's N points. */
struct sph_body_slice {
  size_t N;
  int64_t first;
  pointset p;
};

/* relax() over the ranks: each rank moves its slice, the neighbours' sums
 * over the same lists in the same order (owned and ghost points in
 * creation order), the rebuild decided on the largest move of any rank */
static sph_status relax_slice(const sph_body *b, int dim, sph_body_slice *sl,
                              sph_error *err) {
  if (b->relax_steps <= 0)
    return SPH_OK;
  relax_par r;
  SPH_TRY(relax_par_init(&r, b, dim, sl->N, err));
  pointset *p = &sl->p;
  size_t n = p->n, m = 0, mcap = 0;
  slice_lists L = {0};
  sph_relax_share *h = NULL;
  double *shift = calloc(3 * n + 3, sizeof *shift);
  double *built = malloc((3 * n + 3) * sizeof *built), *x = NULL;
  int64_t *id = NULL;
  sph_status st = sph_relax_share_create(&h, err);
  if (st == SPH_OK)
    st = sph_domain_world_agree(
        shift && built ? SPH_OK
                       : sph_error_set(err, SPH_ERR_NOMEM,
                                       "relaxation of body '%s'", b->name),
        err);
  double moved = INFINITY;
  for (int it = 0; st == SPH_OK && it < b->relax_steps; ++it) {
    moved = sph_relax_share_max(moved);
    int rebuild = moved > 0.5 * r.skin;
    /* the ghosts within the lists' radius, found again at a rebuild */
    st = rebuild
             ? sph_relax_share_ghosts(h, p->x, n, sl->first, dim, r.radius, err)
             : sph_relax_share_refresh(h, p->x, err);
    m = n + (st == SPH_OK ? sph_relax_share_count(h) : 0);
    if (st == SPH_OK && m + 1 > mcap) {
      free(x);
      free(id);
      mcap = m + m / 4 + 1;
      x = malloc(3 * mcap * sizeof *x);
      id = malloc(mcap * sizeof *id);
      st = sph_domain_world_agree(
          x && id ? SPH_OK
                  : sph_error_set(err, SPH_ERR_NOMEM, "relaxation of body '%s'",
                                  b->name),
          err);
    }
    if (st != SPH_OK)
      break;
    memcpy(x, p->x, 3 * n * sizeof *x);
    if (m > n)
      memcpy(x + 3 * n, sph_relax_share_x(h), 3 * (m - n) * sizeof *x);
    if (rebuild) {
      for (size_t i = 0; i < n; ++i)
        id[i] = sl->first + (int64_t)i;
      if (m > n)
        memcpy(id + n, sph_relax_share_id(h), (m - n) * sizeof *id);
      st = slice_lists_build(&L, x, id, n, m, sl->N, dim, r.radius, err);
      if (st != SPH_OK)
        break;
      memcpy(built, p->x, 3 * n * sizeof *built);
      moved = 0.0;
    }
    long nn = (long)n;
#pragma omp parallel for schedule(static)
    for (long a = 0; a < nn; ++a)
      relax_shift(&r, x, (size_t)a, L.index + L.offset[a],
                  L.offset[a + 1] - L.offset[a], shift + 3 * a);
    for (size_t a = 0; a < n; ++a) {
      double d = relax_move(&r, p->x + 3 * a, shift + 3 * a, built + 3 * a);
      moved = d > moved ? d : moved;
    }
  }
  free(L.e);
  free(L.offset);
  free(L.index);
  free(x);
  free(id);
  free(built);
  free(shift);
  sph_relax_share_destroy(h);
  return st;
}

/* the body's slice: its points of creation indices [first, last) */
typedef struct slice_keep {
  int64_t at, first, last;
  pointset *p;
} slice_keep;

static sph_status keep_slice(void *ctx, const double X[3], double volume,
                             sph_error *err) {
  slice_keep *k = ctx;
  int64_t i = k->at++;
  return i >= k->first && i < k->last ? sph_pointset_push(k->p, X, volume, err)
                                      : SPH_OK;
}

static sph_status count_point(void *ctx, const double X[3], double volume,
                              sph_error *err) {
  (void)ctx, (void)X, (void)volume, (void)err;
  return SPH_OK;
}

static sph_status slice_create(const sph_body *b, int dim, sph_body_slice **out,
                               sph_error *err) {
  sph_body_slice *sl = calloc(1, sizeof *sl);
  sph_status st = sph_domain_world_agree(
      sl ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "particles"), err);
  if (st != SPH_OK) {
    free(sl);
    return st;
  }
  /* the same on every rank: the body's points and their errors */
  st = sph_body_visit(b, dim, count_point, NULL, &sl->N, err);
  size_t R = (size_t)sph_domain_world_size(),
         r = (size_t)sph_domain_world_rank();
  slice_keep k = {.first = (int64_t)(sl->N * r / R),
                  .last = (int64_t)(sl->N * (r + 1) / R),
                  .p = &sl->p};
  sl->first = k.first;
  size_t n;
  if (st == SPH_OK)
    st = sph_domain_world_agree(sph_body_visit(b, dim, keep_slice, &k, &n, err),
                                err);
  if (st == SPH_OK)
    st = relax_slice(b, dim, sl, err);
  if (st != SPH_OK) {
    sph_body_slice_destroy(sl);
    return st;
  }
  *out = sl;
  return SPH_OK;
}

void sph_body_slice_destroy(sph_body_slice *s) {
  if (!s)
    return;
  free(s->p.x);
  free(s->p.v);
  free(s);
}

/* the streamed chunks to the visitor, point by point */
typedef struct slice_visit {
  sph_point_fn fn;
  void *ctx;
  double volume;
} slice_visit;

static sph_status visit_chunk(void *ctx, const double *x, size_t count,
                              sph_error *err) {
  const slice_visit *v = ctx;
  for (size_t i = 0; i < count; ++i)
    SPH_TRY(v->fn(v->ctx, x + 3 * i, v->volume, err));
  return SPH_OK;
}

sph_status sph_body_visit_share(const sph_body *b, int dim,
                                sph_body_slice **slice, sph_point_fn fn,
                                void *ctx, size_t *n, sph_error *err) {
  if (b->distribution != SPH_DIST_RELAX)
    return sph_body_visit(b, dim, fn, ctx, n, err);
  *n = 0;
  if (!*slice)
    SPH_TRY(slice_create(b, dim, slice, err));
  /* equal volumes that add up to the exact measure */
  slice_visit v = {fn, ctx,
                   sph_shape_measure(&b->shape, dim) / (double)(*slice)->N};
  SPH_TRY(sph_relax_share_stream((*slice)->p.x, (*slice)->p.n, visit_chunk, &v,
                                 err));
  *n = (*slice)->N;
  return SPH_OK;
}
