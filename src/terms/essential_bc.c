/* Essential boundary conditions imposed directly on the particles (seed 000
 * Algorithm 1 step 8): clamped particles keep zero momentum, rollers zero
 * normal momentum (p - (p . n) n for an oblique normal n), prescribed
 * velocities p = rho0 v inside their time window
 * (after it the particles are free). The rates of constrained components are
 * zeroed and the state is reset after every update. */
#include <math.h>
#include <stdlib.h>

#include "terms/terms_impl.h"

typedef struct bc_set {
  const sph_boundary *bc;
  size_t *index;
  size_t count;
} bc_set;

typedef struct essential_bc {
  const double *rho0;
  bc_set *sets;
  size_t nsets;
} essential_bc;

/* Components the boundary fixes at time t (bit mask), 0 when inactive; an
 * oblique roller fixes none of them (projected in `apply`). */
static unsigned fixed_mask(const sph_boundary *bc, double t) {
  switch (bc->kind) {
  case SPH_BC_CLAMP:
    return 7u;
  case SPH_BC_ROLLER:
    return bc->axis >= 0 ? 1u << bc->axis : 0u;
  case SPH_BC_VELOCITY:
    return (t >= bc->from && t < bc->until) ? bc->mask : 0u;
  default:
    return 0u;
  }
}

/* v - (v . n) n */
static void drop_normal(double *v, const double n[3]) {
  double vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
  for (int c = 0; c < 3; ++c)
    v[c] -= vn * n[c];
}

static void apply(essential_bc *e, double t, double *p, double *dp) {
  for (size_t s = 0; s < e->nsets; ++s) {
    const sph_boundary *bc = e->sets[s].bc;
    if (bc->kind == SPH_BC_ROLLER && bc->axis < 0)
      for (size_t k = 0; k < e->sets[s].count; ++k) {
        size_t a = e->sets[s].index[k];
        if (dp)
          drop_normal(dp + 3 * a, bc->normal);
        if (p)
          drop_normal(p + 3 * a, bc->normal);
      }
    unsigned mask = fixed_mask(bc, t);
    if (!mask)
      continue;
    for (size_t k = 0; k < e->sets[s].count; ++k) {
      size_t a = e->sets[s].index[k];
      for (int c = 0; c < 3; ++c) {
        if (!(mask & (1u << c)))
          continue;
        if (dp)
          dp[3 * a + c] = 0.0;
        if (p)
          p[3 * a + c] = bc->kind == SPH_BC_VELOCITY
                             ? (e->rho0 ? e->rho0[a] : 1.0) * bc->value[c]
                             : 0.0;
      }
    }
  }
}

static sph_status bc_rates(sph_term *term, sph_sim *sim, sph_stage *stage,
                           sph_error *err) {
  apply(term->data, stage->t, NULL, stage->dp);
  return SPH_OK;
}

static sph_status bc_constrain(sph_term *term, sph_sim *sim, sph_stage *state,
                               sph_error *err) {
  /* the state is writable here: the method passes its own arrays */
  apply(term->data, state->t, (double *)state->p, NULL);
  return SPH_OK;
}

/* the owned particles each boundary selects (by their reference position) */
static void select_particles(essential_bc *e, const sph_sim *sim) {
  const sph_particles *ps = sim->ps;
  for (size_t k = 0; k < e->nsets; ++k) {
    bc_set *set = &e->sets[k];
    set->count = 0;
    for (size_t a = 0; a < ps->n; ++a)
      if (sph_selection_contains(sim->scene, &set->bc->select, ps->body[a],
                                 ps->field[SPH_FIELD_POSITION0] + 3 * a))
        set->index[set->count++] = a;
  }
}

static sph_status bc_renumber(sph_term *term, sph_sim *sim, sph_error *err) {
  (void)err;
  select_particles(term->data, sim);
  return SPH_OK;
}

static void bc_destroy(sph_term *term) {
  essential_bc *e = term->data;
  if (!e)
    return;
  for (size_t s = 0; s < e->nsets; ++s)
    free(e->sets[s].index);
  free(e->sets);
  free(e);
}

const sph_term_ops essential_bc_term_ops = {
    .name = "essential_bc",
    .gpu = 1, /* clamps (gpu/tl_jst_gpu_one.h) */
    .reference = "seed 000 Algorithm 1 step 8",
    .distributed = 1,
    .rates = bc_rates,
    .constrain = bc_constrain,
    .renumber = bc_renumber,
    .destroy = bc_destroy,
};

sph_status essential_bc_create(sph_sim *sim, const double *rho0,
                               sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_particles *ps = sim->ps;
  essential_bc *e = calloc(1, sizeof *e);
  if (!e || !(e->sets = calloc(s->nboundaries, sizeof *e->sets))) {
    free(e);
    return sph_error_set(err, SPH_ERR_NOMEM, "boundary conditions");
  }
  e->rho0 = rho0;
  e->nsets = s->nboundaries;
  sph_term t = {.data = e};
  /* room for every particle a rank may own after migrations */
  size_t cap = sph_domain_capacity(sim->domain, ps);
  for (size_t k = 0; k < s->nboundaries; ++k) {
    bc_set *set = &e->sets[k];
    set->bc = &s->boundaries[k];
    set->index = malloc((cap ? cap : 1) * sizeof *set->index);
    if (!set->index) {
      bc_destroy(&t);
      return sph_error_set(err, SPH_ERR_NOMEM, "boundary conditions");
    }
  }
  select_particles(e, sim);
  sph_status st = sph_sim_add_term(sim, &essential_bc_term_ops, e, err);
  if (st != SPH_OK)
    bc_destroy(&t);
  return st;
}
