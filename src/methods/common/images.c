/* Mirror images across the scene's symmetry (normal component negated) and
 * skew-symmetry (tangential components negated) planes, as docs/benchmarks.md
 * D.1 recommends for the swinging cube of seed 000 sec. 8.2: the image
 * particles of the reference configuration (built once, or for a run over
 * MPI ranks with a dynamic domain the serial run's, which ul-csph places at
 * each rebuild) and the images' state from their sources'. Points reflect
 * through parallel/planes.h (the domain's reflected boxes use the same);
 * vectors by R = I - 2 n n^T (sign flips for coordinate planes) and
 * two-point tensors by I + sigma R (A - I) R^T. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"
#include "methods/common/common_impl.h"
#include "parallel/planes.h"

typedef struct plane {
  sph_domain_plane geo; /* X . n = at */
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

static sph_status grow_points(sph_ref *r, size_t need, size_t *cap, int oblique,
                              sph_error *err) {
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
    memcpy(pl->geo.n, bc->select.normal, sizeof pl->geo.n);
    pl->geo.axis = bc->select.axis;
    pl->geo.at = bc->select.at;
    pl->body = bc->select.body;
    pl->sigma = bc->kind == SPH_BC_SYMMETRY ? 1 : -1;
    pl->done = 0;
    pl->side = 1;
    *oblique |= pl->geo.axis < 0;
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
        mean[0] += sph_plane_distance(&pl->geo, X0 + 3 * a);
        mean[1] += 1.0;
      }
    sph_domain_sum(dom, mean, 2);
    pl->side = mean[1] > 0.0 && mean[0] / mean[1] < 0.0 ? -1 : 1;
  }
}

/* The real points: the particles, then over MPI ranks the ghosts, each its
 * own source with no sign flipped. */
static void real_points(sph_ref *r, const sph_sim *sim, size_t ng,
                        int oblique) {
  const sph_particles *ps = sim->ps;
  const sph_domain *dom = sim->domain;
  size_t n = ps->n, nr = n + ng;
  memcpy(r->X, ps->field[SPH_FIELD_POSITION0], 3 * n * sizeof(double));
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
}

/* Point `at` becomes the image Xn of point i across pl: its source's
 * volume, body and source, the signs composed with the plane's and, with an
 * oblique plane, vmat = sigma (I - 2 n n^T) vmat of point i. */
static void set_image(sph_ref *r, size_t at, size_t i, const plane *pl,
                      const double Xn[3], int oblique) {
  memcpy(r->X + 3 * at, Xn, 3 * sizeof *Xn);
  r->V[at] = r->V[i];
  r->body[at] = r->body[i];
  r->src[at] = r->src[i];
  r->ssign[at] = (signed char)(r->ssign[i] * pl->sigma);
  for (int c = 0; c < 3; ++c) {
    r->rsign[3 * at + c] =
        (signed char)(r->rsign[3 * i + c] * (c == pl->geo.axis ? -1 : 1));
    r->vsign[3 * at + c] = (signed char)(r->ssign[at] * r->rsign[3 * at + c]);
  }
  const double *n = pl->geo.n;
  for (int a = 0; oblique && a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const double *M = r->vmat + 9 * i;
      double m = M[3 * a + b] -
                 2.0 * n[a] * (n[0] * M[b] + n[1] * M[3 + b] + n[2] * M[6 + b]);
      r->vmat[9 * at + 3 * a + b] = pl->sigma * m;
    }
}

/* Over ranks the real points in the serial storage order (*order NULL
 * without a domain or planes). */
static sph_status serial_order(const sph_domain *dom, size_t nr, int np,
                               stored **order, sph_error *err) {
  *order = NULL;
  if (!np || !dom)
    return SPH_OK;
  const int64_t *gidx = sph_domain_storage_index(dom);
  if (!(*order = malloc(nr * sizeof **order)))
    return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
  for (size_t a = 0; a < nr; ++a)
    (*order)[a] = (stored){gidx[a], a};
  qsort(*order, nr, sizeof **order, cmp_stored);
  return SPH_OK;
}

/* Images of every point within two supports of a plane on its domain side,
 * appended from *total on; two passes over the planes complete edges,
 * corners and periodic images, duplicates (by position, to 1e-6 dp) are
 * skipped. The first nr points are visited in `order` when given. */
static sph_status add_images(sph_ref *r, const sph_sim *sim, plane *planes,
                             int np, const stored *order, size_t nr,
                             size_t *total, size_t *cap, int oblique,
                             sph_error *err) {
  double layer = 2.0 * sim->kernel.support, q = 1e-6 * sim->dp;
  hash h = {0};
  h.cap = 16 * nr > 65536 ? 16 * nr : 65536;
  h.key = malloc(3 * h.cap * sizeof *h.key);
  h.used = calloc(h.cap, 1);
  sph_status st = h.key && h.used
                      ? SPH_OK
                      : sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
  int full = 0;
  for (size_t a = 0; st == SPH_OK && a < nr; ++a) {
    int64_t key[3];
    for (int c = 0; c < 3; ++c)
      key[c] = llround(r->X[3 * a + c] / q);
    hash_insert(&h, key);
  }
  for (int pass = 0; pass < 2 && st == SPH_OK; ++pass)
    for (int k = 0; k < np && st == SPH_OK; ++k) {
      plane *pl = &planes[k];
      size_t count = *total;
      for (size_t v = pl->done; v < count && st == SPH_OK; ++v) {
        size_t i = order && v < nr ? order[v].i : v;
        if (pl->body >= 0 && r->body[i] != pl->body)
          continue;
        double dist = sph_plane_distance(&pl->geo, r->X + 3 * i),
               d = dist * pl->side;
        if (d <= 0.0 || d >= layer)
          continue;
        double Xn[3];
        sph_plane_reflect(&pl->geo, r->X + 3 * i, dist, Xn);
        int64_t key[3];
        for (int c = 0; c < 3; ++c)
          key[c] = llround(Xn[c] / q);
        int ins = hash_insert(&h, key);
        if (ins < 0)
          full = 1;
        if (ins <= 0)
          continue;
        if ((st = grow_points(r, *total + 1, cap, oblique, err)) != SPH_OK)
          break;
        set_image(r, (*total)++, i, pl, Xn, oblique);
      }
      pl->done = count;
    }
  free(h.key);
  free(h.used);
  if (st == SPH_OK && full)
    st = sph_error_set(err, SPH_ERR_NOMEM, "mirror image table is full");
  return st;
}

/* Over MPI ranks with a fixed domain: the serial order of the total points
 * (the owned, the images, the ghosts: ni owned and images, nr real) as
 * r->key. */
static sph_status serial_keys(sph_ref *r, const sph_domain *dom, size_t n,
                              size_t nr, size_t ni, size_t total,
                              sph_error *err) {
  const int64_t *gidx = sph_domain_storage_index(dom);
  if (!(r->key = malloc(r->cap * sizeof *r->key)))
    return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
  for (size_t a = 0; a < total; ++a)
    r->key[a < n    ? a
           : a < nr ? a + ni - n
                    : a - (nr - n)] =
        a < nr ? gidx[a] : ((int64_t)1 << 40) + (int64_t)a;
  return SPH_OK;
}

/* moves the ghosts (from n on) behind the images (the m points after them),
 * the images' sources renumbered to match */
static sph_status ghosts_behind(sph_ref *r, size_t n, size_t ng, size_t m,
                                int oblique, sph_error *err) {
  size_t nr = n + ng, total = nr + m;
  for (size_t a = n; ng && a < total; ++a)
    if ((size_t)r->src[a] >= n)
      r->src[a] += (int32_t)((size_t)r->src[a] < nr ? m : 0);
  if (!ng || !m)
    return SPH_OK;
  SPH_TRY(rotate_points(r->X, 3 * sizeof *r->X, n, ng, m, err));
  SPH_TRY(rotate_points(r->V, sizeof *r->V, n, ng, m, err));
  SPH_TRY(rotate_points(r->body, sizeof *r->body, n, ng, m, err));
  SPH_TRY(rotate_points(r->src, sizeof *r->src, n, ng, m, err));
  SPH_TRY(rotate_points(r->vsign, 3, n, ng, m, err));
  SPH_TRY(rotate_points(r->rsign, 3, n, ng, m, err));
  SPH_TRY(rotate_points(r->ssign, 1, n, ng, m, err));
  if (oblique)
    SPH_TRY(rotate_points(r->vmat, 9 * sizeof *r->vmat, n, ng, m, err));
  return SPH_OK;
}

void sph_images_publish(sph_ref *ref, int oblique) {
  size_t n = ref->n;
  ref->mirror = (sph_mirror){.n_real = n,
                             .n_ghost = ref->n_img - n,
                             .src = ref->src + n,
                             .vsign = ref->vsign + 3 * n,
                             .vmat = oblique ? ref->vmat + 9 * n : NULL,
                             .ssign = ref->ssign + n};
}

/* Real points first, then their images (add_images). Images across
 * coordinate planes flip signs; with an oblique plane every point carries
 * its reflection as a matrix (chosen once here). Over MPI ranks the real
 * points are the owned particles and the ghosts, visited in the serial
 * storage order, so the images of both come in the serial images' order
 * (key); the ghosts then move behind the images. The planes' sides are
 * side[k] when given (the whole set's for a part of it), else from
 * plane_sides. */
static sph_status build_images(sph_ref *r, sph_sim *sim, int images,
                               const int *side, sph_error *err) {
  const sph_particles *ps = sim->ps;
  sph_domain *dom = sim->domain;
  size_t n = ps->n, cap = 0;
  /* other ranks' particles within a support of ours (and of our images) */
  size_t ng = sph_domain_ghosts(dom), nr = n + ng;
  plane planes[32];
  int oblique = 0, np = images ? scene_planes(sim->scene, planes, &oblique) : 0;
  if (side)
    for (int k = 0; k < np; ++k)
      planes[k].side = side[k];
  else
    plane_sides(planes, np, ps, dom);
  SPH_TRY(grow_points(r, nr + 1, &cap, oblique, err));
  real_points(r, sim, ng, oblique);
  stored *order;
  SPH_TRY(serial_order(dom, nr, np, &order, err));
  size_t total = nr;
  if (np) {
    sph_status st =
        add_images(r, sim, planes, np, order, nr, &total, &cap, oblique, err);
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
    sph_status st = serial_keys(r, dom, n, nr, ni, total, err);
    if (st != SPH_OK) {
      free(order);
      return st;
    }
  }
  free(order);
  SPH_TRY(ghosts_behind(r, n, ng, total - nr, oblique, err));
  r->n = n;
  r->n_img = ni;
  r->n_ext = total;
  r->sync_images = dom && np;
  if (!sph_domain_migrates(dom)) /* a dynamic domain's ghosts follow ps */
    sph_domain_set_ghost_base(dom, ni);
  sph_images_publish(r, oblique);
  return SPH_OK;
}

static int cmp_row(const void *pa, const void *pb) {
  const int64_t *a = pa, *b = pb;
  return (a[0] > b[0]) - (a[0] < b[0]);
}

/* The images of the serial run g (P real points, row i of `all` holding
 * the storage index of point i, of N) as the table t. */
static sph_status fill_table(sph_mirror_table *t, const sph_ref *g,
                             const int64_t *all, size_t P, size_t N,
                             sph_error *err) {
  size_t M = g->n_img - P;
  t->m = M;
  t->n_real = N;
  t->src = malloc((M + 1) * sizeof *t->src);
  t->vsign = malloc(3 * M + 1);
  t->rsign = malloc(3 * M + 1);
  t->ssign = malloc(M + 1);
  t->X = malloc((3 * M + 1) * sizeof *t->X);
  t->vmat = g->vmat ? malloc((9 * M + 1) * sizeof *t->vmat) : NULL;
  int *per = calloc(P + 1, sizeof *per);
  if (!t->src || !t->vsign || !t->rsign || !t->ssign || !t->X || !per ||
      (g->vmat && !t->vmat)) {
    free(per);
    return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
  }
  for (size_t j = 0; j < M; ++j) {
    size_t i = P + j;
    t->src[j] = (int32_t)all[6 * (size_t)g->src[i]];
    memcpy(t->vsign + 3 * j, g->vsign + 3 * i, 3);
    memcpy(t->rsign + 3 * j, g->rsign + 3 * i, 3);
    t->ssign[j] = g->ssign[i];
    memcpy(t->X + 3 * j, g->X + 3 * i, 3 * sizeof *t->X);
    if (t->vmat)
      memcpy(t->vmat + 9 * j, g->vmat + 9 * i, 9 * sizeof *t->vmat);
    int c = ++per[g->src[i]];
    t->k = c > t->k ? c : t->k;
  }
  free(per);
  return SPH_OK;
}

void sph_images_assign(sph_ref *ref, size_t g, const sph_mirror_table *t,
                       size_t j) {
  memcpy(ref->vsign + 3 * g, t->vsign + 3 * j, 3);
  memcpy(ref->rsign + 3 * g, t->rsign + 3 * j, 3);
  ref->ssign[g] = t->ssign[j];
  if (t->vmat)
    memcpy(ref->vmat + 9 * g, t->vmat + 9 * j, 9 * sizeof *ref->vmat);
}

/* Over MPI ranks with a dynamic domain: the serial images, kept as
 * r->all_images, built over the real points within four supports of a
 * plane, gathered from every rank in storage order (the images' sources lie
 * within two, the real points an image could coincide with within two and
 * a rounding; the planes' sides are the whole set's); the local points are
 * the owned particles, with room for the images the method places. */
static sph_status build_images_dynamic(sph_ref *r, sph_sim *sim,
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
  sph_ref g = {0};
  sph_mirror_table *t = calloc(1, sizeof *t);
  sph_status st =
      mine && t ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
  for (size_t a = 0; st == SPH_OK && a < n; ++a) {
    int in = 0;
    for (int k = 0; k < np; ++k)
      in |= fabs(sph_plane_distance(&planes[k].geo, X0 + 3 * a)) < near;
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
  if (st == SPH_OK)
    st = fill_table(t, &g, all, P, N, err);
  free(mine);
  free(all);
  sph_particles_destroy(part);
  sph_ref_destroy(&g);
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

sph_status sph_images_build(sph_ref *ref, sph_sim *sim, int images,
                            sph_error *err) {
  const sph_scene *s = sim->scene;
  int planes = 0;
  for (size_t k = 0; images && k < s->nboundaries; ++k)
    planes |= s->boundaries[k].kind == SPH_BC_SYMMETRY ||
              s->boundaries[k].kind == SPH_BC_SKEW_SYMMETRY;
  if (planes && sph_domain_migrates(sim->domain))
    return build_images_dynamic(ref, sim, err);
  return build_images(ref, sim, images, NULL, err);
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

static void mirror_refresh_oblique(const sph_ref *ref, double *x, double *p,
                                   double *F, double *H, double *J) {
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

void sph_mirror_state(const sph_ref *ref, double *x, double *p, double *F,
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

sph_status sph_mirror_sources(const sph_sim *sim, const sph_ref *ref,
                              double *field, int ncomp, sph_error *err) {
  if (!ref->sync_images)
    return SPH_OK;
  return sph_domain_exchange(sim->domain, field, ncomp, err);
}

/* A particle that starts on a plane is its own image: across a symmetry
 * plane its normal momentum is zero and it stays on the plane, across a
 * skew-symmetry plane its tangential momentum and displacement are zero. */
static void hold_on_plane(const plane *pl, const double *X0, double *x,
                          double *p) {
  const double *n = pl->geo.n;
  double pn = sph_vec3_dot(p, n), xn = sph_plane_distance(&pl->geo, x);
  double Xn = sph_plane_distance(&pl->geo, X0);
  for (int c = 0; c < 3; ++c) {
    if (pl->sigma > 0) { /* symmetry: the normal components */
      p[c] = pl->geo.axis == c ? 0.0 : p[c] - pn * n[c];
      x[c] = pl->geo.axis == c ? pl->geo.at : x[c] - xn * n[c];
    } else { /* skew-symmetry: the tangential components */
      p[c] = pn * n[c];
      x[c] = X0[c] + (xn - Xn) * n[c];
    }
  }
}

void sph_mirror_hold(const sph_sim *sim, const sph_ref *ref, double *x,
                     double *p) {
  plane planes[32];
  int oblique, np = scene_planes(sim->scene, planes, &oblique);
  const sph_particles *ps = sim->ps;
  const double *X0 = ps->field[SPH_FIELD_POSITION0];
  double tol = 1e-9 * sim->dp;
  long n = (long)ref->n;
  if (!np || !X0)
    return;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a)
    for (int k = 0; k < np; ++k) {
      const plane *pl = &planes[k];
      if ((pl->body < 0 || ps->body[a] == pl->body) &&
          fabs(sph_plane_distance(&pl->geo, X0 + 3 * a)) <= tol)
        hold_on_plane(pl, X0 + 3 * a, x + 3 * a, p + 3 * a);
    }
}

/* The planes' sides over every rank (plane_sides): what sph_mirror_crossed
 * and sph_mirror_fold judge a particle by. */
static int planes_of(const sph_sim *sim, plane *planes) {
  int oblique, np = scene_planes(sim->scene, planes, &oblique);
  plane_sides(planes, np, sim->ps, sim->domain);
  return np;
}

/* whether point X lies across plane pl from its body */
static int across(const plane *pl, const sph_ref *ref, size_t a,
                  const double *X) {
  return (pl->body < 0 || ref->body[a] == pl->body) &&
         sph_plane_distance(&pl->geo, X) * pl->side < 0.0;
}

long sph_mirror_crossed(const sph_sim *sim, const sph_ref *ref,
                        const double *x) {
  plane planes[32];
  int np = planes_of(sim, planes);
  long n = (long)ref->n, count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
  for (long a = 0; a < n; ++a)
    for (int k = 0; k < np; ++k)
      count += across(&planes[k], ref, (size_t)a, x + 3 * a);
  return (long)sph_domain_max(sim->domain, (double)count);
}

/* v -> Q v and A -> I + sigma Q (A - I) Q with Q = I - 2 n n^T */
static void reflect_vector(const plane *pl, double *v) {
  double vn = sph_vec3_dot(v, pl->geo.n);
  for (int c = 0; c < 3; ++c)
    v[c] -= 2.0 * vn * pl->geo.n[c];
}

static void reflect_tensor(const plane *pl, double *A) {
  double Q[9], B[9], T[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Q[3 * i + j] = (i == j) - 2.0 * pl->geo.n[i] * pl->geo.n[j];
      B[3 * i + j] = A[3 * i + j] - (i == j);
    }
  sph_mat3_mul(Q, B, T);
  sph_mat3_mul(T, Q, B);
  for (int k = 0; k < 9; ++k)
    A[k] = (k % 4 == 0) + pl->sigma * B[k];
}

void sph_mirror_fold(const sph_sim *sim, sph_ref *ref, double *x, double *p,
                     double *F, double *Fr) {
  plane planes[32];
  int np = planes_of(sim, planes);
  long n = (long)ref->n, ne = (long)ref->n_ext, ni = (long)ref->n_img;
  /* the images first: those of a source that folds fold with it */
#pragma omp parallel for schedule(static)
  for (long g = n; g < ni; ++g)
    for (int k = 0; k < np; ++k) {
      size_t s = (size_t)ref->src[g];
      if (across(&planes[k], ref, s, x + 3 * s)) {
        double *Xg = ref->X + 3 * g;
        sph_plane_reflect(&planes[k].geo, Xg,
                          sph_plane_distance(&planes[k].geo, Xg), Xg);
      }
    }
    /* then the owned particles and the ghosts */
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ne; ++a) {
    if (a >= n && a < ni)
      continue;
    for (int k = 0; k < np; ++k) {
      const plane *pl = &planes[k];
      double *xa = x + 3 * a, *Xa = ref->X + 3 * a;
      if (!across(pl, ref, (size_t)a, xa))
        continue;
      sph_plane_reflect(&pl->geo, xa, sph_plane_distance(&pl->geo, xa), xa);
      sph_plane_reflect(&pl->geo, Xa, sph_plane_distance(&pl->geo, Xa), Xa);
      reflect_vector(pl, p + 3 * a);
      if (pl->sigma < 0) /* skew-symmetry: the tangential components */
        for (int c = 0; c < 3; ++c)
          p[3 * a + c] = -p[3 * a + c];
      reflect_tensor(pl, F + 9 * a);
      reflect_tensor(pl, Fr + 9 * a);
    }
  }
  sph_mirror_state(ref, x, p, F, NULL, NULL);
  sph_mirror_state(ref, x, p, Fr, NULL, NULL);
}
