/* A simulation: the particles a scene makes, the method that advances them
 * and the terms the scene asked for (docs/design.md sec. 2 and 4).
 *
 * Methods and terms plug in through small run-time ops tables (as SUNDIALS'
 * N_Vector_Ops): the time loop calls method->stable_dt and method->step once
 * per step; a method calls its terms' hooks once per stage. Pair
 * interactions stay static inline inside each method. A term the scene does
 * not ask for is never created, so it is never allocated, run or timed. */
#ifndef SPH_SIM_H
#define SPH_SIM_H

#include <stddef.h>

#include "core/kernel.h"
#include "core/neighbors.h"
#include "core/particles.h"
#include "parallel/domain.h"
#include "scene/node.h"
#include "scene/scene.h"
#include "sph/status.h"

/* A stable time step below this fraction of the largest one of the run
 * stops it (`step` indicator): particles collapsing onto each other. */
#define SPH_DT_COLLAPSE 1e-3

typedef struct sph_sim sph_sim;
typedef struct sph_term sph_term;

/* The state a stage works on and the rates it produces (NULL when the method
 * does not carry the variable). Arrays are per particle, as in particles.h. */
typedef struct sph_stage {
  double t;        /* stage time */
  const double *x; /* positions (3) */
  const double *p; /* linear momentum per reference volume (3) or velocity */
  const double *F; /* deformation gradient (9) */
  const double *H; /* cofactor (9) */
  const double *J; /* Jacobian (1) */
  const double *x_moment;         /* positions about which angular momentum is
                                     balanced at this stage (seed 000 eq. 45) */
  double *dx, *dp, *dF, *dH, *dJ; /* rates, same layouts */
} sph_stage;

typedef struct sph_term_ops {
  const char *name;      /* as printed and in summary.json */
  const char *reference; /* seed and equations */
  int distributed;       /* runs over MPI ranks on owned particles */
  int gpu; /* 1: runs on the device with the method's step (docs/gpu.md) */
  /* adds its contribution to the stage rates (may be NULL) */
  sph_status (*rates)(sph_term *term, sph_sim *sim, sph_stage *stage,
                      sph_error *err);
  /* corrects the state after an update, e.g. prescribed velocities (may be
   * NULL); `state` has the same layout as a stage with rates unused */
  sph_status (*constrain)(sph_term *term, sph_sim *sim, sph_stage *state,
                          sph_error *err);
  /* the largest step the term's own rates allow (may be NULL: no bound) */
  double (*stable_dt)(sph_term *term, const sph_sim *sim);
  /* the owned particles changed (a migration over MPI ranks): remakes the
   * term's particle indices (may be NULL: it keeps none) */
  sph_status (*renumber)(sph_term *term, sph_sim *sim, sph_error *err);
  void (*destroy)(sph_term *term);
} sph_term_ops;

struct sph_term {
  const sph_term_ops *ops;
  void *data;     /* the term's own state */
  double seconds; /* wall time spent in its hooks */
  unsigned long calls;
};

/* A named state array of a method (checkpoints save and restore these). */
typedef struct sph_state_array {
  const char *name;
  double *data;
  size_t len;
} sph_state_array;
#define SPH_MAX_STATE 12
#define SPH_DISTRIBUTED_DYNAMIC 2

typedef struct sph_method_ops {
  const char *name;               /* scene name, e.g. "tl-jst" */
  const char *title;              /* readable name */
  const char *reference;          /* seed sections and equations */
  int conserves_angular_momentum; /* to round-off, for a free body */
  /* runs over MPI ranks (sph_domain: owned + ghosts): 1 with the fixed
   * reference neighbourhoods, SPH_DISTRIBUTED_DYNAMIC with the ghosts found
   * again, migration and re-balancing at its rebuilds (updated Lagrangian) */
  int distributed;
  /* 1: `device: cuda` runs its step on the GPU (docs/gpu.md); 0: refused */
  int gpu;
  unsigned long fields; /* the output fields it fills: bit 1ul << f */
  /* validates the method block, requires fields, creates its terms */
  sph_status (*setup)(sph_sim *sim, sph_node *options, sph_error *err);
  double (*stable_dt)(sph_sim *sim);
  sph_status (*step)(sph_sim *sim, double dt, sph_error *err);
  /* fills the derived output fields (pressure, stress, von Mises, J,
   * displacement, velocity) from the method's state */
  sph_status (*derive)(sph_sim *sim, sph_error *err);
  /* kinetic and stored (strain) energy of the current state */
  void (*energy)(sph_sim *sim, double *kinetic, double *strain);
  /* the arrays that, with the time, determine every later step; returns
   * their count (at most SPH_MAX_STATE) */
  int (*state)(sph_sim *sim, sph_state_array *out);
  /* rebuilds what the method derives from its state arrays after a
   * checkpoint has overwritten them (may be NULL) */
  sph_status (*restore)(sph_sim *sim, sph_error *err);
  void (*destroy)(sph_sim *sim);
} sph_method_ops;

/* Timer slot for a method's own work (internal force etc.). */
typedef struct sph_timer {
  const char *name;
  double seconds;
  unsigned long calls;
} sph_timer;

#define SPH_MAX_TERMS 16
#define SPH_MAX_TIMERS 8

struct sph_sim {
  const sph_scene *scene;
  /* the step on the device (`device: cuda`, gpu/device_run.c), or NULL */
  struct sph_device_run *device;
  const sph_method_ops *method;
  void *method_data;
  sph_particles *ps;
  sph_kernel kernel;
  double dp; /* smallest particle spacing */
  double t;
  unsigned long steps;
  double dt_min, dt_max, dt_last;
  double dt_stable_peak; /* largest stable step of this process */
  sph_term terms[SPH_MAX_TERMS];
  int nterms;
  sph_timer timers[SPH_MAX_TIMERS];
  int ntimers;
  int timer_stable_dt; /* the method's stable_dt, timed by sph_sim_step */
  int threads;
  const sph_mirror *mirror;        /* NULL without symmetry planes */
  struct sph_reference *reference; /* the scene's reference, or NULL */
  int initial_defgrad;             /* DEFGRAD holds the initial F (reference) */
  sph_domain *domain; /* this rank's share of a distributed run, or NULL */
};

/* Method table lookup (the registry lists every method once). */
const sph_method_ops *sph_method_find(const char *name);
/* NULL-terminated list of every method. */
const sph_method_ops *const *sph_method_list(void);
/* The names of the registry's methods (the first 15), ", " between them,
 * into known (size bytes, truncated). */
void sph_method_known(char *known, size_t size);
/* The error of an unknown method name at node `at`: the closest known name
 * ("did you mean"), else the names known. */
sph_status sph_method_unknown(const char *name, sph_node *at, sph_error *err);

/* The memory estimate of sph_sim_create alone (the scene's particles and
 * frames against the limits of solver/memory.h): SPH_ERR_RANGE at the
 * scene's bodies or png block when it does not fit. sph render uses it. */
sph_status sph_sim_check_memory(const sph_scene *scene, sph_error *err);

/* Builds particles, looks up and sets up the method (its option errors point
 * into the scene file). */
sph_status sph_sim_create(sph_sim **out, const sph_scene *scene,
                          sph_error *err);
void sph_sim_destroy(sph_sim *sim);

/* The stable step of the current state: the method's, bounded by its
 * terms' (contact springs). */
double sph_sim_stable_dt(sph_sim *sim);

/* Advances one step of at most dt_cap (so output times are hit exactly). */
sph_status sph_sim_step(sph_sim *sim, double dt_cap, sph_error *err);

/* Adds a term to the sim (called by methods in setup); the sim owns it. */
sph_status sph_sim_add_term(sph_sim *sim, const sph_term_ops *ops, void *data,
                            sph_error *err);
/* Registers a named timer for method work; returns its index. */
int sph_sim_add_timer(sph_sim *sim, const char *name);

/* Runs every term's rates / constrain hook in order, timing each. */
sph_status sph_sim_terms_rates(sph_sim *sim, sph_stage *stage, sph_error *err);
/* every term's renumber hook, after a migration */
sph_status sph_sim_terms_renumber(sph_sim *sim, sph_error *err);
sph_status sph_sim_terms_constrain(sph_sim *sim, sph_stage *state,
                                   sph_error *err);

#endif
