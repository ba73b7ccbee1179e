/* Shared set-up and output of the total-Lagrangian methods (seed 000
 * sec. 3.2, seed 001 sec. 2): the reference configuration is fixed, so the
 * neighbour lists and corrected gradients are computed once here, including
 * mirror images across symmetry (normal component negated) and
 * skew-symmetry (tangential components negated) planes, as BENCHMARKS.md
 * D.1 recommends for the swinging cube of seed 000 sec. 8.2; a plane of any
 * unit normal n reflects X - 2((X - p) . n) n, vectors by R = I - 2 n n^T
 * and two-point tensors R A R^T (sign flips for coordinate planes). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/corrections.h"
#include "core/tensor.h"
#include "methods/tl_common_impl.h"
#include "methods/tl_iact.h"
#include "terms/terms_impl.h"

/* ---- mirror images
 * ------------------------------------------------------------ */

typedef struct plane {
  double n[3], at; /* X . n = at */
  int axis;        /* n is this coordinate axis, or -1 (oblique) */
  int side, body;
  int sigma; /* +1 symmetry, -1 skew-symmetry */
  size_t done;
} plane;

typedef struct hash {
  int64_t *key; /* 3 per slot */
  char *used;
  size_t cap;
} hash;

static uint64_t hash3(const int64_t k[3]) {
  uint64_t h = 1469598103934665603ull;
  for (int c = 0; c < 3; ++c)
    h = (h ^ (uint64_t)k[c]) * 1099511628211ull;
  return h;
}

/* Inserts k; returns 0 if it was already present, 1 if new, -1 if full. */
static int hash_insert(hash *h, const int64_t k[3]) {
  for (size_t i = hash3(k) % h->cap, tries = 0; tries < h->cap;
       i = (i + 1) % h->cap, ++tries) {
    if (!h->used[i]) {
      h->used[i] = 1;
      memcpy(h->key + 3 * i, k, 3 * sizeof *k);
      return 1;
    }
    if (!memcmp(h->key + 3 * i, k, 3 * sizeof *k))
      return 0;
  }
  return -1;
}

static sph_status grow_points(tl_reference *r, size_t need, size_t *cap,
                              int oblique, sph_error *err) {
  if (need <= *cap)
    return SPH_OK;
  size_t c = 2 * need;
  if (oblique) {
    double *M = realloc(r->vmat, 9 * c * sizeof *M);
    if (!M)
      return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
    r->vmat = M;
  }
  double *X = realloc(r->X, 3 * c * sizeof *X), *V;
  if (X)
    r->X = X;
  V = realloc(r->V, c * sizeof *V);
  if (V)
    r->V = V;
  int32_t *b = realloc(r->body, c * sizeof *b), *s;
  if (b)
    r->body = b;
  s = realloc(r->src, c * sizeof *s);
  if (s)
    r->src = s;
  signed char *vs = realloc(r->vsign, 3 * c), *rs, *ss;
  if (vs)
    r->vsign = vs;
  rs = realloc(r->rsign, 3 * c);
  if (rs)
    r->rsign = rs;
  ss = realloc(r->ssign, c);
  if (ss)
    r->ssign = ss;
  if (!X || !V || !b || !s || !vs || !rs || !ss)
    return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
  *cap = c;
  return SPH_OK;
}

/* Signed distance of X from the plane (exact for a coordinate axis). */
static inline double plane_distance(const plane *pl, const double *X) {
  if (pl->axis >= 0)
    return X[pl->axis] - pl->at;
  return X[0] * pl->n[0] + X[1] * pl->n[1] + X[2] * pl->n[2] - pl->at;
}

/* a local real point and its storage index in the whole set */
typedef struct stored {
  int64_t key;
  size_t i;
} stored;

static int cmp_stored(const void *pa, const void *pb) {
  const stored *a = pa, *b = pb;
  return (a->key > b->key) - (a->key < b->key);
}

/* moves the ng points from n on behind the m that follow them, w bytes a
 * point (the ghosts of a distributed run after the images) */
static sph_status rotate_points(void *base, size_t w, size_t n, size_t ng,
                                size_t m, sph_error *err) {
  char *a = base, *tmp = malloc(ng * w + 1);
  if (!tmp)
    return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
  memcpy(tmp, a + n * w, ng * w);
  memmove(a + n * w, a + (n + ng) * w, m * w);
  memcpy(a + (n + m) * w, tmp, ng * w);
  free(tmp);
  return SPH_OK;
}

/* The scene's symmetry and skew-symmetry planes (at most 32) into planes:
 * their count; *oblique when one is not a coordinate plane. */
static int scene_planes(const sph_scene *s, plane *planes, int *oblique) {
  int np = 0;
  *oblique = 0;
  for (size_t k = 0; k < s->nboundaries && np < 32; ++k) {
    const sph_boundary *bc = &s->boundaries[k];
    if (bc->kind != SPH_BC_SYMMETRY && bc->kind != SPH_BC_SKEW_SYMMETRY)
      continue;
    plane *pl = &planes[np++];
    memcpy(pl->n, bc->select.normal, sizeof pl->n);
    pl->axis = bc->select.axis;
    pl->at = bc->select.at;
    pl->body = bc->select.body;
    pl->sigma = bc->kind == SPH_BC_SYMMETRY ? 1 : -1;
    pl->done = 0;
    pl->side = 1;
    *oblique |= pl->axis < 0;
  }
  return np;
}

/* Each plane's domain side: that of the mean distance of its body's
 * particles (over every rank's). */
static void plane_sides(plane *planes, int np, const sph_particles *ps,
                        sph_domain *dom) {
  const double *X0 = ps->field[SPH_FIELD_POSITION0];
  for (int k = 0; k < np; ++k) {
    plane *pl = &planes[k];
    double mean[2] = {0.0, 0.0};
    for (size_t a = 0; a < ps->n; ++a)
      if (pl->body < 0 || ps->body[a] == pl->body) {
        mean[0] += plane_distance(pl, X0 + 3 * a);
        mean[1] += 1.0;
      }
    sph_domain_sum(dom, mean, 2);
    pl->side = mean[1] > 0.0 && mean[0] / mean[1] < 0.0 ? -1 : 1;
  }
}

/* Real points first, then images of every point within two supports of a
 * plane on its domain side; two passes over the planes complete edges,
 * corners and periodic images, duplicates are skipped. Images across
 * coordinate planes flip signs; with an oblique plane every point carries
 * its reflection as a matrix (chosen once here). Over MPI ranks the real
 * points are the owned particles and the ghosts, visited in the serial
 * storage order, so the images of both come in the serial images' order
 * (key); the ghosts then move behind the images. The planes' sides are
 * side[k] when given (the whole set's for a part of it), else from
 * plane_sides. */
static sph_status build_images(tl_reference *r, sph_sim *sim, int images,
                               const int *side, sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_particles *ps = sim->ps;
  const double *X0 = ps->field[SPH_FIELD_POSITION0];
  sph_domain *dom = sim->domain;
  size_t n = ps->n, cap = 0;
  /* other ranks' particles within a support of ours (and of our images) */
  size_t ng = sph_domain_ghosts(dom), nr = n + ng;
  plane planes[32];
  int oblique = 0, np = images ? scene_planes(s, planes, &oblique) : 0;
  if (side)
    for (int k = 0; k < np; ++k)
      planes[k].side = side[k];
  else
    plane_sides(planes, np, ps, dom);
  SPH_TRY(grow_points(r, nr + 1, &cap, oblique, err));
  memcpy(r->X, X0, 3 * n * sizeof(double));
  memcpy(r->V, ps->field[SPH_FIELD_VOLUME0], n * sizeof(double));
  memcpy(r->body, ps->body, n * sizeof(int32_t));
  if (ng) {
    memcpy(r->X + 3 * n, sph_domain_ghost_X(dom), 3 * ng * sizeof(double));
    memcpy(r->V + n, sph_domain_ghost_volume(dom), ng * sizeof(double));
    memcpy(r->body + n, sph_domain_ghost_body(dom), ng * sizeof(int32_t));
  }
  for (size_t a = 0; a < nr; ++a) {
    r->src[a] = (int32_t)a;
    memset(r->vsign + 3 * a, 1, 3);
    memset(r->rsign + 3 * a, 1, 3);
    r->ssign[a] = 1;
    if (oblique)
      sph_mat3_identity(r->vmat + 9 * a);
  }
  /* over ranks the real points in the serial storage order */
  stored *order = NULL;
  if (np && dom) {
    const int64_t *gidx = sph_domain_storage_index(dom);
    if (!(order = malloc(nr * sizeof *order)))
      return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
    for (size_t a = 0; a < nr; ++a)
      order[a] = (stored){gidx[a], a};
    qsort(order, nr, sizeof *order, cmp_stored);
  }
  size_t total = nr;
  if (np) {
    double layer = 2.0 * sim->kernel.support, q = 1e-6 * sim->dp;
    hash h = {0};
    h.cap = 16 * nr > 65536 ? 16 * nr : 65536;
    h.key = malloc(3 * h.cap * sizeof *h.key);
    h.used = calloc(h.cap, 1);
    if (!h.key || !h.used) {
      free(h.key);
      free(h.used);
      free(order);
      return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
    }
    sph_status st = SPH_OK;
    int full = 0;
    for (size_t a = 0; a < nr; ++a) {
      int64_t key[3];
      for (int c = 0; c < 3; ++c)
        key[c] = llround(r->X[3 * a + c] / q);
      hash_insert(&h, key);
    }
    for (int pass = 0; pass < 2 && st == SPH_OK; ++pass)
      for (int k = 0; k < np && st == SPH_OK; ++k) {
        plane *pl = &planes[k];
        size_t count = total;
        for (size_t v = pl->done; v < count && st == SPH_OK; ++v) {
          size_t i = order && v < nr ? order[v].i : v;
          if (pl->body >= 0 && r->body[i] != pl->body)
            continue;
          double dist = plane_distance(pl, r->X + 3 * i), d = dist * pl->side;
          if (d <= 0.0 || d >= layer)
            continue;
          double Xn[3] = {r->X[3 * i], r->X[3 * i + 1], r->X[3 * i + 2]};
          if (pl->axis >= 0)
            Xn[pl->axis] = 2.0 * pl->at - Xn[pl->axis];
          else
            for (int c = 0; c < 3; ++c)
              Xn[c] -= 2.0 * dist * pl->n[c];
          int64_t key[3];
          for (int c = 0; c < 3; ++c)
            key[c] = llround(Xn[c] / q);
          int ins = hash_insert(&h, key);
          if (ins < 0)
            full = 1;
          if (ins <= 0)
            continue;
          if ((st = grow_points(r, total + 1, &cap, oblique, err)) != SPH_OK)
            break;
          memcpy(r->X + 3 * total, Xn, sizeof Xn);
          r->V[total] = r->V[i];
          r->body[total] = r->body[i];
          r->src[total] = r->src[i];
          r->ssign[total] = (signed char)(r->ssign[i] * pl->sigma);
          for (int c = 0; c < 3; ++c) {
            r->rsign[3 * total + c] =
                (signed char)(r->rsign[3 * i + c] * (c == pl->axis ? -1 : 1));
            r->vsign[3 * total + c] =
                (signed char)(r->ssign[total] * r->rsign[3 * total + c]);
          }
          /* vmat of the image: sigma (I - 2 n n^T) vmat of its source */
          for (int a = 0; oblique && a < 3; ++a)
            for (int b = 0; b < 3; ++b) {
              const double *M = r->vmat + 9 * i;
              double m =
                  M[3 * a + b] - 2.0 * pl->n[a] *
                                     (pl->n[0] * M[b] + pl->n[1] * M[3 + b] +
                                      pl->n[2] * M[6 + b]);
              r->vmat[9 * total + 3 * a + b] = pl->sigma * m;
            }
          ++total;
        }
        pl->done = count;
      }
    free(h.key);
    free(h.used);
    if (st == SPH_OK && full)
      st = sph_error_set(err, SPH_ERR_NOMEM, "mirror image table is full");
    if (st != SPH_OK) {
      free(order);
      return st;
    }
  }
  size_t ni = total - ng; /* owned and images */
  /* an updated-Lagrangian run over ranks holds up to the domain's capacity */
  size_t hold = sph_domain_capacity(dom, ps);
  r->cap = total > hold ? total : hold;
  SPH_TRY(grow_points(r, r->cap, &cap, oblique, err));
  if (dom && !sph_domain_migrates(dom)) { /* the serial order of points */
    const int64_t *gidx = sph_domain_storage_index(dom);
    sph_status st = (r->key = malloc(r->cap * sizeof *r->key))
                        ? SPH_OK
                        : sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
    for (size_t a = 0; st == SPH_OK && a < total; ++a)
      r->key[a < n    ? a
             : a < nr ? a + ni - n
                      : a - ng] =
          a < nr ? gidx[a] : ((int64_t)1 << 40) + (int64_t)a;
    if (st != SPH_OK) {
      free(order);
      return st;
    }
  }
  free(order);
  /* the ghosts behind the images; sources renumbered to match */
  size_t m = total - nr;
  for (size_t a = n; ng && a < total; ++a)
    if ((size_t)r->src[a] >= n)
      r->src[a] += (int32_t)((size_t)r->src[a] < nr ? m : 0);
  if (ng && m) {
    SPH_TRY(rotate_points(r->X, 3 * sizeof *r->X, n, ng, m, err));
    SPH_TRY(rotate_points(r->V, sizeof *r->V, n, ng, m, err));
    SPH_TRY(rotate_points(r->body, sizeof *r->body, n, ng, m, err));
    SPH_TRY(rotate_points(r->src, sizeof *r->src, n, ng, m, err));
    SPH_TRY(rotate_points(r->vsign, 3, n, ng, m, err));
    SPH_TRY(rotate_points(r->rsign, 3, n, ng, m, err));
    SPH_TRY(rotate_points(r->ssign, 1, n, ng, m, err));
    if (oblique)
      SPH_TRY(rotate_points(r->vmat, 9 * sizeof *r->vmat, n, ng, m, err));
  }
  r->n = n;
  r->n_img = ni;
  r->n_ext = total;
  r->sync_images = dom && np;
  if (!sph_domain_migrates(dom)) /* a dynamic domain's ghosts follow ps */
    sph_domain_set_ghost_base(dom, ni);
  r->mirror = (sph_mirror){.n_real = n,
                           .n_ghost = ni - n,
                           .src = r->src + n,
                           .vsign = r->vsign + 3 * n,
                           .vmat = oblique ? r->vmat + 9 * n : NULL,
                           .ssign = r->ssign + n};
  return SPH_OK;
}

static int cmp_row(const void *pa, const void *pb) {
  const int64_t *a = pa, *b = pb;
  return (a[0] > b[0]) - (a[0] < b[0]);
}

/* Over MPI ranks with a dynamic domain: the serial images, kept as
 * r->all_images, built over the real points within four supports of a
 * plane, gathered from every rank in storage order (the images' sources lie
 * within two, the real points an image could coincide with within two and
 * a rounding; the planes' sides are the whole set's); the local points are
 * the owned particles, with room for the images the method places. */
static sph_status build_images_dynamic(tl_reference *r, sph_sim *sim,
                                       sph_error *err) {
  sph_particles *ps = sim->ps;
  sph_domain *dom = sim->domain;
  const double *X0 = ps->field[SPH_FIELD_POSITION0];
  const int64_t *gidx = sph_domain_storage_index(dom);
  size_t n = ps->n;
  double count = (double)n;
  sph_domain_sum(dom, &count, 1);
  size_t N = (size_t)count;
  plane planes[32];
  int side[32], oblique = 0, np = scene_planes(sim->scene, planes, &oblique);
  plane_sides(planes, np, ps, dom);
  for (int k = 0; k < np; ++k)
    side[k] = planes[k].side;
  /* rows of 6 words: storage index, then the bits of X, V and the body */
  double near = 4.0 * sim->kernel.support;
  int64_t *mine = malloc((6 * n + 1) * sizeof *mine), *all = NULL;
  size_t m = 0, total = 0;
  sph_particles *part = NULL;
  tl_reference g = {0};
  tl_images *t = calloc(1, sizeof *t);
  sph_status st =
      mine && t ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
  for (size_t a = 0; st == SPH_OK && a < n; ++a) {
    int in = 0;
    for (int k = 0; k < np; ++k)
      in |= fabs(plane_distance(&planes[k], X0 + 3 * a)) < near;
    if (!in)
      continue;
    int64_t *row = mine + 6 * m++;
    row[0] = gidx[a];
    memcpy(row + 1, X0 + 3 * a, 3 * sizeof *row);
    memcpy(row + 4, ps->field[SPH_FIELD_VOLUME0] + a, sizeof *row);
    row[5] = ps->body[a];
  }
  st = sph_domain_agree(dom, st, err);
  if (st == SPH_OK)
    st = sph_domain_allgather_i64(dom, mine, 6 * m, &all, &total, NULL, err);
  size_t P = total / 6;
  if (st == SPH_OK) {
    qsort(all, P, 6 * sizeof *all, cmp_row);
    st = sph_particles_create(&part, P, ps->dim, err);
  }
  if (st == SPH_OK)
    st = sph_particles_require(part, SPH_FIELD_POSITION0, err);
  if (st == SPH_OK)
    st = sph_particles_require(part, SPH_FIELD_VOLUME0, err);
  if (st == SPH_OK) {
    part->n = P;
    for (size_t i = 0; i < P; ++i) {
      memcpy(part->field[SPH_FIELD_POSITION0] + 3 * i, all + 6 * i + 1,
             3 * sizeof *all);
      memcpy(part->field[SPH_FIELD_VOLUME0] + i, all + 6 * i + 4, sizeof *all);
      part->body[i] = (int32_t)all[6 * i + 5];
    }
    sph_sim serial = *sim; /* the serial run's images */
    serial.ps = part;
    serial.domain = NULL;
    st = build_images(&g, &serial, 1, side, err);
  }
  size_t M = st == SPH_OK ? g.n_img - P : 0;
  int *per = NULL;
  if (st == SPH_OK) {
    t->m = M;
    t->n_real = N;
    t->src = malloc((M + 1) * sizeof *t->src);
    t->vsign = malloc(3 * M + 1);
    t->rsign = malloc(3 * M + 1);
    t->ssign = malloc(M + 1);
    t->X = malloc((3 * M + 1) * sizeof *t->X);
    t->vmat = g.vmat ? malloc((9 * M + 1) * sizeof *t->vmat) : NULL;
    per = calloc(P + 1, sizeof *per);
    if (!t->src || !t->vsign || !t->rsign || !t->ssign || !t->X || !per ||
        (g.vmat && !t->vmat))
      st = sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
  }
  for (size_t j = 0; st == SPH_OK && j < M; ++j) {
    size_t i = P + j;
    t->src[j] = (int32_t)all[6 * (size_t)g.src[i]];
    memcpy(t->vsign + 3 * j, g.vsign + 3 * i, 3);
    memcpy(t->rsign + 3 * j, g.rsign + 3 * i, 3);
    t->ssign[j] = g.ssign[i];
    memcpy(t->X + 3 * j, g.X + 3 * i, 3 * sizeof *t->X);
    if (t->vmat)
      memcpy(t->vmat + 9 * j, g.vmat + 9 * i, 9 * sizeof *t->vmat);
    int c = ++per[g.src[i]];
    t->k = c > t->k ? c : t->k;
  }
  free(per);
  free(mine);
  free(all);
  sph_particles_destroy(part);
  tl_reference_destroy(&g);
  r->all_images = t;
  SPH_TRY(st);
  SPH_TRY(build_images(r, sim, 0, NULL, err));
  size_t cap = 0;
  r->cap += M;
  SPH_TRY(grow_points(r, r->cap, &cap, t->vmat != NULL, err));
  if (!(r->key = malloc(r->cap * sizeof *r->key)))
    return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
  return SPH_OK;
}

/* ---- reference configuration
 * -------------------------------------------------- */

/* binary search for a in b's list */
sph_status tl_reference_reverse_slots(const tl_reference *ref, size_t **out,
                                      sph_error *err) {
  const sph_neighbors *nl = ref->nl;
  size_t *rev = malloc((nl->count ? nl->count : 1) * sizeof *rev);
  if (!rev)
    return sph_error_set(err, SPH_ERR_NOMEM, "reverse slots");
  sph_status st = tl_reference_reverse_fill(ref, rev, err);
  if (st != SPH_OK) {
    free(rev);
    return st;
  }
  *out = rev;
  return SPH_OK;
}

sph_status tl_reference_reverse_fill(const tl_reference *ref, size_t *rev,
                                     sph_error *err) {
  const sph_neighbors *nl = ref->nl;
  long n = (long)nl->n, missing = 0;
#pragma omp parallel for schedule(static) reduction(+ : missing)
  for (long a = 0; a < n; ++a)
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      size_t lo = nl->offset[b], hi = nl->offset[b + 1];
      while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (nl->index[mid] < (int32_t)a)
          lo = mid + 1;
        else
          hi = mid;
      }
      /* a distributed run's lists ascend in the serial storage order,
       * not in the local one: then look through b's list */
      if (!(lo < nl->offset[b + 1] && nl->index[lo] == (int32_t)a))
        for (lo = nl->offset[b]; lo < nl->offset[b + 1]; ++lo)
          if (nl->index[lo] == (int32_t)a)
            break;
      if (lo < nl->offset[b + 1])
        rev[k] = lo;
      else
        ++missing;
    }
  if (missing)
    return sph_error_set(err, SPH_ERR_ARG, "neighbour lists are not symmetric");
  return SPH_OK;
}

sph_status tl_ghost_slots(const sph_sim *sim, const tl_reference *ref,
                          const sph_cloud *cloud, sph_gradient_kind kind,
                          const size_t *rev, double *grad, double *lap,
                          sph_error *err) {
  if (!sim->domain)
    return SPH_OK;
  size_t ne = ref->n_ext, ni = ref->n_img, nc = SPH_CORRECTION_COEFS;
  double *coef = calloc(nc * ne + 1, sizeof *coef);
  double *part = calloc(9 * ne + 1, sizeof *part);
  sph_status st =
      coef && part
          ? sph_correction_coefficients(cloud, kind, lap != NULL, coef, err)
          : sph_error_set(err, SPH_ERR_NOMEM, "ghost coefficients");
  st = sph_domain_agree(sim->domain, st, err);
  /* the ghosts' from their owners, in parts of at most 9 */
  for (size_t j = 0; st == SPH_OK && j < nc; j += 9) {
    size_t w = nc - j < 9 ? nc - j : 9;
    for (size_t a = 0; a < ni; ++a)
      memcpy(part + w * a, coef + nc * a + j, w * sizeof *part);
    st = sph_domain_exchange(sim->domain, part, (int)w, err);
    for (size_t a = ni; st == SPH_OK && a < ne; ++a)
      memcpy(coef + nc * a + j, part + w * a, w * sizeof *part);
  }
  const sph_neighbors *nl = ref->nl;
  for (size_t a = 0; st == SPH_OK && a < ni; ++a)
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      double l;
      if (b < ni)
        continue;
      sph_correction_slot(cloud, kind, coef + nc * b, b, a, grad + 3 * rev[k],
                          &l);
      if (lap)
        lap[rev[k]] = l;
    }
  free(coef);
  free(part);
  return st;
}

/* w_ab = V_b W'(r) / r per slot and s_a = sum_b w_ab r_ab */
static void pair_weights(tl_reference *ref, const sph_kernel *kernel) {
  const sph_neighbors *nl = ref->nl;
  long ne = (long)ref->n_ext;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ne; ++a) {
    double s[3] = {0, 0, 0};
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      double r[3];
      tl_iact_pair_vector(ref->X, (size_t)a, b, r);
      double d = sqrt(sph_vec3_dot(r, r));
      ref->w[k] = d > 0.0 ? ref->V[b] * sph_kernel_dwdr(kernel, d) / d : 0.0;
      for (int c = 0; c < 3; ++c)
        s[c] += ref->w[k] * r[c];
    }
    if (a < (long)ref->n)
      memcpy(ref->s + 3 * a, s, sizeof s);
  }
}

void tl_reference_gradient(const tl_reference *ref, size_t a, size_t k,
                           double g[3]) {
  size_t b = (size_t)ref->nl->index[k];
  double r[3];
  tl_iact_pair_vector(ref->X, a, b, r);
  for (int c = 0; c < 3; ++c)
    r[c] *= ref->w[k] / ref->V[b];
  sph_mat3_vec(ref->L + 9 * a, r, g);
}

void tl_conservative_force(const tl_reference *ref, double *dp) {
  long n = (long)ref->n;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    tl_sums s;
    tl_pair_sums(ref, (size_t)a, NULL, 1, NULL, &s);
    double G[9], f[3], self[3];
    tl_sums_store(&s, G, f);
    tl_iact_force_self(ref->Qt + 9 * a, ref->s + 3 * a, self);
    for (int c = 0; c < 3; ++c)
      dp[3 * a + c] = f[c] + self[c];
  }
}

sph_status tl_reference_alloc(const tl_reference *ref, size_t ncomp,
                              double **out, sph_error *err) {
  *out = calloc(ncomp * ref->cap + 1, sizeof **out);
  return *out ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "state arrays");
}

/* the lists (sorted in the serial order over ranks), w's room and the
 * corrections of the points whose lists are whole */
static sph_status rebuild_local(tl_reference *ref, const sph_sim *sim,
                                sph_error *err) {
  const sph_scene *s = sim->scene;
  size_t ne = ref->n_ext;
  /* neighbours and corrected gradients in the reference configuration */
  SPH_TRY(sph_neighbors_build(ref->nl, ref->X, ne, s->dimension,
                              sim->kernel.support, ref->body,
                              SPH_PAIRS_SAME_BODY, err));
  /* a distributed run sums pairs in the serial run's order */
  if (ref->key)
    sph_domain_sort_lists_by(ref->nl, ref->n_img, ref->key);
  else
    sph_domain_sort_lists(sim->domain, ref->nl, ref->n_img);
  if (ref->nl->count + 1 > ref->w_cap) { /* grows only, amortised */
    size_t cap = 2 * (ref->nl->count + 1);
    double *w = realloc(ref->w, cap * sizeof *w);
    if (!w)
      return sph_error_set(err, SPH_ERR_NOMEM, "pair weights");
    ref->w = w;
    ref->w_cap = cap;
  }
  /* ghosts lack part of their neighbourhood: their L comes from the owner */
  size_t whole = ref->n_whole ? ref->n_whole : ref->n_img;
  /* so may the images of ghosts far from the owned particles: unused */
  size_t n = ref->n;
  int flag = sim->domain && !ref->n_whole && ref->n_img > n;
  if (flag && ref->n_img > ref->partial_cap) { /* grows only */
    unsigned char *p = realloc(ref->partial, ref->n_img);
    if (!p)
      return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
    ref->partial = p;
    ref->partial_cap = ref->n_img;
  }
  const sph_neighbors *nl = ref->nl;
  long ni = flag ? (long)ref->n_img : 0;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ni; ++a) {
    int near = a < (long)n;
    for (size_t k = nl->offset[a]; !near && k < nl->offset[a + 1]; ++k)
      near = (size_t)nl->index[k] < n;
    ref->partial[a] = (unsigned char)!near;
  }
  sph_cloud cloud = {.n = sim->domain ? whole : ne,
                     .partial = flag ? ref->partial : NULL,
                     .dim = s->dimension,
                     .x = ref->X,
                     .volume = ref->V,
                     .id = ref->id,
                     .nl = ref->nl,
                     .kernel = &sim->kernel};
  return sph_correction_gradient(&cloud, SPH_GRAD_CORRECTED, NULL, NULL, ref->L,
                                 err);
}

sph_status tl_reference_rebuild(tl_reference *ref, const sph_sim *sim,
                                sph_error *err) {
  /* a rank that fails alone must not leave the others in the exchange */
  SPH_TRY(sph_domain_agree(sim->domain, rebuild_local(ref, sim, err), err));
  SPH_TRY(sph_domain_exchange(sim->domain, ref->L, 9, err));
  pair_weights(ref, &sim->kernel);
  return SPH_OK;
}

sph_status tl_reference_redistribute(tl_reference *ref, sph_sim *sim,
                                     sph_error *err) {
  sph_particles *ps = sim->ps;
  if (!sim->domain || sim->method->distributed != SPH_DISTRIBUTED_DYNAMIC)
    return SPH_OK;
  SPH_TRY(sph_domain_rebuild(sim->domain, ps, sim->kernel.support, err));
  const sph_scene *s = sim->scene;
  ref->n = ref->n_img = ps->n;
  ref->n_ext = ps->n + sph_domain_ghosts(sim->domain);
  for (size_t a = 0; a < ref->n_ext; ++a) {
    const sph_body *b = &s->bodies[ps->body[a]];
    ref->body[a] = ps->body[a];
    ref->id[a] = ps->id[a];
    ref->mat[a] = &s->materials[b->material];
    ref->rho0[a] = ref->mat[a]->density;
    if (ref->axes)
      ref->axes[a] = b->transform.given ? b->transform.R : NULL;
  }
  return sph_sim_terms_renumber(sim, err);
}

sph_status tl_reference_create(tl_reference *ref, sph_sim *sim, int images,
                               sph_error *err) {
  memset(ref, 0, sizeof *ref);
  const sph_scene *s = sim->scene;
  sph_particles *ps = sim->ps;
  int timer = sph_sim_add_timer(sim, "corrections");
  double t0 = sph_wtime();
  int planes = 0;
  for (size_t k = 0; images && k < s->nboundaries; ++k)
    planes |= s->boundaries[k].kind == SPH_BC_SYMMETRY ||
              s->boundaries[k].kind == SPH_BC_SKEW_SYMMETRY;
  if (planes && sph_domain_migrates(sim->domain))
    SPH_TRY(build_images_dynamic(ref, sim, err));
  else
    SPH_TRY(build_images(ref, sim, images, NULL, err));
  size_t n = ref->n, ne = ref->n_ext;
  if (ref->n_img > n)
    sim->mirror = &ref->mirror;

  /* per-point material and density, the fastest wave */
  ref->mat = malloc(ref->cap * sizeof *ref->mat);
  ref->rho0 = malloc(ref->cap * sizeof *ref->rho0);
  if (!ref->mat || !ref->rho0)
    return sph_error_set(err, SPH_ERR_NOMEM, "materials");
  for (size_t a = 0; a < ne; ++a) {
    ref->mat[a] = &s->materials[s->bodies[ref->body[a]].material];
    ref->rho0[a] = ref->mat[a]->density;
  }
  int placed = 0;
  for (size_t b = 0; b < s->nbodies; ++b) {
    double c = sph_material_wave_speed(&s->materials[s->bodies[b].material]);
    ref->cp = c > ref->cp ? c : ref->cp;
    placed |= s->bodies[b].transform.given;
  }
  /* the material axes of placed bodies turn with them */
  if (placed &&
      !(ref->axes = malloc((ref->cap ? ref->cap : 1) * sizeof *ref->axes)))
    return sph_error_set(err, SPH_ERR_NOMEM, "materials");
  for (size_t a = 0; placed && a < n; ++a) {
    const sph_transform *T = &s->bodies[ref->body[a]].transform;
    ref->axes[a] = T->given ? T->R : NULL;
  }

  /* state and output fields */
  static const sph_field need[] = {SPH_FIELD_POSITION,  SPH_FIELD_MOMENTUM,
                                   SPH_FIELD_DEFGRAD,   SPH_FIELD_JACOBIAN,
                                   SPH_FIELD_PK1,       SPH_FIELD_DISPLACEMENT,
                                   SPH_FIELD_STRESS,    SPH_FIELD_PRESSURE,
                                   SPH_FIELD_VON_MISES, SPH_FIELD_MASS};
  for (size_t i = 0; i < sizeof need / sizeof *need; ++i)
    SPH_TRY(sph_particles_require(ps, need[i], err));
  for (int i = 0; i < s->output.nfields; ++i)
    if (s->output.fields[i] == SPH_FIELD_ACCELERATION)
      SPH_TRY(sph_particles_require(ps, SPH_FIELD_ACCELERATION, err));
  ref->owns_state = ne > n || ref->all_images;
  if (ref->owns_state) {
    SPH_TRY(tl_reference_alloc(ref, 3, &ref->x, err));
    SPH_TRY(tl_reference_alloc(ref, 3, &ref->p, err));
    SPH_TRY(tl_reference_alloc(ref, 9, &ref->F, err));
    SPH_TRY(tl_reference_alloc(ref, 1, &ref->J, err));
    SPH_TRY(tl_reference_alloc(ref, 9, &ref->P, err));
  } else {
    ref->x = ps->field[SPH_FIELD_POSITION];
    ref->p = ps->field[SPH_FIELD_MOMENTUM];
    ref->F = ps->field[SPH_FIELD_DEFGRAD];
    ref->J = ps->field[SPH_FIELD_JACOBIAN];
    ref->P = ps->field[SPH_FIELD_PK1];
  }
  /* a reference's initial state comes deformed (reference.h) */
  const double *x0 =
      sim->initial_defgrad ? ps->field[SPH_FIELD_POSITION] : ref->X;
  for (size_t a = 0; a < n; ++a) {
    if (ref->x != x0)
      memcpy(ref->x + 3 * a, x0 + 3 * a, 3 * sizeof(double));
    for (int c = 0; c < 3; ++c)
      ref->p[3 * a + c] =
          ref->rho0[a] * ps->field[SPH_FIELD_VELOCITY][3 * a + c];
    if (sim->initial_defgrad)
      memcpy(ref->F + 9 * a, ps->field[SPH_FIELD_DEFGRAD] + 9 * a,
             9 * sizeof(double));
    else
      sph_mat3_identity(ref->F + 9 * a);
    ref->J[a] = sph_mat3_det(ref->F + 9 * a);
    ps->field[SPH_FIELD_MASS][a] = ref->rho0[a] * ref->V[a];
  }
  tl_mirror_refresh(ref, ref->x, ref->p, ref->F, NULL, ref->J);

  int64_t *id = malloc(ref->cap * sizeof *id);
  if (!id)
    return sph_error_set(err, SPH_ERR_NOMEM, "ids");
  for (size_t a = 0; a < ne; ++a) { /* an image's is its source's */
    size_t r = (size_t)ref->src[a];
    id[a] =
        r < n ? ps->id[r] : sph_domain_ghost_id(sim->domain)[r - ref->n_img];
  }
  ref->id = id;
  ref->s = calloc(3 * ref->cap + 3, sizeof *ref->s);
  if (!ref->s)
    return sph_error_set(err, SPH_ERR_NOMEM, "pair weights");
  SPH_TRY(tl_reference_alloc(ref, 9, &ref->L, err));
  SPH_TRY(tl_reference_alloc(ref, 9, &ref->Qt, err));
  SPH_TRY(sph_neighbors_create(&ref->nl, err));
  sph_status st = tl_reference_rebuild(ref, sim, err);
  sim->timers[timer].seconds += sph_wtime() - t0;
  sim->timers[timer].calls++;
  return st;
}

void tl_reference_destroy(tl_reference *ref) {
  sph_neighbors_destroy(ref->nl);
  free(ref->id);
  free(ref->w);
  free(ref->partial);
  free(ref->L);
  free(ref->s);
  free(ref->Qt);
  free(ref->mat);
  free(ref->rho0);
  free(ref->X);
  free(ref->V);
  free(ref->body);
  free(ref->src);
  free(ref->vsign);
  free(ref->rsign);
  free(ref->ssign);
  free(ref->vmat);
  free(ref->key);
  free(ref->axes);
  if (ref->all_images) {
    free(ref->all_images->src);
    free(ref->all_images->vsign);
    free(ref->all_images->rsign);
    free(ref->all_images->ssign);
    free(ref->all_images->vmat);
    free(ref->all_images->X);
    free(ref->all_images);
  }
  if (ref->owns_state) {
    free(ref->x);
    free(ref->p);
    free(ref->F);
    free(ref->J);
    free(ref->P);
  }
  memset(ref, 0, sizeof *ref);
}

/* image of a two-point tensor: I + sigma R (A - I) R */
static inline void mirror_tensor(const double *A, double *out, int sigma,
                                 const signed char *R) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out[3 * i + j] =
          (i == j) + sigma * R[i] * R[j] * (A[3 * i + j] - (i == j));
}

/* image of a two-point tensor across oblique planes: I + sigma M (A - I) M^T
 * with M = vmat (sigma^2 = 1 makes it Q (A - I) Q^T for the reflection Q) */
static inline void mirror_tensor_oblique(const double *A, double *out,
                                         int sigma, const double *M) {
  double B[9], T[9];
  memcpy(B, A, sizeof B);
  B[0] -= 1.0, B[4] -= 1.0, B[8] -= 1.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      T[3 * i + j] = B[3 * i] * M[3 * j] + B[3 * i + 1] * M[3 * j + 1] +
                     B[3 * i + 2] * M[3 * j + 2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out[3 * i + j] =
          (i == j) + sigma * (M[3 * i] * T[j] + M[3 * i + 1] * T[3 + j] +
                              M[3 * i + 2] * T[6 + j]);
}

static void mirror_refresh_oblique(const tl_reference *ref, double *x,
                                   double *p, double *F, double *H, double *J) {
  long n = (long)ref->n, ne = (long)ref->n_img;
#pragma omp parallel for schedule(static)
  for (long g = n; g < ne; ++g) {
    size_t s = (size_t)ref->src[g];
    const double *M = ref->vmat + 9 * g;
    int sigma = ref->ssign[g];
    double u[3] = {x[3 * s] - ref->X[3 * s], x[3 * s + 1] - ref->X[3 * s + 1],
                   x[3 * s + 2] - ref->X[3 * s + 2]};
    for (int c = 0; c < 3; ++c) {
      const double *m = M + 3 * c;
      x[3 * g + c] =
          ref->X[3 * g + c] + m[0] * u[0] + m[1] * u[1] + m[2] * u[2];
      p[3 * g + c] =
          m[0] * p[3 * s] + m[1] * p[3 * s + 1] + m[2] * p[3 * s + 2];
    }
    mirror_tensor_oblique(F + 9 * s, F + 9 * g, sigma, M);
    if (H)
      mirror_tensor_oblique(H + 9 * s, H + 9 * g, sigma, M);
    if (J)
      J[g] = 1.0 + sigma * (J[s] - 1.0);
  }
}

void tl_mirror_refresh(const tl_reference *ref, double *x, double *p, double *F,
                       double *H, double *J) {
  if (ref->vmat) {
    mirror_refresh_oblique(ref, x, p, F, H, J);
    return;
  }
  long n = (long)ref->n, ne = (long)ref->n_img;
#pragma omp parallel for schedule(static)
  for (long g = n; g < ne; ++g) {
    size_t s = (size_t)ref->src[g];
    const signed char *S = ref->vsign + 3 * g, *R = ref->rsign + 3 * g;
    int sigma = ref->ssign[g];
    for (int c = 0; c < 3; ++c) {
      x[3 * g + c] =
          ref->X[3 * g + c] + S[c] * (x[3 * s + c] - ref->X[3 * s + c]);
      p[3 * g + c] = S[c] * p[3 * s + c];
    }
    mirror_tensor(F + 9 * s, F + 9 * g, sigma, R);
    if (H)
      mirror_tensor(H + 9 * s, H + 9 * g, sigma, R);
    if (J)
      J[g] = 1.0 + sigma * (J[s] - 1.0);
  }
}

sph_status tl_image_sources(const sph_sim *sim, const tl_reference *ref,
                            double *field, int ncomp, sph_error *err) {
  if (!ref->sync_images)
    return SPH_OK;
  return sph_domain_exchange(sim->domain, field, ncomp, err);
}

void tl_derive(sph_sim *sim, const tl_reference *ref, const double *H,
               const double *J, const double *Fs) {
  sph_particles *ps = sim->ps;
  long n = (long)ps->n;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  const double *x = ref->x, *p = ref->p, *F = ref->F, *P = ref->P;
  double *v = ps->field[SPH_FIELD_VELOCITY];
  double *u = ps->field[SPH_FIELD_DISPLACEMENT];
  double *Jf = ps->field[SPH_FIELD_JACOBIAN];
  double *sig = ps->field[SPH_FIELD_STRESS];
  double *pr = ps->field[SPH_FIELD_PRESSURE];
  double *vm = ps->field[SPH_FIELD_VON_MISES];
  if (ref->owns_state) {
    memcpy(ps->field[SPH_FIELD_POSITION], x, 3 * (size_t)n * sizeof *x);
    memcpy(ps->field[SPH_FIELD_MOMENTUM], p, 3 * (size_t)n * sizeof *p);
    memcpy(ps->field[SPH_FIELD_DEFGRAD], F, 9 * (size_t)n * sizeof *F);
    memcpy(ps->field[SPH_FIELD_PK1], P, 9 * (size_t)n * sizeof *P);
  }
  (void)H;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    for (int c = 0; c < 3; ++c) {
      v[3 * a + c] = p[3 * a + c] / ref->rho0[a];
      u[3 * a + c] = x[3 * a + c] - X[3 * a + c];
    }
    const double *Fa = (Fs ? Fs : F) + 9 * a;
    double detF = sph_mat3_det(Fa);
    Jf[a] = J ? J[a] : detF;
    /* Cauchy stress sigma = P F^T / det F */
    double Ft[9], S[9];
    sph_mat3_transpose(Fa, Ft);
    sph_mat3_mul(P + 9 * a, Ft, S);
    for (int k = 0; k < 9; ++k)
      S[k] /= detF;
    memcpy(sig + 9 * a, S, sizeof S);
    double mean = sph_mat3_trace(S) / 3.0, dev2 = 0.0;
    pr[a] = mean;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double d = S[3 * i + j] - (i == j) * mean;
        dev2 += d * d;
      }
    vm[a] = sqrt(1.5 * dev2);
  }
}

double tl_max_wave_speed(const tl_reference *ref, const double *F) {
  long n = (long)ref->n;
  double c2max = 0.0;
#pragma omp parallel for schedule(static) reduction(max : c2max)
  for (long a = 0; a < n; ++a) {
    const double *Fa = F + 9 * a;
    const sph_material *m = ref->mat[a];
    double Q[27], Fb[9], T[9];
    if (ref->axes && ref->axes[a]) { /* F in the body frame: R^T F R */
      const double *R = ref->axes[a];
      sph_mat3_mul(Fa, R, T);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          Fb[3 * i + j] =
              R[i] * T[j] + R[3 + i] * T[3 + j] + R[6 + i] * T[6 + j];
      Fa = Fb;
    }
    sph_material_acoustic_tensors(m, Fa, Q);
    for (int d = 0; d < 3; ++d) {
      double lo, hi;
      sph_mat3_sym_extremes(Q + 9 * d, &lo, &hi);
      double c2 = hi / m->density;
      c2max = c2 > c2max ? c2 : c2max;
    }
  }
  return sqrt(c2max);
}

double tl_stable_dt(const tl_reference *ref, const sph_sim *sim, double cfl,
                    int current) {
  double c = ref->cp;
  if (current) {
    double cs = tl_max_wave_speed(ref, ref->F);
    c = cs > c ? cs : c;
  }
  return cfl * sim->dp / c;
}

sph_status tl_check_finite(const tl_reference *ref, sph_error *err) {
  long n3 = 3 * (long)ref->n, first = n3;
  /* the lowest non-finite entry, whatever the thread count */
#pragma omp parallel for schedule(static) reduction(min : first)
  for (long i = 0; i < n3; ++i)
    if (!isfinite(ref->p[i]) || !isfinite(ref->x[i]))
      first = i < first ? i : first;
  if (first < n3)
    return sph_error_set(err, SPH_ERR_NUMERIC,
                         "nan: non-finite state at particle %ld", first / 3);
  return SPH_OK;
}

void tl_energy(sph_sim *sim, const tl_reference *ref, const double *H,
               const double *J, double *kinetic, double *strain) {
  const double *V = ref->V, *p = ref->p, *F = ref->F;
  double ek = 0.0, es = 0.0;
  for (size_t a = 0; a < ref->n; ++a) {
    double Ha[9];
    const double *Fa = F + 9 * a;
    if (H)
      memcpy(Ha, H + 9 * a, sizeof Ha);
    else
      sph_mat3_cofactor(Fa, Ha);
    double Ja = J ? J[a] : sph_mat3_det(Fa);
    ek += V[a] * sph_vec3_dot(p + 3 * a, p + 3 * a) / (2 * ref->rho0[a]);
    es += V[a] * sph_material_energy(ref->mat[a], Fa, Ha, Ja);
  }
  *kinetic = ek;
  *strain = es;
  (void)sim;
}

void tl_acceleration(sph_sim *sim, const tl_reference *ref, const double *dp) {
  double *acc = sim->ps->field[SPH_FIELD_ACCELERATION];
  long n = (long)ref->n;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c)
      acc[3 * a + c] = dp[3 * a + c] / ref->rho0[a];
}

sph_status tl_leapfrog_options(sph_node *opt, double *cfl, sph_error *err) {
  SPH_TRY(sph_node_get_double(opt, "cfl", 0, 0.3, cfl, err));
  if (!(*cfl > 0.0 && *cfl <= 1.0))
    return sph_node_error(sph_node_child(opt, "cfl"), err, SPH_ERR_RANGE,
                          "cfl must be in (0, 1], got %g", *cfl);
  const char *integ;
  SPH_TRY(sph_node_get_string(opt, "integrator", 0, "leapfrog", &integ, err));
  if (strcmp(integ, "leapfrog"))
    return sph_node_error(sph_node_child(opt, "integrator"), err, SPH_ERR_RANGE,
                          "'%s' is not one of: leapfrog", integ);
  return SPH_OK;
}

sph_status
tl_leapfrog_attach(sph_sim *sim, const tl_reference *ref, sph_leapfrog *lf,
                   double *dp,
                   sph_status (*rates)(void *ctx, double t, sph_error *err),
                   sph_status (*constrain)(void *ctx, double t, sph_error *err),
                   void *ctx, sph_error *err) {
  *lf = (sph_leapfrog){.n = ref->n,
                       .x = ref->x,
                       .p = ref->p,
                       .dp = dp,
                       .rho0 = ref->rho0,
                       .rates = rates,
                       .constrain = constrain,
                       .ctx = ctx};
  SPH_TRY(tl_external_terms_create(sim, ref, err));
  return tl_essential_bc_attach(sim, ref, constrain, ctx, err);
}

sph_status tl_external_terms_create(sph_sim *sim, const tl_reference *ref,
                                    sph_error *err) {
  if (sim->scene->has_body_force)
    SPH_TRY(body_force_create(sim, ref->rho0, err));
  if (sim->scene->contact.given)
    SPH_TRY(contact_create(sim, ref->rho0, err));
  return SPH_OK;
}

sph_status tl_essential_bc_attach(sph_sim *sim, const tl_reference *ref,
                                  sph_status (*constrain)(void *ctx, double t,
                                                          sph_error *err),
                                  void *ctx, sph_error *err) {
  if (!sph_scene_has_essential_bc(sim->scene))
    return SPH_OK;
  SPH_TRY(essential_bc_create(sim, ref->rho0, err));
  /* the initial state honours the constraints */
  return constrain(ctx, 0.0, err);
}

/* the finite-state check after an integrator step, timed with the step */
static sph_status step_checked(sph_sim *sim, const tl_reference *ref, int timer,
                               double integrator_seconds, sph_error *err) {
  double t0 = sph_wtime();
  sph_status st = tl_check_finite(ref, err);
  sph_timer *tm = &sim->timers[timer];
  tm->seconds += integrator_seconds + sph_wtime() - t0;
  tm->calls++;
  return st;
}

sph_status tl_leapfrog_step(sph_sim *sim, const tl_reference *ref,
                            sph_leapfrog *lf, int timer, double dt,
                            sph_error *err) {
  double s0 = lf->seconds;
  SPH_TRY(sph_leapfrog_step(lf, sim->t, dt, err));
  return step_checked(sim, ref, timer, lf->seconds - s0, err);
}

sph_status tl_leapfrog_derive(sph_sim *sim, const tl_reference *ref,
                              sph_leapfrog *lf, const double *dp,
                              sph_error *err) {
  tl_derive(sim, ref, NULL, NULL, NULL);
  if (sim->ps->field[SPH_FIELD_ACCELERATION]) {
    if (!lf->have_rates)
      SPH_TRY(lf->rates(lf->ctx, sim->t, err));
    tl_acceleration(sim, ref, dp);
  }
  return SPH_OK;
}

sph_status tl_rates_terms(sph_sim *sim, const tl_reference *ref, double *dp,
                          int timer, double t0, double t, sph_error *err) {
  sim->timers[timer].seconds += sph_wtime() - t0;
  sim->timers[timer].calls++;
  sph_stage s = {.t = t,
                 .x = ref->x,
                 .p = ref->p,
                 .F = ref->F,
                 .x_moment = ref->x,
                 .dp = dp};
  return sph_sim_terms_rates(sim, &s, err);
}

sph_status tl_constrain_terms(sph_sim *sim, const tl_reference *ref, double t,
                              sph_error *err) {
  sph_stage s = {.t = t, .x = ref->x, .p = ref->p, .F = ref->F};
  return sph_sim_terms_constrain(sim, &s, err);
}

sph_status tl_rk_step(sph_sim *sim, const tl_reference *ref, sph_ode *ode,
                      sph_rk_step integrate, int timer, double dt,
                      sph_error *err) {
  double s0 = ode->seconds;
  SPH_TRY(integrate(ode, sim->t, dt, err));
  return step_checked(sim, ref, timer, ode->seconds - s0, err);
}

sph_status tl_rk_acceleration(sph_sim *sim, const tl_reference *ref,
                              sph_ode *ode, sph_error *err) {
  if (!sim->ps->field[SPH_FIELD_ACCELERATION])
    return SPH_OK;
  /* the rates are scratch between steps; the momentum's are the second */
  SPH_TRY(ode->rhs(ode->ctx, 0, sim->t, 0.0, err));
  tl_acceleration(sim, ref, ode->rate[1]);
  return SPH_OK;
}

int tl_state_xpF(const tl_reference *ref, sph_state_array *out) {
  out[0] = (sph_state_array){"x", ref->x, 3 * ref->n};
  out[1] = (sph_state_array){"p", ref->p, 3 * ref->n};
  out[2] = (sph_state_array){"F", ref->F, 9 * ref->n};
  return 3;
}

sph_status tl_leapfrog_restore(sph_sim *sim, sph_leapfrog *lf, sph_error *err) {
  SPH_TRY(lf->rates(lf->ctx, sim->t, err));
  lf->have_rates = 1;
  return SPH_OK;
}
