/* A validated, typed scene (docs/design.md sec. 6) and the particles it makes.
 *
 * sph_scene_load reads a YAML scene, applies --set overrides, validates
 * every key (errors name file, line, column and key) and fills defaults.
 * The method block is kept as a node tree: each method validates its own
 * options. sph_scene_build_particles generates every body's particles. */
#ifndef SPH_SCENE_H
#define SPH_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "core/kernel.h"
#include "core/particles.h"
#include "materials/material.h"
#include "render/png_schema.h"
#include "scene/node.h"
#include "sph/status.h"

#define SPH_NAME_MAX 64

typedef enum sph_shape_kind {
  SPH_SHAPE_BOX,      /* min, max */
  SPH_SHAPE_CYLINDER, /* center (of the base), axis, radius, length */
  SPH_SHAPE_RING,     /* 2D annulus: center, inner/outer radius; 3D: a tube
                         along axis with length */
  SPH_SHAPE_DISC,     /* 2D: center, radius */
  SPH_SHAPE_SPHERE,   /* 3D: center, radius */
  SPH_SHAPE_SHELL,    /* 3D spherical shell: center, inner/outer radius */
  SPH_SHAPE_MESH,     /* 3D: a closed triangle surface read from a file
                         (scene/mesh.h); min, max its bounding box */
  SPH_SHAPE_POLYGON,  /* 2D: an outline with holes (scene/polygon.h); min,
                         max its bounding box */
  SPH_SHAPE_PARTICLES /* 2D or 3D: particles read from a file
                         (scene/cloud.h); min, max their bounding box */
} sph_shape_kind;

struct sph_mesh;    /* see mesh.h */
struct sph_polygon; /* see polygon.h */
struct sph_cloud;   /* see cloud.h */

typedef struct sph_shape {
  sph_shape_kind kind;
  double min[3], max[3]; /* box */
  double center[3];
  double axis[3]; /* unit vector (cylinder, tube) */
  double radius, inner_radius, outer_radius, length;
  struct sph_mesh *mesh;       /* owned by the scene */
  struct sph_polygon *polygon; /* owned by the scene */
  struct sph_cloud *cloud;     /* owned by the scene */
  int spacing_estimated;       /* a cloud's dp: its median nearest-neighbour
                                  distance (no `particles: {spacing}`) */
  char file[256]; /* the mesh, outline or particle file as the scene names
                     it */
} sph_shape;

typedef enum sph_lattice {
  SPH_LATTICE_FACES,       /* particles on the faces: count [nx,ny,nz] on a
                              box, dp = L/(n-1), tributary volumes (docs/benchmarks.md
                              D.5) */
  SPH_LATTICE_CELL_CENTRED /* spacing dp, cell centres clipped to the shape,
                              V = dp^d */
} sph_lattice;

typedef enum sph_distribution {
  SPH_DIST_LATTICE,
  SPH_DIST_JITTER, /* lattice moved by a uniform random offset */
  SPH_DIST_RELAX /* lattice jittered then relaxed to a uniform irregular set */
} sph_distribution;

typedef enum sph_velocity_kind {
  SPH_VEL_NONE,
  SPH_VEL_UNIFORM,   /* value */
  SPH_VEL_ROTATION,  /* v = (omega profile(X)) axis x (X - center) */
  SPH_VEL_EXPRESSION /* three expressions of x, y, z (reference coords) */
} sph_velocity_kind;

typedef struct sph_expr sph_expr; /* see expr.h */

typedef struct sph_velocity {
  sph_velocity_kind kind;
  double value[3];
  double axis[3]; /* unit vector */
  double omega;
  double center[3];
  sph_expr *profile; /* rotation profile, NULL = 1 */
  sph_expr *expr[3]; /* expression components */
} sph_velocity;

/* Rigid placement of a body: world X = R X_body + t. The body's shape,
 * initial velocity field and the selections that name it (with the normals
 * and velocities of their boundaries) are given in the body frame. */
typedef struct sph_transform {
  int given;   /* 0: the identity */
  double R[9]; /* rotation, row-major */
  double t[3];
} sph_transform;

typedef struct sph_body {
  char name[SPH_NAME_MAX];
  int material; /* index into scene->materials */
  sph_shape shape;
  sph_transform transform;
  sph_lattice lattice;
  int count[3];   /* SPH_LATTICE_FACES */
  double spacing; /* dp (derived from count for FACES: the smallest L/(n-1)) */
  sph_distribution distribution;
  double jitter; /* fraction of dp */
  unsigned long seed;
  int relax_steps;
  sph_velocity velocity;
  int line, col; /* of the body entry */
} sph_body;

typedef enum sph_select_kind {
  SPH_SELECT_PLANE, /* |X . normal - at| <= tolerance (world frame) */
  SPH_SELECT_BOX,   /* min <= X <= max (inclusive, with tolerance; in the
                       frame of `body` when it names one) */
  SPH_SELECT_FACE,  /* the side of a body's bounding box in its frame: body,
                       axis, sign */
  SPH_SELECT_NEAR   /* within `tolerance` of a mesh's triangles (in the frame
                       of `body` when it names one) */
} sph_select_kind;

typedef struct sph_selection {
  sph_select_kind kind;
  int axis;         /* FACE; PLANE: the coordinate axis of normal, or -1 */
  double normal[3]; /* PLANE: unit normal */
  double at;
  double tolerance; /* default: half the body spacing */
  double min[3], max[3];
  int body;              /* -1: all bodies */
  int side;              /* -1 or +1 for FACE */
  struct sph_mesh *near; /* NEAR; owned by the scene */
} sph_selection;

typedef enum sph_condition_kind {
  SPH_BC_CLAMP,        /* all velocity components fixed to zero */
  SPH_BC_ROLLER,       /* normal component fixed to zero (symmetry plane) */
  SPH_BC_VELOCITY,     /* velocity prescribed over [from, until) */
  SPH_BC_SYMMETRY,     /* mirror plane: ghosts reflect positions, negate the
                          normal velocity component (docs/benchmarks.md D.1) */
  SPH_BC_SKEW_SYMMETRY /* mirror plane: ghosts negate the tangential
                          components */
} sph_condition_kind;

typedef struct sph_boundary {
  char name[SPH_NAME_MAX];
  sph_selection select;
  sph_condition_kind kind;
  double normal[3]; /* roller / symmetry plane unit normal (world frame) */
  int axis;         /* the coordinate axis of normal, or -1 (oblique) */
  double value[3];  /* prescribed velocity (world frame) */
  unsigned mask;    /* components prescribed (bits 0..2) */
  double from, until;
  int line, col;
} sph_boundary;

/* A rigid frictionless obstacle of the optional `contact:` block, moving
 * with a constant velocity: a plane the bodies stay in front of, or a box
 * they stay outside of (the rigid tool of seed 001 sec. 2.4.3). */
typedef enum sph_wall_kind { SPH_WALL_PLANE, SPH_WALL_BOX } sph_wall_kind;

typedef struct sph_wall {
  char name[SPH_NAME_MAX];
  sph_wall_kind kind;
  double point[3], normal[3]; /* plane through point at t = 0; bodies stay
                                 where (x - point) . normal >= 0 */
  double min[3], max[3];      /* box at t = 0 */
  double velocity[3];
  int line, col;
} sph_wall;

/* Penalty contact (src/terms/contact.c): walls, and between particles of
 * different bodies when `between_bodies` is set. */
typedef struct sph_contact {
  int given;
  double stiffness; /* kappa: the contact spring of a particle on a wall is
                       that of a layer dp / (2 kappa) thick of its material */
  int between_bodies;
  sph_wall *walls;
  size_t nwalls;
  int line, col; /* of the contact block */
} sph_contact;

typedef struct sph_probe {
  char name[SPH_NAME_MAX];
  double at[3];
  int fields[8];
  int nfields;
  int line, col;
} sph_probe;

typedef struct sph_output {
  double every;
  int vtk;
  int vtk_ascii;
  int vtk_zlib; /* appended data compressed (vtkZLibDataCompressor) */
  int fields[SPH_FIELD_COUNT]; /* sph_field list for the sinks */
  int nfields;
  int body_id, particle_id; /* integer arrays asked for by name */
  sph_png_output png;
  sph_probe *probes;
  size_t nprobes;
  double checkpoint_every; /* 0 = off */
  int at_steps; /* 1: frames at the steps reaching the output times (run.c) */
} sph_output;

/* Thresholds of the stability verdict the scene may change (the optional
 * top-level `stability:` block; defaults in stability.h, 0 turns an
 * indicator off). */
typedef struct sph_stability_options {
  double fracture_dp; /* initially adjacent pairs farther apart, in dp */
  double zigzag_max;  /* von Mises roughness */
} sph_stability_options;

/* Where a run's time step runs (docs/gpu.md). */
typedef enum sph_device { SPH_DEVICE_CPU, SPH_DEVICE_CUDA } sph_device;

typedef struct sph_scene {
  char name[SPH_NAME_MAX];
  char path[512];
  int dimension;
  /* where the time step runs (`device`, absent: the CPU); device_at the
   * key, for errors, or NULL */
  sph_device device;
  sph_node *device_at;
  sph_node *root;      /* the resolved tree (defaults filled) */
  sph_node *method;    /* the method block, validated by the method */
  sph_node *reference; /* optional `reference:` block (analytic solution or
                          scalar reference), validated by its user; NULL */
  char method_name[SPH_NAME_MAX];
  sph_kernel_type kernel_type;
  double h_over_dp;
  sph_material *materials;
  size_t nmaterials;
  sph_body *bodies;
  size_t nbodies;
  sph_boundary *boundaries;
  size_t nboundaries;
  int has_body_force;
  double body_force[3]; /* acceleration, m/s^2 */
  sph_contact contact;
  double t_end;
  sph_output output;
  sph_stability_options stability;
  /* bytes a run may take (0: 90 % of the memory available); set by the
   * caller after loading (sph run/check --max-memory), not a scene key */
  double memory_limit;
} sph_scene;

/* Loads and validates `path`, after applying `nset` overrides "a.b=value".
 * Both are public (include/sph/sph.h): exported from libsph.so. */
SPH_API sph_status sph_scene_load(sph_scene **out, const char *path,
                                  const char *const *overrides, size_t nset,
                                  sph_error *err);
SPH_API void sph_scene_destroy(sph_scene *s);

/* Generates the particles of every body (POSITION0, VOLUME0, VELOCITY
 * allocated and filled; flags marked for boundary selections) and checks
 * what needs particles: empty bodies, bodies that overlap, boundary
 * selections that select nothing, probes outside every body. */
sph_status sph_scene_build_particles(const sph_scene *s, sph_particles **out,
                                     sph_error *err);

/* One rank's share of the particles sph_scene_build_particles makes, in
 * the order sph_particles_sort_morton(cell) gives them, without making the
 * whole set: the particles with storage indices [rank N / size, (rank + 1)
 * N / size) of the N, with the fields and flags of the whole set's (id: the
 * creation index), their storage indices in *gidx (malloc'd), N in *total.
 * Every rank generates every particle three times (bounds and checks, counts
 * per cell, storage indices), holding a counter per cell of the grid. The
 * checks are the whole set's, with its messages; bodies that overlap are
 * found among the share's particles and those of the cells next to them:
 * that error is this rank's alone, *overlap the creation index of its
 * first particle (the lowest over the ranks is the whole set's error;
 * INT64_MAX for every other outcome, the same on every rank). A `relax`
 * body is relaxed over MPI's ranks, each its slice of the creation order,
 * and streamed to every rank in each pass (sph_body_visit_share: then
 * collective over the ranks, whatever rank and size). *out is NULL (and
 * SPH_OK) when the cell grid would be larger than 2 cells a particle and
 * 2^22 cells (far apart bodies), or for several bodies when its cells are
 * smaller than half the spacing or clamped (sph_morton_cell). */
sph_status sph_scene_build_share(const sph_scene *s, double cell, int rank,
                                 int size, sph_particles **out, int64_t **gidx,
                                 size_t *total, int64_t *overlap,
                                 sph_error *err);

/* Whether a boundary imposes values on particles (clamp, roller,
 * velocity); symmetry planes are handled with mirror images instead. */
int sph_scene_has_essential_bc(const sph_scene *s);

/* Smallest particle spacing over the bodies. */
double sph_scene_min_spacing(const sph_scene *s);

/* Index of the named material/body, or -1. */
int sph_scene_find_material(const sph_scene *s, const char *name);
int sph_scene_find_body(const sph_scene *s, const char *name);

/* Position X (world frame) in the frame of body `body`, and back. */
void sph_body_local(const sph_body *b, const double X[3], double Xb[3]);
void sph_body_world(const sph_body *b, const double Xb[3], double X[3]);

/* out = R v, the rotation of placement T. */
void sph_transform_rotate(const sph_transform *T, const double v[3],
                          double out[3]);

/* The coordinate axis (0, 1, 2) the unit vector n is, or -1. */
int sph_axis_index(const double n[3]);

/* Whether boundary `b` selects the particle at reference position X of body
 * `body`. */
int sph_selection_contains(const sph_scene *s, const sph_selection *sel,
                           int body, const double X[3]);

/* Signed distance of x from wall w at time t (positive in front of a plane
 * or outside a box) and the unit normal n pointing away from the wall. */
double sph_wall_distance(const sph_wall *w, double t, int dim,
                         const double x[3], double n[3]);

/* Physical time of output frame `index`: min(time.end, index * every). */
double sph_output_time(const sph_scene *s, int index);

#endif
