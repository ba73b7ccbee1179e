/* Particle storage: one array per field (structure of arrays), double
 * precision, a particle's components adjacent (x[3*i + c], F[9*i + k]).
 *
 * Only the fields a method, its terms and the sinks declare are allocated
 * (sph_particles_require). Integer attributes (id, body, flags) are always
 * present. Fields are listed once, with their component count and unit. */
#ifndef SPH_PARTICLES_H
#define SPH_PARTICLES_H

#include <stddef.h>
#include <stdint.h>

#include "sph/status.h"

/* X(enum, name, components, unit) */
#define SPH_FIELD_LIST(X)                                                      \
  X(SPH_FIELD_POSITION0, "initial_position", 3, "m")                           \
  X(SPH_FIELD_POSITION, "position", 3, "m")                                    \
  X(SPH_FIELD_VELOCITY, "velocity", 3, "m/s")                                  \
  X(SPH_FIELD_MOMENTUM, "momentum", 3, "kg/(m^2 s)")                           \
  X(SPH_FIELD_ACCELERATION, "acceleration", 3, "m/s^2")                        \
  X(SPH_FIELD_VOLUME0, "volume", 1, "m^3")                                     \
  X(SPH_FIELD_MASS, "mass", 1, "kg")                                           \
  X(SPH_FIELD_DENSITY, "density", 1, "kg/m^3")                                 \
  X(SPH_FIELD_DEFGRAD, "deformation_gradient", 9, "1")                         \
  X(SPH_FIELD_COFACTOR, "cofactor", 9, "1")                                    \
  X(SPH_FIELD_JACOBIAN, "J", 1, "1")                                           \
  X(SPH_FIELD_PK1, "first_piola_kirchhoff", 9, "Pa")                           \
  X(SPH_FIELD_STRESS, "stress", 9, "Pa")                                       \
  X(SPH_FIELD_PRESSURE, "pressure", 1, "Pa")                                   \
  X(SPH_FIELD_VON_MISES, "von_mises", 1, "Pa")                                 \
  X(SPH_FIELD_DISPLACEMENT, "displacement", 3, "m")                            \
  X(SPH_FIELD_SMOOTHING, "smoothing_length", 1, "m")

typedef enum sph_field {
#define SPH_FIELD_ENUM(e, name, ncomp, unit) e,
  SPH_FIELD_LIST(SPH_FIELD_ENUM)
#undef SPH_FIELD_ENUM
      SPH_FIELD_COUNT
} sph_field;

/* particle flags (bit set) */
enum {
  SPH_FLAG_BOUNDARY = 1u << 0, /* selected by at least one boundary condition */
  SPH_FLAG_GHOST = 1u << 1     /* mirror particle, not integrated */
};

typedef struct sph_particles {
  size_t n;                       /* particles in use */
  size_t capacity;                /* particles allocated */
  int dim;                        /* 2 or 3 (storage is always 3 components) */
  double *field[SPH_FIELD_COUNT]; /* NULL until required */
  int64_t *id;                    /* stable particle id, 0..n-1 at creation */
  int64_t *slot;   /* storage index of id j after a reorder (NULL: none) */
  int32_t *body;   /* index of the body in the scene */
  uint32_t *flags; /* SPH_FLAG_* */
} sph_particles;

const char *sph_field_name(sph_field f);
int sph_field_components(sph_field f);
const char *sph_field_unit(sph_field f);
/* Field from its name; -1 if unknown. */
int sph_field_from_name(const char *name);

/* Empty set able to hold `capacity` particles (no double fields yet). */
sph_status sph_particles_create(sph_particles **out, size_t capacity, int dim,
                                sph_error *err);
void sph_particles_destroy(sph_particles *ps);

/* Allocates (zero-filled) field `f` for the whole capacity if absent. */
sph_status sph_particles_require(sph_particles *ps, sph_field f,
                                 sph_error *err);
static inline int sph_particles_has(const sph_particles *ps, sph_field f) {
  return ps->field[f] != NULL;
}

/* Appends a particle at reference position X with volume V of `body`;
 * requires POSITION0 and VOLUME0 (allocated by create). Fails when full. */
sph_status sph_particles_append(sph_particles *ps, const double X[3],
                                double volume, int32_t body, sph_error *err);

/* Bytes held by the allocated fields. */
size_t sph_particles_bytes(const sph_particles *ps);

/* Reorders the particles (every field and attribute) along a Morton
 * (Z-order) curve of cubic cells of edge `cell` over their initial
 * positions, particles of one cell keeping their order, so that neighbours
 * are near in memory; fills ps->slot. Outputs that list particles use
 * sph_particles_slot to keep the creation order. Set-up only. */
sph_status sph_particles_sort_morton(sph_particles *ps, double cell,
                                     sph_error *err);

/* The Morton key sph_particles_sort_morton gives the point X: its cell of
 * edge `cell` counted from the corner lo, each index clamped to [0, 2^21 -
 * 1] (into q). */
uint64_t sph_morton_cell(const double X[3], const double lo[3], double cell,
                         uint32_t q[3]);
/* The Morton key of the cell indices q (each below 2^21). */
uint64_t sph_morton_key(const uint32_t q[3]);

/* storage index of the particle created j-th */
static inline size_t sph_particles_slot(const sph_particles *ps, size_t j) {
  return ps->slot ? (size_t)ps->slot[j] : j;
}

/* Mirror (ghost) images of real particles across symmetry planes (seed 000
 * sec. 8.2, docs/benchmarks.md D.1): particle n_real + g is the image of
 * src[g]. A vector of the image is S v with S = diag(vsign[3g..3g+2]) when
 * every plane is a coordinate plane, else S = vmat[9g..9g+8] (row-major: sigma
 * times the composed reflections I - 2 n n^T); a scalar's departure from its
 * reference value flips by ssign[g] (sigma). Terms that read neighbours'
 * values refresh images with sph_mirror_vector/scalar. */
typedef struct sph_mirror {
  size_t n_real, n_ghost;
  const int32_t *src;
  const signed char *vsign;
  const double *vmat; /* NULL: coordinate planes only */
  const signed char *ssign;
} sph_mirror;

/* Image values of a vector (ncomp 3) or scalar (ncomp 1, about `ref`) field
 * whose real entries are set. */
void sph_mirror_vector(const sph_mirror *m, double *v);
void sph_mirror_scalar(const sph_mirror *m, double *f, double ref);

/* Linear and angular momentum (about the origin) from the mass, velocity
 * and current position fields. */
void sph_momentum(const sph_particles *ps, double lin[3], double ang[3]);

/* Monotonic wall clock in seconds. */
double sph_wtime(void);

#endif
