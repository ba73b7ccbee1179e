/* tl-csph: the classical displacement-based total-Lagrangian corrected SPH
 * of seed 001 sec. 2 (Vidal, Bonet, Huerta 2007, after Bonet and
 * Kulasegaram): F = grad_0 x with the corrected gradient (eq. 8-9), the
 * Galerkin internal force T_i = sum_j V_j P_j G_i(X_j) (eq. 11, written in
 * the conservative pair form of seed 000 eq. 29c), m a = E - T, leap-frog.
 * No stabilisation: this is the baseline the JST papers compare against. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"
#include "methods/registry_impl.h"
#include "methods/tl_csph/tl_csph_iact.h"
#include "methods/tl_csph/tl_csph_impl.h"
#include "terms/terms_impl.h"

/* F from positions for the particles, images mirrored, ghosts' from their
 * owners, P for every point */
static sph_status deformation_and_stress(tl_csph *m, long n, sph_error *err) {
  sph_ref *ref = &m->ref;
  long ne = (long)ref->n_ext;
  int dim = m->sim->scene->dimension;
  SPH_TRY(sph_domain_exchange(m->sim->domain, m->x, 3, err));
  if (ne > n) /* image positions and momenta from their sources */
    sph_mirror_state(ref, m->x, m->p, m->F, NULL, NULL);
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    ref_sums s; /* F = grad_0 x (seed 001 eq. 9) */
    sph_ref_pair_sums(ref, (size_t)a, m->x, 0, NULL, &s);
    double F[9], unused[3];
    ref_sums_store(&s, F, unused);
    ref_iact_gradient_correct(F, ref->L + 9 * a);
    ref_iact_plane_strain(F, dim);
    memcpy(m->F + 9 * a, F, sizeof F);
  }
  SPH_TRY(sph_domain_exchange(m->sim->domain, m->F, 9, err));
  if (ne > n) /* the images' F mirror their sources' */
    sph_mirror_state(ref, m->x, m->p, m->F, NULL, NULL);
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ne; ++a) {
    double H[9];
    sph_mat3_cofactor(m->F + 9 * a, H);
    sph_material_stress(ref->mat[a], m->F + 9 * a, H,
                        sph_mat3_det(m->F + 9 * a), m->P + 9 * a);
    sph_ref_force_matrix(ref, (size_t)a);
  }
  return SPH_OK;
}

static sph_status tl_csph_rates(void *ctx, double t, sph_error *err) {
  tl_csph *m = ctx;
  sph_sim *sim = m->sim;
  long n = (long)sim->ps->n;
  double t0 = sph_wtime();
  SPH_TRY(deformation_and_stress(m, n, err));
  sph_ref_conservative_force(&m->ref, m->dp);
  return sph_step_rates_terms(sim, &m->ref, m->dp, m->timer_force, t0, t, err);
}

static sph_status tl_csph_constrain(void *ctx, double t, sph_error *err) {
  tl_csph *m = ctx;
  return sph_step_constrain_terms(m->sim, &m->ref, t, err);
}

static double tl_csph_stable_dt(sph_sim *sim) {
  const tl_csph *m = sim->method_data;
  return sph_ref_stable_dt(&m->ref, sim, m->cfl, m->current_wave_speed);
}

static sph_status tl_csph_step(sph_sim *sim, double dt, sph_error *err) {
  tl_csph *m = sim->method_data;
  return sph_step_leapfrog(sim, &m->ref, &m->lf, m->timer_integration, dt, err);
}

static sph_status tl_csph_derive(sph_sim *sim, sph_error *err) {
  tl_csph *m = sim->method_data;
  SPH_TRY(deformation_and_stress(m, (long)sim->ps->n, err));
  return sph_step_leapfrog_derive(sim, &m->ref, &m->lf, m->dp, err);
}

static void tl_csph_energy(sph_sim *sim, double *kinetic, double *strain) {
  tl_csph *m = sim->method_data;
  sph_ref_energy(sim, &m->ref, NULL, NULL, kinetic, strain);
}

static void tl_csph_destroy(sph_sim *sim) {
  tl_csph *m = sim->method_data;
  if (!m)
    return;
  sph_ref_destroy(&m->ref);
  free(m->dp);
  free(m);
  sim->method_data = NULL;
}

/* The options of the method block. */
typedef struct tl_csph_options {
  double cfl;
  int current_wave_speed; /* dt from the current state's c_p */
} tl_csph_options;

static sph_status tl_csph_options_parse(sph_node *opt, tl_csph_options *o,
                                        sph_error *err) {
  static const char *const keys[] = {"name", "cfl", "integrator", "wave_speed",
                                     NULL};
  SPH_TRY(sph_node_check_keys(opt, keys, err));
  SPH_TRY(sph_step_leapfrog_options(opt, &o->cfl, err));
  const char *ws;
  SPH_TRY(sph_node_get_string(opt, "wave_speed", 0, "current", &ws, err));
  if (strcmp(ws, "current") && strcmp(ws, "reference"))
    return sph_node_error(sph_node_child(opt, "wave_speed"), err, SPH_ERR_RANGE,
                          "'%s' is not one of: current, reference", ws);
  o->current_wave_speed = !strcmp(ws, "current");
  return SPH_OK;
}

static sph_status tl_csph_setup(sph_sim *sim, sph_node *opt, sph_error *err) {
  tl_csph_options o = {0};
  SPH_TRY(tl_csph_options_parse(opt, &o, err));
  tl_csph *m = calloc(1, sizeof *m);
  if (!m)
    return sph_error_set(err, SPH_ERR_NOMEM, "tl-csph");
  sim->method_data = m;
  m->sim = sim;
  m->cfl = o.cfl;
  m->current_wave_speed = o.current_wave_speed;
  SPH_TRY(sph_ref_create(&m->ref, sim, 1, err));
  sph_particles *ps = sim->ps;
  m->x = m->ref.x;
  m->p = m->ref.p;
  m->F = m->ref.F;
  m->P = m->ref.P;
  m->dp = calloc(3 * ps->n + 3, sizeof *m->dp);
  if (!m->dp)
    return sph_error_set(err, SPH_ERR_NOMEM, "tl-csph rates");
  m->timer_force = sph_sim_add_timer(sim, "internal_force");
  m->timer_integration = sph_sim_add_timer(sim, "time_integration");
  return sph_step_leapfrog_attach(sim, &m->ref, &m->lf, m->dp, tl_csph_rates,
                                  tl_csph_constrain, m, err);
}

static int tl_csph_state(sph_sim *sim, sph_state_array *out) {
  tl_csph *m = sim->method_data;
  /* F of the last rates: the next time step's wave speed reads it */
  return sph_step_state_xpF(&m->ref, out);
}

static sph_status tl_csph_restore(sph_sim *sim, sph_error *err) {
  tl_csph *m = sim->method_data;
  return sph_step_leapfrog_restore(sim, &m->lf, err);
}

const sph_method_ops tl_csph_method_ops = {
    .name = "tl-csph",
    .title = "Total-Lagrangian corrected SPH, displacement-based (baseline)",
    .reference = "seed 001 (Vidal, Bonet, Huerta 2007) sec. 2, eq. 8-11",
    .conserves_angular_momentum = 1,
    .distributed = 1,
    .fields = SPH_REF_OUTPUT_FIELDS,
    .setup = tl_csph_setup,
    .stable_dt = tl_csph_stable_dt,
    .step = tl_csph_step,
    .derive = tl_csph_derive,
    .energy = tl_csph_energy,
    .state = tl_csph_state,
    .restore = tl_csph_restore,
    .destroy = tl_csph_destroy,
};
