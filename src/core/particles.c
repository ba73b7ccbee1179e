/* Particle storage (structure of arrays, fields allocated on demand). */
#include "sph/particles.h"

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
  return bytes;
}
