/* ul-csph over MPI ranks with symmetry and skew-symmetry planes (issue 20):
 * the serial run's mirror images are fixed at set-up (sph_mirror_table, seed
 * 000 sec. 8.2 / docs/benchmarks.md D.1), each carried by its source particle
 * (its serial number and reference position move with it), and at every rebuild
 * a rank places, between its owned particles and its ghosts, the images of
 * its owned particles and those within three supports of its owned box
 * (those within two first, whose lists are whole, so their corrections are
 * computed here), keyed by their serial order, by which every pair sum
 * runs. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/ul_csph/ul_csph_impl.h"
#include "parallel/domain.h"

/* supports around the owned box within which images are placed (the ghosts'
 * depth, solver/sim.c): an image near an owned particle reads its
 * neighbours' corrections, whose own lists reach a third support; those
 * within two supports have whole lists */
#define UL_MIRROR_DEPTH 3.0
#define UL_MIRROR_WHOLE 2.0

/* the images with whole lists first, each group in the serial order */
static int cmp_placed(const void *pa, const void *pb) {
  const ul_placed *a = pa, *b = pb;
  if (a->far != b->far)
    return a->far - b->far;
  return (a->j > b->j) - (a->j < b->j);
}

/* whether X lies in the box lo, hi widened by w */
static int in_box(const double *lo, const double *hi, double w,
                  const double *X) {
  int in = 1;
  for (int d = 0; d < 3; ++d)
    in &= X[d] >= lo[d] - w && X[d] <= hi[d] + w;
  return in;
}

static int cmp_index(const void *pa, const void *pb) {
  int64_t a = *(const int64_t *)pa, b = *(const int64_t *)pb;
  return (a > b) - (a < b);
}

sph_status ul_mirror_setup(ul_csph *m, sph_error *err) {
  const sph_mirror_table *t = m->ref.all_images;
  sph_sim *sim = m->sim;
  if (!t)
    return SPH_OK;
  if (sim->initial_defgrad)
    return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                         "ul-csph with symmetry planes and a given initial "
                         "deformation does not run over MPI ranks yet; run "
                         "without mpirun");
  size_t K = (size_t)(t->k > 0 ? t->k : 1), cap = m->ref.cap, n = m->ref.n;
  m->kimg = (int)K;
  m->imgj = malloc((K * cap + 1) * sizeof *m->imgj);
  m->imgX = malloc((3 * K * cap + 1) * sizeof *m->imgX);
  m->gj = malloc((cap + 1) * sizeof *m->gj);
  m->placed = malloc((K * cap + 1) * sizeof *m->placed);
  if (!m->imgj || !m->imgX || !m->gj || !m->placed)
    return sph_error_set(err, SPH_ERR_NOMEM, "ul-csph mirror images");
  for (size_t i = 0; i < K * cap; ++i)
    m->imgj[i] = -1.0;
  /* the owned particles come in storage order at set-up */
  const int64_t *gidx = sph_domain_storage_index(sim->domain);
  for (size_t j = 0; j < t->m; ++j) {
    int64_t g = t->src[j];
    const int64_t *at = bsearch(&g, gidx, n, sizeof *gidx, cmp_index);
    if (!at)
      continue;
    size_t a = (size_t)(at - gidx), k = 0;
    while (m->imgj[K * a + k] >= 0.0)
      ++k;
    m->imgj[K * a + k] = (double)j;
    memcpy(m->imgX + 3 * (K * a + k), t->X + 3 * j, 3 * sizeof *m->imgX);
  }
  SPH_TRY(sph_domain_track(sim->domain, m->imgj, (int)K, err));
  return sph_domain_track(sim->domain, m->imgX, 3 * (int)K, err);
}

void ul_mirror_store(ul_csph *m) {
  const sph_ref *ref = &m->ref;
  size_t K = (size_t)m->kimg;
  if (!ref->all_images)
    return;
  for (size_t g = ref->n; g < ref->n_img; ++g) {
    size_t s = (size_t)ref->src[g];
    for (size_t k = 0; s < ref->n && k < K; ++k)
      if (m->imgj[K * s + k] == (double)m->gj[g])
        memcpy(m->imgX + 3 * (K * s + k), ref->X + 3 * g, 3 * sizeof *m->imgX);
  }
}

void ul_mirror_sync(ul_csph *m) {
  sph_particles *ps = m->sim->ps;
  size_t n = m->ref.n;
  if (!m->ref.all_images)
    return;
  memcpy(ps->field[SPH_FIELD_POSITION], m->x, 3 * n * sizeof *m->x);
  memcpy(ps->field[SPH_FIELD_MOMENTUM], m->p, 3 * n * sizeof *m->p);
  memcpy(ps->field[SPH_FIELD_DEFGRAD], m->F, 9 * n * sizeof *m->F);
}

/* moves the ng points from n on behind the c that follow, w bytes each */
static void shift(void *base, size_t w, size_t n, size_t c, size_t ng) {
  char *a = base;
  if (a)
    memmove(a + (n + c) * w, a + n * w, ng * w);
}

sph_status ul_mirror_place(ul_csph *m, sph_error *err) {
  sph_ref *ref = &m->ref;
  const sph_mirror_table *t = ref->all_images;
  if (!t)
    return SPH_OK;
  sph_sim *sim = m->sim;
  sph_particles *ps = sim->ps;
  size_t n = ref->n, ng = ref->n_ext - n, nr = n + ng, K = (size_t)m->kimg;
  /* the state of the owned and ghost particles from the set */
  memcpy(m->x, ps->field[SPH_FIELD_POSITION], 3 * nr * sizeof *m->x);
  memcpy(m->p, ps->field[SPH_FIELD_MOMENTUM], 3 * nr * sizeof *m->p);
  memcpy(m->F, ps->field[SPH_FIELD_DEFGRAD], 9 * nr * sizeof *m->F);
  double lo[3] = {INFINITY, INFINITY, INFINITY},
         hi[3] = {-INFINITY, -INFINITY, -INFINITY}, h = sim->kernel.support;
  for (size_t a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c) {
      lo[c] = fmin(lo[c], ref->X[3 * a + c]);
      hi[c] = fmax(hi[c], ref->X[3 * a + c]);
    }
  /* the images of the owned particles and those near them */
  size_t c = 0, whole = 0;
  for (size_t s = 0; s < nr; ++s)
    for (size_t k = 0; k < K && m->imgj[K * s + k] >= 0.0; ++k) {
      const double *Xi = m->imgX + 3 * (K * s + k);
      int far = !in_box(lo, hi, UL_MIRROR_WHOLE * h, Xi);
      if (s < n || in_box(lo, hi, UL_MIRROR_DEPTH * h, Xi)) {
        m->placed[c++] = (ul_placed){(int64_t)m->imgj[K * s + k], s, k, far};
        whole += !far;
      }
    }
  sph_status st = SPH_OK;
  if (nr + c > ref->cap)
    st = sph_error_set(err, SPH_ERR_RANGE,
                       "rank %d would hold %zu particles and %zu mirror "
                       "images, more than the %zu its arrays hold; run on "
                       "fewer ranks",
                       sph_domain_rank(sim->domain), nr, c, ref->cap);
  SPH_TRY(sph_domain_agree(sim->domain, st, err));
  qsort(m->placed, c, sizeof *m->placed, cmp_placed);
  /* the ghosts behind the images */
  shift(ref->X, 3 * sizeof *ref->X, n, c, ng);
  shift(m->V0, sizeof *m->V0, n, c, ng);
  shift(m->Fr, 9 * sizeof *m->Fr, n, c, ng);
  shift(m->x, 3 * sizeof *m->x, n, c, ng);
  shift(m->p, 3 * sizeof *m->p, n, c, ng);
  shift(m->F, 9 * sizeof *m->F, n, c, ng);
  shift(ref->body, sizeof *ref->body, n, c, ng);
  shift(ref->id, sizeof *ref->id, n, c, ng);
  shift(ref->mat, sizeof *ref->mat, n, c, ng);
  shift(ref->rho0, sizeof *ref->rho0, n, c, ng);
  shift(ref->axes, sizeof *ref->axes, n, c, ng);
  const int64_t *gidx = sph_domain_storage_index(sim->domain);
  for (size_t g = 0; g < ng; ++g)
    ref->key[n + c + g] = gidx[n + g];
  for (size_t a = 0; a < n; ++a)
    ref->key[a] = gidx[a];
  for (size_t i = 0; i < c; ++i) {
    const ul_placed *q = &m->placed[i];
    size_t g = n + i, j = (size_t)q->j, s = q->s < n ? q->s : q->s + c;
    memcpy(ref->X + 3 * g, m->imgX + 3 * (K * q->s + q->k), 3 * sizeof *ref->X);
    m->V0[g] = m->V0[s];
    ref->body[g] = ref->body[s];
    ref->id[g] = ref->id[s];
    ref->mat[g] = ref->mat[s];
    ref->rho0[g] = ref->rho0[s];
    if (ref->axes)
      ref->axes[g] = NULL;
    ref->src[g] = (int32_t)s;
    sph_images_assign(ref, g, t, j);
    m->gj[g] = q->j;
    ref->key[g] = (int64_t)t->n_real + q->j;
  }
  ref->n_img = n + c;
  ref->n_ext = nr + c;
  ref->n_whole = n + whole;
  sph_domain_set_ghost_base(sim->domain, n + c);
  sph_images_publish(ref, t->vmat != NULL);
  /* F^r of the images (F^r = F of their sources at the update) */
  sph_mirror_state(ref, m->x, m->p, m->Fr, NULL, NULL);
  return SPH_OK;
}
