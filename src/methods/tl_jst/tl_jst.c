/* tl-jst: the total-Lagrangian mixed {p,F}, {p,F,J} and {p,F,H,J} JST-SPH
 * of seed 000 (Lee, Gil, Greto, Kulasegaram, Bonet 2016), Algorithm 1:
 * conservation laws eq. 41 with the corrected gradient eq. 21, internal
 * force eq. 42 (or the symmetric force of seed 003 eq. 11), JST dissipation
 * on p and J only (eq. 35-38), angular momentum and JST projections
 * (eq. 45-51), monolithic TVD-RK2 (eq. 43; or the SSP-RK3 of seed 004
 * eq. 30) with dt from eq. 44, essential
 * boundary conditions imposed on particles. Over MPI ranks (sph_domain)
 * every rate evaluation (each Runge-Kutta stage) exchanges the ghosts' p and
 * Q = P L (or P) before the pair sweep. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/corrections.h"
#include "core/tensor.h"
#include "methods/common/pair_iact.h"
#include "methods/registry_impl.h"
#include "methods/tl_jst/tl_jst_iact.h"
#include "methods/tl_jst/tl_jst_impl.h"
#include "terms/terms_impl.h"

/* ---- stress and state
 * ---------------------------------------------------------- */

/* H and J of particle a for the chosen variant */
static inline void strain_measures(const tl_jst *m, const double *F,
                                   const double *H, const double *J, size_t a,
                                   double Ha[9], double *Ja) {
  const double *Fa = F + 9 * a;
  if (m->fields == TL_JST_PFHJ)
    memcpy(Ha, H + 9 * a, 9 * sizeof *Ha);
  else
    sph_mat3_cofactor(Fa, Ha);
  *Ja = m->fields == TL_JST_PF ? sph_mat3_det(Fa) : J[a];
}

/* mirror images take their sources' state */
static void refresh_images(tl_jst *m) {
  if (m->ref.n_ext > m->ref.n)
    sph_mirror_state(&m->ref, m->x, m->p, m->F,
                     m->fields == TL_JST_PFHJ ? m->H : NULL,
                     m->fields == TL_JST_PF ? NULL : m->J);
}

/* P, and Q = P L for the conservative force, of every point; the
 * conservative force needs only Q, so its stages store P only when asked
 * (the output fields): 144 bytes per point less to write */
static void compute_stress(tl_jst *m, long n, int store_P) {
  int conservative = m->force == TL_JST_CONSERVATIVE;
  store_P |= !conservative;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double Ha[9], Ja, P[9];
    strain_measures(m, m->F, m->H, m->J, (size_t)a, Ha, &Ja);
    sph_material_stress(m->ref.mat[a], m->F + 9 * a, Ha, Ja, P);
    if (store_P)
      memcpy(m->P + 9 * a, P, sizeof P);
    if (conservative)
      sph_ref_force_matrix_of(&m->ref, (size_t)a, P);
  }
}

/* ---- right-hand side (Algorithm 1 steps 4-8)
 * ------------------------------------ */

/* Geometric conservation laws (eq. 41b-d) from the uncorrected momentum
 * gradient G, the momentum rate dp (= -T) and dx = p / rho0 */
static inline void particle_rates(tl_jst *m, size_t a, double G[9],
                                  const double dp[3]) {
  double inv_rho0 = 1.0 / m->ref.rho0[a];
  ref_iact_gradient_correct(G, m->ref.L + 9 * a);
  for (int k = 0; k < 9; ++k)
    G[k] *= inv_rho0;
  memcpy(m->dF + 9 * a, G, 9 * sizeof *G);
  if (m->fields == TL_JST_PFHJ)
    sph_mat3_tensor_cross(m->F + 9 * a, G, m->dH + 9 * a);
  if (m->fields != TL_JST_PF) {
    double Ha[9], Ja;
    strain_measures(m, m->F, m->H, m->J, a, Ha, &Ja);
    m->dJ[a] = sph_mat3_ddot(Ha, G);
  }
  for (int c = 0; c < 3; ++c) {
    m->dp[3 * a + c] = dp[c];
    m->dx[3 * a + c] = m->p[3 * a + c] * inv_rho0;
  }
}

/* particle a's share of sweep_conservative; with `lap`, also L[p] */
static inline __attribute__((always_inline)) void
conservative_particle(tl_jst *m, size_t a, const double *lap) {
  const sph_ref *ref = &m->ref;
  ref_sums s;
  sph_ref_pair_sums(ref, a, m->p, 1, lap, &s);
  double G[9], f[3], self[3];
  ref_sums_store(&s, G, f);
  ref_iact_force_self(ref->Qt + 9 * a, ref->s + 3 * a, self);
  for (int c = 0; c < 3; ++c)
    f[c] += self[c];
  particle_rates(m, a, G, f);
  if (lap) {
    m->lu_p[3 * a] = s.l01[0];
    m->lu_p[3 * a + 1] = s.l01[1];
    m->lu_p[3 * a + 2] = s.l2;
  }
}

/* one sweep for the momentum gradient and the force of eq. 42, and the
 * JST term's L[p] with them: one pass over the neighbour slots less */
static void sweep_conservative(tl_jst *m, long n) {
  if (m->lu_p) {
#pragma omp parallel for schedule(static)
    for (long a = 0; a < n; ++a)
      conservative_particle(m, (size_t)a, m->lap);
  } else {
#pragma omp parallel for schedule(static)
    for (long a = 0; a < n; ++a)
      conservative_particle(m, (size_t)a, NULL);
  }
}

/* the symmetric force of seed 003 eq. 11 with the corrected gradient, or
 * (eq. 30) with the uncorrected one */
static void sweep_symmetric(tl_jst *m, long n) {
  const sph_ref *ref = &m->ref;
  const sph_neighbors *nl = ref->nl;
  int corrected = m->force == TL_JST_SYMMETRIC;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double G[9] = {0}, T[3] = {0, 0, 0};
    const double *pa = m->p + 3 * a, *Pa = m->P + 9 * a;
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      double r[3], g[3];
      ref_iact_pair_vector(ref->X, (size_t)a, b, r);
      ref_iact_gradient(G, ref->w[k], pa, m->p + 3 * b, r);
      for (int c = 0; c < 3; ++c)
        r[c] *= ref->w[k];
      if (corrected)
        sph_mat3_vec(ref->L + 9 * a, r, g);
      else
        memcpy(g, r, sizeof g);
      tl_jst_iact_force_symmetric(T, Pa, m->P + 9 * b, g);
    }
    double dp[3] = {-T[0], -T[1], -T[2]};
    particle_rates(m, (size_t)a, G, dp);
  }
}

/* the kernel-gradient force of seed 000 eq. 31 */
static void sweep_eq31(tl_jst *m, long n) {
  const sph_ref *ref = &m->ref;
  const sph_neighbors *nl = ref->nl;
  const double *V = ref->V;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double G[9] = {0}, T[3] = {0, 0, 0};
    const double *pa = m->p + 3 * a;
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      double r[3];
      ref_iact_pair_vector(ref->X, (size_t)a, b, r);
      ref_iact_gradient(G, ref->w[k], pa, m->p + 3 * b, r);
      tl_jst_iact_force_kernel(T, V[b], m->P + 9 * b, m->fgrad + 3 * m->rev[k]);
    }
    /* the b = a term of eq. 31 */
    tl_jst_iact_force_kernel(T, V[a], m->P + 9 * a, m->fgrad_self + 3 * a);
    double dp[3] = {-T[0], -T[1], -T[2]};
    particle_rates(m, (size_t)a, G, dp);
  }
}

static sph_status tl_jst_rhs(void *ctx, int stage, double t, double dt,
                             sph_error *err) {
  tl_jst *m = ctx;
  sph_sim *sim = m->sim;
  long n = (long)sim->ps->n;
  double t0 = sph_wtime();
  /* over MPI ranks the sweep reads the ghosts' p and Q (or P), which their
   * owners compute; images of ghosts mirror the ghosts' p, F, H and J */
  SPH_TRY(sph_domain_exchange(sim->domain, m->p, 3, err));
  SPH_TRY(sph_mirror_sources(sim, &m->ref, m->F, 9, err));
  if (m->fields == TL_JST_PFHJ)
    SPH_TRY(sph_mirror_sources(sim, &m->ref, m->H, 9, err));
  if (m->fields != TL_JST_PF)
    SPH_TRY(sph_mirror_sources(sim, &m->ref, m->J, 1, err));
  refresh_images(m);
  compute_stress(m, (long)m->ref.n_img, 0);
  if (m->force == TL_JST_CONSERVATIVE)
    SPH_TRY(sph_domain_exchange(sim->domain, m->ref.Qt, 9, err));
  else
    SPH_TRY(sph_domain_exchange(sim->domain, m->P, 9, err));
  m->sweep(m, n);
  /* X^chi of eq. 45: x^n, then x^n + dt / (2 rho0) (p^n + p*) for
   * TVD-RK2; SSP-RK3 takes the stage's x (no exact angular momentum) */
  const double *xm = m->x;
  if (stage > 0 && m->integrate == sph_tvd_rk2_step) {
#pragma omp parallel for schedule(static)
    for (long a = 0; a < n; ++a)
      for (int c = 0; c < 3; ++c)
        m->xmoment[3 * a + c] =
            m->x0[3 * a + c] +
            0.5 * dt * (m->p0[3 * a + c] + m->p[3 * a + c]) / m->ref.rho0[a];
    xm = m->xmoment;
  }
  sim->timers[m->timer_force].seconds += sph_wtime() - t0;
  sim->timers[m->timer_force].calls++;
  sph_stage s = {.t = t,
                 .x = m->x,
                 .p = m->p,
                 .F = m->F,
                 .H = m->H,
                 .J = m->J,
                 .x_moment = xm,
                 .dx = m->dx,
                 .dp = m->dp,
                 .dF = m->dF,
                 .dH = m->dH,
                 .dJ = m->dJ};
  return sph_sim_terms_rates(sim, &s, err);
}

static sph_status tl_jst_constrain(void *ctx, double t, sph_error *err) {
  tl_jst *m = ctx;
  sph_stage s = {.t = t, .x = m->x, .p = m->p, .F = m->F, .H = m->H, .J = m->J};
  return sph_sim_terms_constrain(m->sim, &s, err);
}

/* ---- ops
 * ------------------------------------------------------------------------- */

static double tl_jst_stable_dt(sph_sim *sim) {
  tl_jst *m = sim->method_data;
  if (!m->current_wave_speed || m->wave_speed_every == 1)
    return sph_ref_stable_dt(&m->ref, sim, m->cfl, m->current_wave_speed);
  /* the current state's c_p at every wave_speed_every-th step, held between */
  if (m->c_held <= 0.0 || sim->steps % (unsigned long)m->wave_speed_every == 0)
    m->c_held = m->cfl * sim->dp / sph_ref_stable_dt(&m->ref, sim, m->cfl, 1);
  return m->cfl * sim->dp / m->c_held;
}

static sph_status tl_jst_step(sph_sim *sim, double dt, sph_error *err) {
  tl_jst *m = sim->method_data;
  return sph_step_rk(sim, &m->ref, &m->ode, m->integrate, m->timer_integration,
                     dt, err);
}

static sph_status tl_jst_derive(sph_sim *sim, sph_error *err) {
  tl_jst *m = sim->method_data;
  refresh_images(m);
  compute_stress(m, (long)m->ref.n_img, 1);
  sph_ref_derive(sim, &m->ref, m->fields == TL_JST_PFHJ ? m->H : NULL,
                 m->fields == TL_JST_PF ? NULL : m->J, NULL);
  return sph_step_rk_acceleration(sim, &m->ref, &m->ode, err);
}

static void tl_jst_energy(sph_sim *sim, double *kinetic, double *strain) {
  tl_jst *m = sim->method_data;
  sph_ref_energy(sim, &m->ref, m->fields == TL_JST_PFHJ ? m->H : NULL,
                 m->fields == TL_JST_PF ? NULL : m->J, kinetic, strain);
}

static void tl_jst_destroy(sph_sim *sim) {
  tl_jst *m = sim->method_data;
  if (!m)
    return;
  sph_ref_destroy(&m->ref);
  free(m->H);
  free(m->lap);
  free(m->lu_p);
  free(m->fgrad);
  free(m->fgrad_self);
  free(m->rev);
  free(m->x0);
  free(m->p0);
  free(m->F0);
  free(m->H0);
  free(m->J0);
  free(m->dx);
  free(m->dp);
  free(m->dF);
  free(m->dH);
  free(m->dJ);
  free(m->xmoment);
  free(m);
  sim->method_data = NULL;
}

/* ---- setup
 * -------------------------------------------------------------------------- */

static sph_status alloc_zero(double **p, size_t count, sph_error *err) {
  *p = calloc(count ? count : 1, sizeof **p);
  return *p ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "tl-jst arrays");
}

/* The options of the method block. */
typedef struct tl_jst_options {
  tl_jst_fields fields;
  tl_jst_force force;
  int gradient_laplacian; /* laplacian: gradient (else corrected) */
  sph_rk_step integrate;
  int lagrange;          /* essential_bc: lagrange (else direct) */
  int lagrange_momentum; /* the total momentum rows of the projection */
  int current_wave_speed, wave_speed_every;
  double cfl;
  int amp, jproj; /* angular momentum and JST projections */
  double e2p, e4p, e2j, e4j;
} tl_jst_options;

/* The `jst` block's coefficients into o (fields already parsed). */
static sph_status jst_options_parse(sph_node *opt, tl_jst_options *o,
                                    sph_error *err) {
  sph_node *jst;
  SPH_TRY(sph_node_insert_default(opt, "jst", "{}", &jst, err));
  if (jst->kind != SPH_NODE_MAP)
    return sph_node_error(jst, err, SPH_ERR_TYPE, "expected a mapping");
  static const char *const jkeys[] = {"eps2_p", "eps4_p", "eps2_J", "eps4_J",
                                      NULL};
  SPH_TRY(sph_node_check_keys(jst, jkeys, err));
  SPH_TRY(sph_node_get_double(jst, "eps2_p", 0, 0.0, &o->e2p, err));
  SPH_TRY(sph_node_get_double(jst, "eps4_p", 0, 0.125, &o->e4p, err));
  SPH_TRY(sph_node_get_double(jst, "eps2_J", 0, 0.0, &o->e2j, err));
  SPH_TRY(sph_node_get_double(jst, "eps4_J", 0, 0.0, &o->e4j, err));
  if (o->fields == TL_JST_PF && (o->e2j != 0.0 || o->e4j != 0.0))
    return sph_node_error(
        sph_node_child(jst, o->e2j != 0.0 ? "eps2_J" : "eps4_J"), err,
        SPH_ERR_ARG,
        "fields pF has no J equation; use fields pFJ or "
        "pFHJ for JST on J, or set it to 0");
  double eps[4] = {o->e2p, o->e4p, o->e2j, o->e4j};
  for (int i = 0; i < 4; ++i)
    if (eps[i] < 0.0)
      return sph_node_error(jst, err, SPH_ERR_RANGE,
                            "JST coefficients must be >= 0");
  return SPH_OK;
}

static sph_status tl_jst_options_parse(sph_node *opt, tl_jst_options *o,
                                       sph_error *err) {
  static const char *const keys[] = {"name",
                                     "fields",
                                     "force",
                                     "jst",
                                     "jst_projection",
                                     "angular_momentum_projection",
                                     "laplacian",
                                     "integrator",
                                     "cfl",
                                     "essential_bc",
                                     "wave_speed",
                                     "wave_speed_every",
                                     "lagrange_momentum",
                                     NULL};
  SPH_TRY(sph_node_check_keys(opt, keys, err));
  static const char *const fields[] = {"pF", "pFJ", "pFHJ", NULL};
  static const char *const forces[] = {"conservative", "symmetric", "eq30",
                                       "eq31", NULL};
  static const char *const laps[] = {"corrected", "gradient", NULL};
  static const char *const integrators[] = {"tvd-rk2", "ssp-rk3", NULL};
  static const char *const bcs[] = {"direct", "lagrange", NULL};
  int f, fo, lp, integ, bc;
  SPH_TRY(sph_node_get_choice(opt, "fields", fields, "pF", &f, err));
  SPH_TRY(sph_node_get_choice(opt, "force", forces, "conservative", &fo, err));
  SPH_TRY(sph_node_get_choice(opt, "laplacian", laps, "corrected", &lp, err));
  SPH_TRY(sph_node_get_choice(opt, "integrator", integrators, "tvd-rk2", &integ,
                              err));
  SPH_TRY(sph_node_get_choice(opt, "essential_bc", bcs, "direct", &bc, err));
  SPH_TRY(sph_node_get_bool(opt, "lagrange_momentum", 0, 0,
                            &o->lagrange_momentum, err));
  if (o->lagrange_momentum && bc != 1)
    return sph_node_error(sph_node_child(opt, "lagrange_momentum"), err,
                          SPH_ERR_ARG,
                          "lagrange_momentum needs essential_bc: lagrange");
  static const char *const speeds[] = {"current", "reference", NULL};
  int ws;
  SPH_TRY(sph_node_get_choice(opt, "wave_speed", speeds, "current", &ws, err));
  o->current_wave_speed = ws == 0;
  long every;
  SPH_TRY(sph_node_get_int(opt, "wave_speed_every", 0, 1, &every, err));
  if (every < 1 || every > 1000000)
    return sph_node_error(
        sph_node_child(opt, "wave_speed_every"), err, SPH_ERR_RANGE,
        "wave_speed_every must be in [1, 1000000], got %ld", every);
  o->wave_speed_every = (int)every;
  o->integrate = integ == 1 ? sph_ssp_rk3_step : sph_tvd_rk2_step;
  o->fields = (tl_jst_fields)f;
  o->force = (tl_jst_force)fo;
  o->gradient_laplacian = lp == 1;
  o->lagrange = bc == 1;
  /* each integrator's default CFL: about 0.8 of the largest measured stable
   * on the column, the punch and the cube (docs/results.md, tl-jst's time
   * step) for SSP-RK3; seed 000's 0.3 for TVD-RK2 */
  static const double default_cfl[] = {0.3, 1.2};
  SPH_TRY(sph_node_get_double(opt, "cfl", 0, default_cfl[integ], &o->cfl, err));
  if (!(o->cfl > 0.0 && o->cfl <= 1.5))
    return sph_node_error(sph_node_child(opt, "cfl"), err, SPH_ERR_RANGE,
                          "cfl must be in (0, 1.5], got %g", o->cfl);
  SPH_TRY(sph_node_get_bool(opt, "angular_momentum_projection", 0, 1, &o->amp,
                            err));
  SPH_TRY(sph_node_get_bool(opt, "jst_projection", 0, 1, &o->jproj, err));
  return jst_options_parse(opt, o, err);
}

/* The per-slot arrays of the chosen force and dissipation: eq. 31's
 * gradients of W~1 and reverse slots, the Laplacian weights
 * V_b Lap W~_b(X_a) of the JST term (corrected, or the Brookshaw form with
 * the corrected gradient of docs/benchmarks.md D.4). */
static sph_status setup_slots(tl_jst *m, sph_sim *sim, const sph_cloud *cloud,
                              int gradient_laplacian, int need_lap,
                              sph_error *err) {
  size_t ne = m->ref.n_ext;
  if (m->force == TL_JST_EQ31) {
    SPH_TRY(alloc_zero(&m->fgrad, 3 * m->ref.nl->count, err));
    SPH_TRY(alloc_zero(&m->fgrad_self, 3 * ne, err));
    SPH_TRY(sph_correction_gradient(cloud, SPH_GRAD_W1, m->fgrad, m->fgrad_self,
                                    NULL, err));
    SPH_TRY(sph_ref_reverse_slots(&m->ref, &m->rev, err));
    SPH_TRY(sph_ref_ghost_slots(sim, &m->ref, cloud, SPH_GRAD_W1, m->rev,
                                m->fgrad, NULL, err));
  }
  if (!need_lap)
    return SPH_OK;
  SPH_TRY(alloc_zero(&m->lap, m->ref.nl->count, err));
  if (!gradient_laplacian) {
    SPH_TRY(sph_correction_laplacian(cloud, m->lap, err));
  } else {
    const double *X = m->ref.X;
    for (size_t a = 0; a < cloud->n; ++a)
      for (size_t k = m->ref.nl->offset[a]; k < m->ref.nl->offset[a + 1]; ++k) {
        size_t b = (size_t)m->ref.nl->index[k];
        double r[3], g[3];
        ref_iact_pair_vector(X, a, b, r);
        sph_ref_gradient(&m->ref, a, k, g);
        m->lap[k] = -2.0 * sph_vec3_dot(r, g) / sph_vec3_dot(r, r);
      }
  }
  /* the JST term takes V_b Lap W~_b(X_a) */
  for (size_t a = 0; a < cloud->n; ++a)
    for (size_t k = m->ref.nl->offset[a]; k < m->ref.nl->offset[a + 1]; ++k)
      m->lap[k] *= m->ref.V[m->ref.nl->index[k]];
  return SPH_OK;
}

/* The integrator's copies and rates of the variables of the chosen
 * fields. */
static sph_status setup_ode(tl_jst *m, size_t n, sph_error *err) {
  size_t len[5] = {3 * n, 3 * n, 9 * n, 9 * n, n};
  double **y[5] = {&m->x, &m->p, &m->F, &m->H, &m->J};
  double **y0[5] = {&m->x0, &m->p0, &m->F0, &m->H0, &m->J0};
  double **r[5] = {&m->dx, &m->dp, &m->dF, &m->dH, &m->dJ};
  int use[5] = {1, 1, 1, m->fields == TL_JST_PFHJ, m->fields != TL_JST_PF};
  sph_ode *ode = &m->ode;
  for (int i = 0; i < 5; ++i)
    if (use[i])
      SPH_TRY(sph_ode_add(ode, *y[i], len[i], y0[i], r[i], err));
  SPH_TRY(alloc_zero(&m->xmoment, 3 * n, err));
  ode->rhs = tl_jst_rhs;
  ode->constrain = tl_jst_constrain;
  ode->ctx = m;
  return SPH_OK;
}

/* The terms, only those asked for, in the order of Algorithm 1; the
 * essential boundary conditions imposed on the initial state. */
static sph_status setup_terms(tl_jst *m, sph_sim *sim, const sph_cloud *cloud,
                              const tl_jst_options *o, sph_error *err) {
  const sph_scene *s = sim->scene;
  if (o->amp)
    SPH_TRY(angular_momentum_projection_create(sim, err));
  if (o->e2p != 0.0 || o->e4p != 0.0) {
    if (m->force == TL_JST_CONSERVATIVE)
      SPH_TRY(alloc_zero(&m->lu_p, 3 * m->ref.n_ext, err));
    jst_params jp = {.nl = m->ref.nl,
                     .lap = m->lap,
                     .lu = m->lu_p,
                     .V = m->ref.V,
                     .ncomp = 3,
                     .eps2 = o->e2p,
                     .eps4 = o->e4p,
                     .cp = m->ref.cp,
                     .h = sim->dp,
                     .project = o->jproj};
    SPH_TRY(jst_dissipation_create(sim, &jp, err));
  }
  if (o->e2j != 0.0 || o->e4j != 0.0) {
    jst_params jp = {.nl = m->ref.nl,
                     .lap = m->lap,
                     .V = m->ref.V,
                     .ncomp = 1,
                     .eps2 = o->e2j,
                     .eps4 = o->e4j,
                     .cp = m->ref.cp,
                     .h = sim->dp,
                     .project = o->jproj,
                     .exchange_u = !m->ref.sync_images};
    SPH_TRY(jst_dissipation_create(sim, &jp, err));
  }
  SPH_TRY(sph_step_external_terms(sim, &m->ref, err));
  int planes = 0;
  for (size_t k = 0; k < s->nboundaries; ++k)
    planes |= s->boundaries[k].kind == SPH_BC_SYMMETRY ||
              s->boundaries[k].kind == SPH_BC_SKEW_SYMMETRY;
  if (o->lagrange && (planes || sph_scene_has_essential_bc(s))) {
    /* symmetry planes are constraints here, not mirror images */
    SPH_TRY(lagrange_projection_create(sim, cloud, m->ref.rho0,
                                       o->lagrange_momentum, err));
    return tl_jst_constrain(m, 0.0, err);
  }
  return sph_step_essential_bc(sim, &m->ref, tl_jst_constrain, m, err);
}

static sph_status tl_jst_setup(sph_sim *sim, sph_node *opt, sph_error *err) {
  tl_jst_options o = {0};
  SPH_TRY(tl_jst_options_parse(opt, &o, err));
  tl_jst *m = calloc(1, sizeof *m);
  if (!m)
    return sph_error_set(err, SPH_ERR_NOMEM, "tl-jst");
  sim->method_data = m;
  m->sim = sim;
  size_t n = sim->ps->n;
  m->current_wave_speed = o.current_wave_speed;
  m->wave_speed_every = o.wave_speed_every;
  m->integrate = o.integrate;
  m->fields = o.fields;
  m->force = o.force;
  m->cfl = o.cfl;
  /* reference configuration (with mirror images) and the state */
  SPH_TRY(sph_ref_create(&m->ref, sim, !o.lagrange, err));
  size_t ne = m->ref.n_ext;
  /* symmetry planes exert forces: the totals the projections zero are not
   * zero there */
  if (m->ref.n_img > n && (o.amp || o.jproj))
    return sph_node_error(
        sph_node_child(opt, o.amp ? "angular_momentum_projection"
                                  : "jst_projection"),
        err, SPH_ERR_ARG,
        "the momentum projections assume a free body; with symmetry planes "
        "set angular_momentum_projection and jst_projection to false");
  m->x = m->ref.x;
  m->p = m->ref.p;
  m->F = m->ref.F;
  m->J = m->ref.J;
  m->P = m->ref.P;
  if (m->fields == TL_JST_PFHJ) {
    SPH_TRY(sph_ref_alloc(&m->ref, 9, &m->H, err));
    for (size_t a = 0; a < ne; ++a)
      sph_mat3_cofactor(m->F + 9 * a, m->H + 9 * a);
  }
  /* over MPI ranks the ghosts' rows are not used (nor complete) */
  sph_cloud cloud = {.n = m->ref.n_img,
                     .partial = m->ref.partial,
                     .dim = sim->scene->dimension,
                     .x = m->ref.X,
                     .volume = m->ref.V,
                     .id = m->ref.id,
                     .nl = m->ref.nl,
                     .kernel = &sim->kernel};
  m->sweep = m->force == TL_JST_CONSERVATIVE ? sweep_conservative
             : m->force == TL_JST_EQ31       ? sweep_eq31
                                             : sweep_symmetric;
  int need_lap = o.e2p != 0.0 || o.e4p != 0.0 || o.e2j != 0.0 || o.e4j != 0.0;
  SPH_TRY(setup_slots(m, sim, &cloud, o.gradient_laplacian, need_lap, err));
  m->timer_force = sph_sim_add_timer(sim, "internal_force");
  m->timer_integration = sph_sim_add_timer(sim, "time_integration");
  SPH_TRY(setup_ode(m, n, err));
  return setup_terms(m, sim, &cloud, &o, err);
}

static int tl_jst_state(sph_sim *sim, sph_state_array *out) {
  tl_jst *m = sim->method_data;
  static const char *const names[] = {"x", "p", "F", "H", "J"};
  const double *y[5] = {m->x, m->p, m->F, m->H, m->J};
  int k = 0;
  for (int v = 0; v < m->ode.nvec; ++v)
    for (int i = 0; i < 5; ++i)
      if (m->ode.y[v] == y[i])
        out[k++] = (sph_state_array){names[i], m->ode.y[v], m->ode.len[v]};
  return k;
}

const sph_method_ops tl_jst_method_ops = {
    .name = "tl-jst",
    .title = "Total-Lagrangian JST-SPH, mixed {p,F}/{p,F,J}/{p,F,H,J}",
    .reference = "seed 000 (Lee et al. 2016) sec. 3-7, Algorithm 1; seed 003 "
                 "eq. 11",
    .conserves_angular_momentum = 1,
    .distributed = 1,
    .gpu = 1, /* pF with the conservative force (gpu/tl_jst_twin.c) */
    .fields = SPH_REF_OUTPUT_FIELDS,
    .setup = tl_jst_setup,
    .stable_dt = tl_jst_stable_dt,
    .step = tl_jst_step,
    .derive = tl_jst_derive,
    .energy = tl_jst_energy,
    .state = tl_jst_state,
    .destroy = tl_jst_destroy,
};
