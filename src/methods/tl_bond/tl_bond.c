/* tl-bond: total-Lagrangian SPH with the improved bond-based deformation
 * gradient of seed 004 (Wiragunarsa, Zuhal, Dirgantara, Putra, Febrianto):
 * first-order corrected kernel and its exact gradient (eq. 6-8, App. A; or
 * the zeroth-order kernel with the gradient correction of eq. 10-14),
 * symmetrised momentum equation (eq. 22), deformation gradient rate
 * (eq. 24), the stress evaluated at the bond-corrected
 * F^c_a = sum_b V_b W~_b(X_a) F_ab (eq. 37) with the bond gradient of
 * eq. 39, symmetrised JST dissipation on p (eq. 27-28), three-stage SSP-RK3
 * (eq. 30) and the pair wave speed time step (eq. 31-32).
 *
 * With sum_b V_b W~_b(X_a) = 1 (eq. 5a, b = a included, F_aa = F_a) eq. 37
 * with eq. 39 reads F^c_a = F_a M_a + sum_{b != a} (x_b - x_a) (x) q_ab,
 * q_ab = V_b W~_b(X_a) (X_b - X_a) / |X_b - X_a|^2 and
 * M_a = I - sum_b (X_b - X_a) (x) q_ab, both fixed at set-up: a homogeneous
 * deformation x_b - x_a = F (X_b - X_a) gives F^c = F exactly. F itself is
 * integrated from eq. 24 and F^c is recomputed from it and the positions at
 * every stage (it does not replace F). Over MPI ranks (sph_domain) each
 * stage exchanges the ghosts' x, p and P, and the ghosts' pair weights
 * toward this rank's particles come from their owners' coefficients. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/corrections.h"
#include "core/tensor.h"
#include "methods/registry_impl.h"
#include "methods/tl_bond/tl_bond_iact.h"
#include "methods/tl_bond/tl_bond_impl.h"
#include "terms/terms_impl.h"

/* ---- deformation and stress
 * ---------------------------------------------------- */

/* F^c of the real particles (eq. 37-39) */
static void bond_defgrad_owned(tl_bond *m, long n) {
  const sph_ref *ref = &m->ref;
  const sph_neighbors *nl = ref->nl;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double Fc[9];
    const double *xa = m->x + 3 * a;
    sph_mat3_mul(m->F + 9 * a, m->Mc + 9 * a, Fc);
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k)
      tl_bond_iact_defgrad(Fc, xa, m->x + 3 * (size_t)nl->index[k],
                           m->q + 3 * k);
    memcpy(m->Fc + 9 * a, Fc, sizeof Fc);
  }
}

/* the same mirrored onto the images (over MPI ranks those of ghosts from
 * the ghosts' F^c) */
static sph_status bond_defgrad(tl_bond *m, long n, sph_error *err) {
  const sph_ref *ref = &m->ref;
  bond_defgrad_owned(m, n);
  SPH_TRY(sph_mirror_sources(m->sim, ref, m->Fc, 9, err));
  if (ref->n_ext > ref->n)
    sph_mirror_state(ref, m->x, m->p, m->Fc, NULL, NULL);
  return SPH_OK;
}

/* images from their sources, F^c (or F) into *Fs, P at it for every
 * point; over MPI ranks the ghosts' x and p before, their P after (from
 * their owners) */
static sph_status deformation_and_stress(tl_bond *m, const double **Fs,
                                         sph_error *err) {
  sph_ref *ref = &m->ref;
  sph_domain *d = m->sim->domain;
  long n = (long)ref->n, ne = (long)ref->n_ext, ni = (long)ref->n_img;
  SPH_TRY(sph_domain_exchange(d, m->x, 3, err));
  SPH_TRY(sph_domain_exchange(d, m->p, 3, err));
  if (!m->bond) /* the images' stress is at their F */
    SPH_TRY(sph_mirror_sources(m->sim, ref, m->F, 9, err));
  if (ne > n)
    sph_mirror_state(ref, m->x, m->p, m->F, NULL, NULL);
  *Fs = m->F;
  if (m->bond) {
    SPH_TRY(bond_defgrad(m, n, err));
    *Fs = m->Fc;
  }
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ni; ++a) {
    double H[9];
    const double *Fa = *Fs + 9 * a;
    sph_mat3_cofactor(Fa, H);
    sph_material_stress(ref->mat[a], Fa, H, sph_mat3_det(Fa), m->P + 9 * a);
  }
  return sph_domain_exchange(d, m->P, 9, err);
}

/* ---- right-hand side
 * ----------------------------------------------------------- */

static sph_status tl_bond_rhs(void *ctx, int stage, double t, double dt,
                              sph_error *err) {
  tl_bond *m = ctx;
  sph_sim *sim = m->sim;
  const sph_ref *ref = &m->ref;
  const sph_neighbors *nl = ref->nl;
  long n = (long)ref->n;
  double t0 = sph_wtime();
  (void)stage;
  (void)dt;
  const double *Fs;
  SPH_TRY(deformation_and_stress(m, &Fs, err));
  long ne = (long)ref->n_ext;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ne; ++a)
    for (int c = 0; c < 3; ++c)
      m->v[3 * a + c] = m->p[3 * a + c] / ref->rho0[a];
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double dF[9] = {0}, dp[3] = {0, 0, 0};
    const double *Pa = m->P + 9 * a, *va = m->v + 3 * a;
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      tl_bond_iact_rates(dF, dp, va, m->v + 3 * b, Pa, m->P + 9 * b,
                         m->gv + 3 * k, m->fa + 3 * k, m->fb + 3 * k);
    }
    memcpy(m->dF + 9 * a, dF, sizeof dF);
    for (int c = 0; c < 3; ++c) {
      m->dp[3 * a + c] = dp[c];
      m->dx[3 * a + c] = va[c];
    }
  }
  return sph_step_rates_terms(sim, ref, m->dp, m->timer_force, t0, t, err);
}

static sph_status tl_bond_constrain(void *ctx, double t, sph_error *err) {
  tl_bond *m = ctx;
  return sph_step_constrain_terms(m->sim, &m->ref, t, err);
}

/* ---- ops
 * ------------------------------------------------------------------------- */

/* eq. 31: dt = cfl min_ij r_ij / c_p,ij over the current pairs, c_p,ij of
 * eq. 32 from the smallest principal stretches of F (or c_p^Lin) */
static double tl_bond_stable_dt(sph_sim *sim) {
  tl_bond *m = sim->method_data;
  const sph_ref *ref = &m->ref;
  const sph_neighbors *nl = ref->nl;
  long n = (long)ref->n, ne = (long)ref->n_ext, ni = (long)ref->n_img;
  /* over MPI ranks the pairs read the ghosts' x and stretches, the images
   * of ghosts the ghosts' x and F */
  if (sph_domain_exchange(sim->domain, m->x, 3, NULL) != SPH_OK ||
      (m->pair_speed && sph_mirror_sources(sim, ref, m->F, 9, NULL) != SPH_OK))
    return NAN;
  if (ne > n)
    sph_mirror_state(ref, m->x, m->p, m->F, NULL, NULL);
  double lam_min = 1.0;
  if (m->pair_speed) {
    lam_min = INFINITY;
#pragma omp parallel for schedule(static) reduction(min : lam_min)
    for (long a = 0; a < ni; ++a) {
      double Ft[9], C[9], lo, hi;
      sph_mat3_transpose(m->F + 9 * a, Ft);
      sph_mat3_mul(Ft, m->F + 9 * a, C);
      sph_mat3_sym_extremes(C, &lo, &hi);
      m->lam[a] = sqrt(fmax(lo, 0.0));
      lam_min = fmin(lam_min, m->lam[a]);
    }
    lam_min = sph_domain_min(sim->domain, lam_min);
    if (sph_domain_exchange(sim->domain, m->lam, 1, NULL) != SPH_OK)
      return NAN;
  }
  double tmin = INFINITY;
#pragma omp parallel for schedule(static) reduction(min : tmin)
  for (long a = 0; a < n; ++a)
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      double la = m->pair_speed ? m->lam[a] : 1.0;
      double lb = m->pair_speed ? m->lam[b] : 1.0;
      double ts =
          tl_bond_iact_transit(m->x + 3 * a, m->x + 3 * b, la, lb, ref->cp);
      tmin = ts < tmin ? ts : tmin;
    }
  /* the JST's c_p: the fastest pair speed of the step */
  m->cp_now = ref->cp / fmax(lam_min, 1e-12);
  if (!isfinite(tmin)) /* a particle without neighbours */
    tmin = sim->dp / ref->cp;
  return m->cfl * tmin;
}

static sph_status tl_bond_step(sph_sim *sim, double dt, sph_error *err) {
  tl_bond *m = sim->method_data;
  return sph_step_rk(sim, &m->ref, &m->ode, m->integrate, m->timer_integration,
                     dt, err);
}

static sph_status tl_bond_derive(sph_sim *sim, sph_error *err) {
  tl_bond *m = sim->method_data;
  const double *Fs;
  SPH_TRY(deformation_and_stress(m, &Fs, err));
  sph_ref_derive(sim, &m->ref, NULL, NULL, Fs);
  return sph_step_rk_acceleration(sim, &m->ref, &m->ode, err);
}

/* strain energy at the F the stress is evaluated at */
static void tl_bond_energy(sph_sim *sim, double *kinetic, double *strain) {
  tl_bond *m = sim->method_data;
  sph_ref r = m->ref;
  if (m->bond) {
    bond_defgrad_owned(m, (long)r.n);
    r.F = m->Fc;
  }
  sph_ref_energy(sim, &r, NULL, NULL, kinetic, strain);
}

static void tl_bond_destroy(sph_sim *sim) {
  tl_bond *m = sim->method_data;
  if (!m)
    return;
  sph_ref_destroy(&m->ref);
  double *arrays[] = {m->v,       m->gv,      m->fa,       m->fb, m->q,  m->lap,
                      m->lap_sym, m->lap_adj, m->lap_diag, m->Mc, m->Fc, m->lam,
                      m->x0,      m->p0,      m->F0,       m->dx, m->dp, m->dF};
  for (size_t i = 0; i < sizeof arrays / sizeof *arrays; ++i)
    free(arrays[i]);
  free(m);
  sim->method_data = NULL;
}

/* ---- setup
 * -------------------------------------------------------------------------- */

static sph_status alloc_zero(double **p, size_t count, sph_error *err) {
  *p = calloc(count ? count : 1, sizeof **p);
  return *p ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "tl-bond arrays");
}

/* the pair weights of eq. 22, 24, 27-28 and 37-39 in the reference
 * configuration */
static sph_status pair_weights(tl_bond *m, sph_sim *sim, int first_order,
                               int symmetric, int need_lap, sph_error *err) {
  const sph_ref *ref = &m->ref;
  const sph_neighbors *nl = ref->nl;
  size_t ne = ref->n_ext, count = nl->count;
  /* over MPI ranks the ghosts' rows are not whole: their slots toward this
   * rank's particles come from their owners' coefficients (sph_ref_ghost_slots)
   */
  sph_cloud cloud = {.n = ref->n_img,
                     .partial = ref->partial,
                     .dim = sim->scene->dimension,
                     .x = ref->X,
                     .volume = ref->V,
                     .id = ref->id,
                     .nl = nl,
                     .kernel = &sim->kernel};
  double *g = NULL, *w = NULL, *wself = NULL, *lap = NULL;
  size_t *rev = NULL;
  sph_gradient_kind kind = first_order ? SPH_GRAD_W1 : SPH_GRAD_CORRECTED_W0;
  sph_status st;
  if ((st = alloc_zero(&g, 3 * count, err)) != SPH_OK ||
      (st = alloc_zero(&w, count, err)) != SPH_OK ||
      (st = alloc_zero(&wself, ne, err)) != SPH_OK ||
      (need_lap && (st = alloc_zero(&lap, count, err)) != SPH_OK) ||
      (st = sph_ref_reverse_slots(ref, &rev, err)) != SPH_OK ||
      (st = sph_correction_gradient(&cloud, kind, g, NULL, NULL, err)) !=
          SPH_OK ||
      (st = sph_correction_kernel(&cloud, first_order ? 1 : 0, w, wself,
                                  err)) != SPH_OK ||
      (need_lap &&
       (st = sph_correction_laplacian(&cloud, lap, err)) != SPH_OK) ||
      (st = sph_ref_ghost_slots(sim, ref, &cloud, kind, rev, g, lap, err)) !=
          SPH_OK)
    goto done;
  for (size_t a = 0; a < cloud.n; ++a) {
    double *M = m->Mc + 9 * a;
    sph_mat3_identity(M);
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      double Vb = ref->V[b], r[3], r2 = 0.0;
      for (int c = 0; c < 3; ++c) {
        r[c] = ref->X[3 * b + c] - ref->X[3 * a + c];
        r2 += r[c] * r[c];
      }
      for (int c = 0; c < 3; ++c) {
        m->gv[3 * k + c] = Vb * g[3 * k + c];
        if (symmetric) {
          m->fa[3 * k + c] = 0.5 * Vb * (g[3 * k + c] - g[3 * rev[k] + c]);
          m->fb[3 * k + c] = m->fa[3 * k + c];
        } else {
          m->fa[3 * k + c] = Vb * g[3 * k + c];
          m->fb[3 * k + c] = -Vb * g[3 * rev[k] + c];
        }
        m->q[3 * k + c] = Vb * w[k] * r[c] / r2;
      }
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          M[3 * i + j] -= r[i] * m->q[3 * k + j];
      if (need_lap) {
        m->lap[k] = Vb * lap[k];
        m->lap_sym[k] = 0.5 * Vb * (lap[k] + lap[rev[k]]);
        if (m->lap_adj) {
          m->lap_adj[k] = Vb * lap[rev[k]];
          m->lap_diag[a] += m->lap_adj[k] - m->lap[k];
        }
      }
    }
  }
done:
  free(g);
  free(w);
  free(wself);
  free(lap);
  free(rev);
  return st;
}

/* The options of the method block. */
typedef struct tl_bond_options {
  int bond;        /* deformation_gradient: bond (else average) */
  int first_order; /* correction: first_order (else zeroth_order) */
  int symmetric;   /* force: symmetric (else conservative) */
  int pair_speed;  /* wave_speed: pair (else linear) */
  sph_rk_step integrate;
  double cfl;
  double e2p, e4p; /* JST on p */
  int adjoint;     /* jst.outer: adjoint (else eq. 28's symmetric sums) */
} tl_bond_options;

static sph_status tl_bond_options_parse(sph_node *opt, tl_bond_options *o,
                                        sph_error *err) {
  static const char *const keys[] = {
      "name", "deformation_gradient", "correction", "force", "integrator",
      "cfl",  "wave_speed",           "jst",        NULL};
  SPH_TRY(sph_node_check_keys(opt, keys, err));
  static const char *const defgrads[] = {"bond", "average", NULL};
  static const char *const corrections[] = {"first_order", "zeroth_order",
                                            NULL};
  static const char *const integrators[] = {"ssp-rk3", "tvd-rk2", NULL};
  static const char *const speeds[] = {"pair", "linear", NULL};
  static const char *const forces[] = {"symmetric", "conservative", NULL};
  int dg, corr, integ, ws, fo;
  SPH_TRY(sph_node_get_choice(opt, "force", forces, "conservative", &fo, err));
  SPH_TRY(sph_node_get_choice(opt, "deformation_gradient", defgrads, "bond",
                              &dg, err));
  SPH_TRY(sph_node_get_choice(opt, "correction", corrections, "first_order",
                              &corr, err));
  SPH_TRY(sph_node_get_choice(opt, "integrator", integrators, "ssp-rk3", &integ,
                              err));
  SPH_TRY(sph_node_get_choice(opt, "wave_speed", speeds, "pair", &ws, err));
  o->bond = dg == 0;
  o->first_order = corr == 0;
  o->symmetric = fo == 0;
  o->pair_speed = ws == 0;
  o->integrate = integ == 0 ? sph_ssp_rk3_step : sph_tvd_rk2_step;
  SPH_TRY(sph_node_get_double(opt, "cfl", 0, 0.9, &o->cfl, err));
  /* both integrators are SSP with coefficient 1: stable up to the forward
   * Euler limit, CFL 1 (seed 004 runs up to 0.9) */
  if (!(o->cfl > 0.0 && o->cfl <= 1.0))
    return sph_node_error(sph_node_child(opt, "cfl"), err, SPH_ERR_RANGE,
                          "cfl must be in (0, 1] (the SSP limit of %s), got %g",
                          integrators[integ], o->cfl);
  sph_node *jst;
  SPH_TRY(sph_node_insert_default(opt, "jst", "{}", &jst, err));
  if (jst->kind != SPH_NODE_MAP)
    return sph_node_error(jst, err, SPH_ERR_TYPE, "expected a mapping");
  static const char *const jkeys[] = {"eps2_p", "eps4_p", "outer", NULL};
  SPH_TRY(sph_node_check_keys(jst, jkeys, err));
  static const char *const outers[] = {"adjoint", "symmetric", NULL};
  int outer;
  SPH_TRY(sph_node_get_choice(jst, "outer", outers, "adjoint", &outer, err));
  o->adjoint = outer == 0;
  SPH_TRY(sph_node_get_double(jst, "eps2_p", 0, 0.0, &o->e2p, err));
  SPH_TRY(sph_node_get_double(jst, "eps4_p", 0, 0.125, &o->e4p, err));
  if (o->e2p < 0.0 || o->e4p < 0.0)
    return sph_node_error(
        sph_node_child(jst, o->e2p < 0.0 ? "eps2_p" : "eps4_p"), err,
        SPH_ERR_RANGE, "JST coefficients must be >= 0");
  return SPH_OK;
}

static sph_status tl_bond_setup(sph_sim *sim, sph_node *opt, sph_error *err) {
  tl_bond_options o = {0};
  SPH_TRY(tl_bond_options_parse(opt, &o, err));
  tl_bond *m = calloc(1, sizeof *m);
  if (!m)
    return sph_error_set(err, SPH_ERR_NOMEM, "tl-bond");
  sim->method_data = m;
  m->sim = sim;
  size_t n = sim->ps->n;
  m->bond = o.bond;
  m->pair_speed = o.pair_speed;
  m->integrate = o.integrate;
  m->cfl = o.cfl;
  double e2p = o.e2p, e4p = o.e4p;

  /* reference configuration with images across symmetry planes, state */
  SPH_TRY(sph_ref_create(&m->ref, sim, 1, err));
  size_t ne = m->ref.n_ext, count = m->ref.nl->count;
  m->x = m->ref.x;
  m->p = m->ref.p;
  m->F = m->ref.F;
  m->P = m->ref.P;
  int need_lap = e2p != 0.0 || e4p != 0.0;
  SPH_TRY(alloc_zero(&m->gv, 3 * count, err));
  SPH_TRY(alloc_zero(&m->fa, 3 * count, err));
  SPH_TRY(alloc_zero(&m->fb, 3 * count, err));
  SPH_TRY(alloc_zero(&m->q, 3 * count, err));
  if (need_lap) {
    SPH_TRY(alloc_zero(&m->lap, count, err));
    SPH_TRY(alloc_zero(&m->lap_sym, count, err));
    if (o.adjoint) {
      SPH_TRY(alloc_zero(&m->lap_adj, count, err));
      SPH_TRY(alloc_zero(&m->lap_diag, ne, err));
    }
  }
  SPH_TRY(alloc_zero(&m->Mc, 9 * ne, err));
  SPH_TRY(alloc_zero(&m->v, 3 * ne, err));
  if (m->bond)
    SPH_TRY(alloc_zero(&m->Fc, 9 * ne, err));
  if (m->pair_speed)
    SPH_TRY(alloc_zero(&m->lam, ne, err));
  SPH_TRY(pair_weights(m, sim, o.first_order, o.symmetric, need_lap, err));
  m->cp_now = m->ref.cp;
  m->timer_force = sph_sim_add_timer(sim, "internal_force");
  m->timer_integration = sph_sim_add_timer(sim, "time_integration");

  /* integrator storage */
  sph_ode *ode = &m->ode;
  SPH_TRY(sph_ode_add(ode, m->x, 3 * n, &m->x0, &m->dx, err));
  SPH_TRY(sph_ode_add(ode, m->p, 3 * n, &m->p0, &m->dp, err));
  SPH_TRY(sph_ode_add(ode, m->F, 9 * n, &m->F0, &m->dF, err));
  ode->rhs = tl_bond_rhs;
  ode->constrain = tl_bond_constrain;
  ode->ctx = m;

  /* terms, only those asked for */
  if (need_lap) {
    jst_params jp = {.nl = m->ref.nl,
                     .lap = m->lap,
                     .V = m->ref.V,
                     .ncomp = 3,
                     .eps2 = e2p,
                     .eps4 = e4p,
                     .cp = m->ref.cp,
                     .h = sim->dp,
                     .lap_sym = m->lap_sym,
                     .lap_adj = m->lap_adj,
                     .lap_diag = m->lap_diag,
                     .cp_now = m->pair_speed ? &m->cp_now : NULL};
    SPH_TRY(jst_dissipation_create(sim, &jp, err));
  }
  SPH_TRY(sph_step_external_terms(sim, &m->ref, err));
  return sph_step_essential_bc(sim, &m->ref, tl_bond_constrain, m, err);
}

static int tl_bond_state(sph_sim *sim, sph_state_array *out) {
  tl_bond *m = sim->method_data;
  return sph_step_state_xpF(&m->ref, out);
}

const sph_method_ops tl_bond_method_ops = {
    .name = "tl-bond",
    .title = "Total-Lagrangian SPH with the bond-based deformation gradient, "
             "SSP-RK3",
    .reference = "seed 004 (Wiragunarsa et al.) eq. 6-14, 22, 24, 28, 30-32, "
                 "37-39",
    .conserves_angular_momentum = 0,
    .distributed = 1,
    .fields = SPH_REF_OUTPUT_FIELDS,
    .setup = tl_bond_setup,
    .stable_dt = tl_bond_stable_dt,
    .step = tl_bond_step,
    .derive = tl_bond_derive,
    .energy = tl_bond_energy,
    .state = tl_bond_state,
    .destroy = tl_bond_destroy,
};
