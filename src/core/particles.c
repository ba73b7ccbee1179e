/* Particle storage (structure of arrays, fields allocated on demand), the
 * mirror images of symmetry planes and the momentum sums. */
#include "core/particles.h"

#include "core/check.h"
#include "core/tensor.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static const char *const field_names[] = {
#define F_NAME(e, name, ncomp, unit) name,
    SPH_FIELD_LIST(F_NAME)
#undef F_NAME
};
static const int field_ncomp[] = {
#define F_NCOMP(e, name, ncomp, unit) ncomp,
    SPH_FIELD_LIST(F_NCOMP)
#undef F_NCOMP
};
static const char *const field_units[] = {
#define F_UNIT(e, name, ncomp, unit) unit,
    SPH_FIELD_LIST(F_UNIT)
#undef F_UNIT
};

const char *sph_field_name(sph_field f) { return field_names[f]; }
int sph_field_components(sph_field f) { return field_ncomp[f]; }
const char *sph_field_unit(sph_field f) { return field_units[f]; }

int sph_field_from_name(const char *name) {
  for (int f = 0; f < SPH_FIELD_COUNT; ++f)
    if (strcmp(field_names[f], name) == 0)
      return f;
  return -1;
}

sph_status sph_particles_create(sph_particles **out, size_t capacity, int dim,
                                sph_error *err) {
  *out = NULL;
  if (dim < 1 || dim > 3)
    return sph_error_set(err, SPH_ERR_ARG, "dimension %d is not 1, 2 or 3",
                         dim);
  sph_particles *ps = calloc(1, sizeof *ps);
  if (!ps)
    return sph_error_set(err, SPH_ERR_NOMEM, "particle set");
  ps->capacity = capacity;
  ps->dim = dim;
  size_t c = capacity ? capacity : 1;
  ps->id = calloc(c, sizeof *ps->id);
  ps->body = calloc(c, sizeof *ps->body);
  ps->flags = calloc(c, sizeof *ps->flags);
  sph_status st = SPH_OK;
  if (!ps->id || !ps->body || !ps->flags)
    st = sph_error_set(err, SPH_ERR_NOMEM, "particle attributes (%zu)",
                       capacity);
  if (st == SPH_OK)
    st = sph_particles_require(ps, SPH_FIELD_POSITION0, err);
  if (st == SPH_OK)
    st = sph_particles_require(ps, SPH_FIELD_VOLUME0, err);
  if (st != SPH_OK) {
    sph_particles_destroy(ps);
    return st;
  }
  *out = ps;
  return SPH_OK;
}

void sph_particles_destroy(sph_particles *ps) {
  if (!ps)
    return;
  for (int f = 0; f < SPH_FIELD_COUNT; ++f)
    free(ps->field[f]);
  free(ps->id);
  free(ps->slot);
  free(ps->body);
  free(ps->flags);
  free(ps);
}

sph_status sph_particles_require(sph_particles *ps, sph_field f,
                                 sph_error *err) {
  if ((int)f < 0 || f >= SPH_FIELD_COUNT)
    return sph_error_set(err, SPH_ERR_ARG, "unknown field %d", (int)f);
  if (ps->field[f])
    return SPH_OK;
  size_t c = ps->capacity ? ps->capacity : 1;
  ps->field[f] = calloc(c * (size_t)field_ncomp[f], sizeof(double));
  if (!ps->field[f])
    return sph_error_set(err, SPH_ERR_NOMEM, "field %s for %zu particles",
                         field_names[f], ps->capacity);
  return SPH_OK;
}

sph_status sph_particles_append(sph_particles *ps, const double X[3],
                                double volume, int32_t body, sph_error *err) {
  if (ps->n >= ps->capacity)
    return sph_error_set(err, SPH_ERR_ARG, "particle set is full (%zu)",
                         ps->capacity);
  size_t i = ps->n++;
  memcpy(ps->field[SPH_FIELD_POSITION0] + 3 * i, X, 3 * sizeof *X);
  ps->field[SPH_FIELD_VOLUME0][i] = volume;
  ps->id[i] = (int64_t)i;
  if (ps->slot)
    ps->slot[i] = (int64_t)i;
  ps->body[i] = body;
  ps->flags[i] = 0;
  return SPH_OK;
}

size_t sph_particles_bytes(const sph_particles *ps) {
  size_t bytes =
      ps->capacity * (sizeof *ps->id + sizeof *ps->body + sizeof *ps->flags);
  for (int f = 0; f < SPH_FIELD_COUNT; ++f)
    if (ps->field[f])
      bytes += ps->capacity * (size_t)field_ncomp[f] * sizeof(double);
  if (ps->slot)
    bytes += ps->capacity * sizeof *ps->slot;
  return bytes;
}

/* ---- Morton order
 * ------------------------------------------------------------- */

typedef struct morton_key {
  uint64_t key;
  size_t index;
} morton_key;

/* the 21 low bits of v spread to every third bit */
static uint64_t spread3(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

uint64_t sph_morton_key(const uint32_t q[3]) {
  return spread3(q[0]) | spread3(q[1]) << 1 | spread3(q[2]) << 2;
}

uint64_t sph_morton_cell(const double X[3], const double lo[3], double cell,
                         uint32_t q[3]) {
  for (int c = 0; c < 3; ++c) {
    double f = floor((X[c] - lo[c]) / cell);
    q[c] = (uint32_t)fmin(fmax(f, 0.0), 2097151.0);
  }
  return sph_morton_key(q);
}

static int cmp_key(const void *pa, const void *pb) {
  const morton_key *a = pa, *b = pb;
  if (a->key != b->key)
    return a->key < b->key ? -1 : 1;
  return a->index < b->index ? -1 : a->index > b->index;
}

/* out[i] = in[perm[i]] for records of `size` bytes */
static void permute(void *data, void *tmp, const morton_key *k, size_t n,
                    size_t size) {
  char *d = data, *t = tmp;
  for (size_t i = 0; i < n; ++i)
    memcpy(t + i * size, d + k[i].index * size, size);
  memcpy(d, t, n * size);
}

sph_status sph_particles_sort_morton(sph_particles *ps, double cell,
                                     sph_error *err) {
  size_t n = ps->n;
  if (n < 2 || !(cell > 0.0))
    return SPH_OK;
  for (size_t a = 0; a < n; ++a)
    SPH_CHECK(ps->id[a] >= 0 && (size_t)ps->id[a] < n, err,
              "particle order: id %lld of %zu particles", (long long)ps->id[a],
              n);
  const double *X = ps->field[SPH_FIELD_POSITION0];
  double lo[3] = {INFINITY, INFINITY, INFINITY};
  for (size_t a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c)
      lo[c] = fmin(lo[c], X[3 * a + c]);
  morton_key *k = malloc(n * sizeof *k);
  void *tmp = malloc(n * 9 * sizeof(double));
  int64_t *slot = ps->slot ? ps->slot : malloc(ps->capacity * sizeof *slot);
  if (!k || !tmp || !slot) {
    free(k);
    free(tmp);
    if (slot != ps->slot)
      free(slot);
    return sph_error_set(err, SPH_ERR_NOMEM, "particle order (%zu)", n);
  }
  for (size_t a = 0; a < n; ++a) {
    uint32_t q[3];
    k[a] = (morton_key){sph_morton_cell(X + 3 * a, lo, cell, q), a};
  }
  qsort(k, n, sizeof *k, cmp_key);
  for (int f = 0; f < SPH_FIELD_COUNT; ++f)
    if (ps->field[f])
      permute(ps->field[f], tmp, k, n, (size_t)field_ncomp[f] * sizeof(double));
  permute(ps->id, tmp, k, n, sizeof *ps->id);
  permute(ps->body, tmp, k, n, sizeof *ps->body);
  permute(ps->flags, tmp, k, n, sizeof *ps->flags);
  for (size_t i = 0; i < n; ++i)
    slot[ps->id[i]] = (int64_t)i;
  ps->slot = slot;
  free(k);
  free(tmp);
  /* outputs list particles through slot: it must invert the reorder */
  for (size_t j = 0; j < n; ++j)
    SPH_CHECK(slot[j] >= 0 && (size_t)slot[j] < n &&
                  ps->id[slot[j]] == (int64_t)j,
              err, "particle order: slot %lld of the particle created %zu-th",
              (long long)slot[j], j);
  return SPH_OK;
}

double sph_wtime(void) { return omp_get_wtime(); }

void sph_momentum(const sph_particles *ps, double lin[3], double ang[3]) {
  const double *m = ps->field[SPH_FIELD_MASS];
  const double *v = ps->field[SPH_FIELD_VELOCITY];
  const double *x = ps->field[SPH_FIELD_POSITION]
                        ? ps->field[SPH_FIELD_POSITION]
                        : ps->field[SPH_FIELD_POSITION0];
  for (int c = 0; c < 3; ++c)
    lin[c] = ang[c] = 0.0;
  if (!m || !v)
    return;
  for (size_t a = 0; a < ps->n; ++a) {
    double mv[3] = {m[a] * v[3 * a], m[a] * v[3 * a + 1], m[a] * v[3 * a + 2]};
    double t[3];
    sph_vec3_cross(x + 3 * a, mv, t);
    for (int c = 0; c < 3; ++c) {
      lin[c] += mv[c];
      ang[c] += t[c];
    }
  }
}

void sph_mirror_vector(const sph_mirror *m, double *v) {
  long ng = (long)m->n_ghost;
  if (m->vmat) {
#pragma omp parallel for schedule(static)
    for (long g = 0; g < ng; ++g) {
      size_t s = (size_t)m->src[g], d = m->n_real + (size_t)g;
      const double *M = m->vmat + 9 * g;
      for (int c = 0; c < 3; ++c)
        v[3 * d + c] = M[3 * c] * v[3 * s] + M[3 * c + 1] * v[3 * s + 1] +
                       M[3 * c + 2] * v[3 * s + 2];
    }
    return;
  }
#pragma omp parallel for schedule(static)
  for (long g = 0; g < ng; ++g) {
    size_t s = (size_t)m->src[g], d = m->n_real + (size_t)g;
    for (int c = 0; c < 3; ++c)
      v[3 * d + c] = m->vsign[3 * g + c] * v[3 * s + c];
  }
}

void sph_mirror_scalar(const sph_mirror *m, double *f, double ref) {
  long ng = (long)m->n_ghost;
#pragma omp parallel for schedule(static)
  for (long g = 0; g < ng; ++g)
    f[m->n_real + (size_t)g] = ref + m->ssign[g] * (f[(size_t)m->src[g]] - ref);
}
