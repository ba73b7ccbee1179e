/* ul-csph: the stabilised updated-Lagrangian corrected SPH of seed 001
 * sec. 3-4 (Vidal, Bonet, Huerta 2007): every `update_every` steps the
 * current configuration becomes the reference x^r (new neighbours and
 * corrected gradients, eq. 13; F^r = F kept as state; V^r = J^r V^0,
 * Remark 1); in between the incremental f = sum_b x_b g_b^T(x^r) (eq. 12)
 * gives F = f F^r and the internal force is eq. 14,
 * T_i = sum_j V^0_j P_j [F^r_j]^T g_i(x^r_j), m a = E - T, leap-frog as
 * tl-csph. With eta > 0 the gradients are the Hessian-difference
 * stabilised ones of sec. 3.4 (eq. 17-21: linearly corrected kernel
 * Hessian, h of Remark 2) in f and, as the adjoint of that map, in the
 * force; eta = 0 is the standard updated formulation of sec. 3.1, whose
 * zero-energy mechanisms (sec. 3.2-3.3) are left for the verdict to see. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"
#include "methods/registry_impl.h"
#include "methods/ul_csph/ul_csph_iact.h"
#include "methods/ul_csph/ul_csph_impl.h"
#include "terms/terms_impl.h"

/* f (eq. 12-13, stabilised by eq. 17 / 21 when eta > 0), F = f F^r, images
 * mirrored, ghosts' from their owners, P, S = P F^r^T / J^r and the force
 * matrices for every point */
static sph_status deformation_and_stress(ul_csph *m, long n, sph_error *err) {
  sph_ref *ref = &m->ref;
  const sph_neighbors *nl = ref->nl;
  sph_domain *dom = m->sim->domain;
  long ne = (long)ref->n_ext;
  /* a ghost's list is partial: its stabilised force matrix is its owner's */
  long nq = dom ? (long)ref->n_img : ne;
  int dim = m->sim->scene->dimension, stab = m->eta > 0.0;
  /* an image's source may be a ghost: its state first */
  SPH_TRY(sph_domain_exchange(dom, m->x, 3, err));
  if (ne > n)
    sph_mirror_state(ref, m->x, m->p, m->F, NULL, NULL);
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    ref_sums s; /* f = grad_r x (seed 001 eq. 12-13) */
    sph_ref_pair_sums(ref, (size_t)a, m->x, 0, NULL, &s);
    double f[9], unused[3];
    ref_sums_store(&s, f, unused);
    ref_iact_gradient_correct(f, ref->L + 9 * a);
    ref_iact_plane_strain(f, dim);
    if (stab)
      memcpy(m->f0 + 9 * a, f, sizeof f);
    else
      ul_iact_total_defgrad(f, m->Fr + 9 * a, m->F + 9 * a);
  }
  if (stab) {
    SPH_TRY(sph_domain_exchange(dom, m->f0, 9, err));
    if (ne > n)
      sph_mirror_state(ref, m->x, m->p, m->f0, NULL, NULL);
#pragma omp parallel for schedule(static)
    for (long a = 0; a < n; ++a) {
      double acc[9] = {0}, f[9];
      const double *f0a = m->f0 + 9 * a;
      for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
        size_t b = (size_t)nl->index[k];
        ul_iact_stab_defgrad(acc, ref->V[b], m->x + 3 * a, m->x + 3 * b,
                             m->hv + 3 * k, m->gh[k], f0a, m->f0 + 9 * b);
      }
      for (int c = 0; c < 9; ++c)
        f[c] = f0a[c] + m->eta * acc[c];
      ref_iact_plane_strain(f, dim);
      ul_iact_total_defgrad(f, m->Fr + 9 * a, m->F + 9 * a);
    }
  }
  SPH_TRY(sph_domain_exchange(dom, m->F, 9, err));
  if (ne > n)
    sph_mirror_state(ref, m->x, m->p, m->F, NULL, NULL);
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ne; ++a) {
    double H[9];
    sph_mat3_cofactor(m->F + 9 * a, H);
    sph_material_stress(ref->mat[a], m->F + 9 * a, H,
                        sph_mat3_det(m->F + 9 * a), m->P + 9 * a);
    ul_iact_reference_stress(m->P + 9 * a, m->Fr + 9 * a, m->Jr[a],
                             m->S + 9 * a);
    if (!stab)
      ul_iact_force_matrix(m->S + 9 * a, m->S + 9 * a, 0.0, ref->L + 9 * a,
                           ref->Qt + 9 * a);
  }
  if (!stab)
    return SPH_OK;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < nq; ++a) {
    double Y[9] = {0}; /* adjoint of the f0 difference term */
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t j = (size_t)nl->index[k];
      ul_iact_stab_adjoint(Y, m->gh[m->rev[k]], ref->V[j], m->S + 9 * j);
    }
    for (int c = 0; c < 9; ++c)
      Y[c] -= m->sgh[a] * ref->V[a] * m->S[9 * a + c];
    ul_iact_force_matrix(m->S + 9 * a, Y, m->eta / ref->V[a], ref->L + 9 * a,
                         ref->Qt + 9 * a);
  }
  return sph_domain_exchange(dom, ref->Qt, 9, err);
}

/* the Hessian term's share of the force (adjoint of eq. 21's first
 * stabilisation term) */
static void stabilisation_force(ul_csph *m, long n) {
  const sph_ref *ref = &m->ref;
  const sph_neighbors *nl = ref->nl;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double out[3] = {0, 0, 0}, self[3];
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t j = (size_t)nl->index[k];
      ul_iact_stab_hessian_force(out, ref->V[j], m->S + 9 * j,
                                 m->hv + 3 * m->rev[k]);
    }
    sph_mat3_vec(m->S + 9 * a, m->sv + 3 * a, self);
    for (int c = 0; c < 3; ++c)
      m->dp[3 * a + c] -= m->eta * (out[c] - self[c]);
  }
}

static sph_status ul_csph_rates(void *ctx, double t, sph_error *err) {
  ul_csph *m = ctx;
  sph_sim *sim = m->sim;
  long n = (long)sim->ps->n;
  double t0 = sph_wtime();
  SPH_TRY(deformation_and_stress(m, n, err));
  sph_ref_conservative_force(&m->ref, m->dp);
  if (m->eta > 0.0)
    stabilisation_force(m, n);
    /* per initial volume: dp_i = -T_i / V^0_i = J^r_i (-T_i / V^r_i) */
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c)
      m->dp[3 * a + c] *= m->Jr[a];
  return sph_step_rates_terms(sim, &m->ref, m->dp, m->timer_force, t0, t, err);
}

static sph_status ul_csph_constrain(void *ctx, double t, sph_error *err) {
  ul_csph *m = ctx;
  sph_mirror_hold(m->sim, &m->ref, m->x, m->p);
  return sph_step_constrain_terms(m->sim, &m->ref, t, err);
}

/* Per slot H~_k(x_a) h = H_k h + (A . (x_a - x_k)) h with the linear
 * correction A of eq. 19 contracted with h (the B of eq. 20 drops out of
 * the difference form), and g_k(x_a).h; per point their sums */
static sph_status stabilisation_setup(ul_csph *m, sph_error *err) {
  sph_ref *ref = &m->ref;
  const sph_neighbors *nl = ref->nl;
  const sph_kernel *kernel = &m->sim->kernel;
  if (nl->count + 1 > m->slot_cap) { /* grows only, amortised */
    size_t cap = 2 * (nl->count + 1);
    double *hv = realloc(m->hv, 3 * cap * sizeof *hv);
    if (hv)
      m->hv = hv;
    double *gh = realloc(m->gh, cap * sizeof *gh);
    if (gh)
      m->gh = gh;
    size_t *rev = realloc(m->rev, cap * sizeof *rev);
    if (rev)
      m->rev = rev;
    if (!hv || !gh || !rev)
      return sph_error_set(err, SPH_ERR_NOMEM, "ul-csph stabilisation");
    m->slot_cap = cap;
  }
  SPH_TRY(sph_domain_agree(m->sim->domain,
                           sph_ref_reverse_fill(ref, m->rev, err), err));
  int dim = m->sim->scene->dimension;
  long ne = (long)ref->n_ext;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ne; ++a) {
    double C[9] = {0}, D[9] = {0}, Dinv[9] = {0};
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      double r[3], d;
      ref_iact_pair_vector(ref->X, (size_t)a, b, r);
      d = sqrt(sph_vec3_dot(r, r));
      double *hv = m->hv + 3 * k;
      if (d > 0.0)
        ul_iact_hessian_h(r, d, sph_kernel_dwdr(kernel, d),
                          sph_kernel_d2wdr2(kernel, d), m->h, hv);
      else
        hv[0] = hv[1] = hv[2] = 0.0;
      /* C = sum V_k (H_k h) (x) (x_k - x_a), D = sum V_k r r^T */
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          C[3 * i + j] -= ref->V[b] * hv[i] * r[j];
          D[3 * i + j] += ref->V[b] * r[i] * r[j];
        }
    }
    for (int c = dim; c < 3; ++c)
      D[4 * c] = 1.0; /* no moment across the plane of a 2D body */
    sph_mat3_inverse(D, Dinv);
    sph_mat3_mul(C, Dinv, m->A + 9 * a);
  }
  /* a ghost's A is its owner's (its own list is partial) */
  SPH_TRY(sph_domain_exchange(m->sim->domain, m->A, 9, err));
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ne; ++a) {
    const double *Xa = ref->X + 3 * a, *M = m->A + 9 * a;
    double sv[3] = {0, 0, 0}, sgh = 0.0;
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      double r[3], Mr[3], g[3];
      for (int c = 0; c < 3; ++c)
        r[c] = Xa[c] - ref->X[3 * b + c];
      sph_mat3_vec(M, r, Mr);
      double *hv = m->hv + 3 * k;
      for (int c = 0; c < 3; ++c) {
        hv[c] += Mr[c];
        sv[c] += ref->V[b] * hv[c];
        r[c] *= ref->w[k];
      }
      sph_mat3_vec(ref->L + 9 * a, r, g); /* g_k(x_a), eq. 13 */
      m->gh[k] = sph_vec3_dot(g, m->h);
      sgh += m->gh[k];
    }
    memcpy(m->sv + 3 * a, sv, sizeof sv);
    m->sgh[a] = sgh;
  }
  return SPH_OK;
}

/* over MPI ranks the particles migrate and the ghosts are found again; then
 * V^r = J^r V^0 (Remark 1) and the neighbours and corrections in X = x^r */
static sph_status rebuild(ul_csph *m, sph_error *err) {
  sph_ref *ref = &m->ref;
  ul_mirror_sync(m);
  SPH_TRY(sph_ref_redistribute(ref, m->sim, err));
  SPH_TRY(ul_mirror_place(m, err));
  m->lf.n = ref->n;
  long ne = (long)ref->n_ext;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ne; ++a) {
    m->Jr[a] = sph_mat3_det(m->Fr + 9 * a);
    ref->V[a] = m->Jr[a] * m->V0[a];
  }
  sph_status st = sph_ref_rebuild(ref, m->sim, err);
  if (st == SPH_OK && m->eta > 0.0)
    st = stabilisation_setup(m, err);
  /* every rank learns of a failure before the next exchange */
  return sph_domain_agree(m->sim->domain, st, err);
}

/* x^r = x^n and F^r = F^n (seed 001 sec. 3.1, Fig. 8), timed on its own */
static sph_status reference_update(ul_csph *m, sph_error *err) {
  sph_sim *sim = m->sim;
  sph_ref *ref = &m->ref;
  double t0 = sph_wtime();
  SPH_TRY(deformation_and_stress(m, (long)ref->n, err));
  memcpy(ref->X, m->x, 3 * ref->n_ext * sizeof *ref->X);
  memcpy(m->Fr, m->F, 9 * ref->n_ext * sizeof *m->Fr);
  if (m->mirrored)
    sph_mirror_fold(sim, ref, m->x, m->p, m->F, m->Fr);
  ul_mirror_store(m);
  sph_status st = rebuild(m, err);
  m->lf.have_rates = 0; /* the rates of the new reference */
  m->since = 0.0;
  sim->timers[m->timer_update].seconds += sph_wtime() - t0;
  sim->timers[m->timer_update].calls++;
  return st;
}

static double ul_csph_stable_dt(sph_sim *sim) {
  const ul_csph *m = sim->method_data;
  return sph_ref_stable_dt(&m->ref, sim, m->cfl, 1);
}

/* the displacement criterion: some particle has moved more than
 * update_distance spacings from its reference position */
static int moved_beyond(ul_csph *m) {
  const sph_ref *ref = &m->ref;
  long n = (long)ref->n;
  double lim = m->update_distance * m->sim->dp, d2max = 0.0;
#pragma omp parallel for schedule(static) reduction(max : d2max)
  for (long a = 0; a < n; ++a) {
    double d[3];
    for (int c = 0; c < 3; ++c)
      d[c] = m->x[3 * a + c] - ref->X[3 * a + c];
    double d2 = sph_vec3_dot(d, d);
    d2max = d2 > d2max ? d2 : d2max;
  }
  return sph_domain_max(m->sim->domain, d2max) > lim * lim;
}

static sph_status ul_csph_step(sph_sim *sim, double dt, sph_error *err) {
  ul_csph *m = sim->method_data;
  if (m->update_distance > 0.0 ? moved_beyond(m) : m->since >= m->update_every)
    SPH_TRY(reference_update(m, err));
  m->since += 1.0;
  SPH_TRY(
      sph_step_leapfrog(sim, &m->ref, &m->lf, m->timer_integration, dt, err));
  /* a particle that crossed a plane in the step trades places with its
   * image at once; F then in the new reference (f = I to round-off), as an
   * output frame's derive would make it, which the next stable step reads */
  if (m->mirrored && sph_mirror_crossed(sim, &m->ref, m->x) > 0) {
    SPH_TRY(reference_update(m, err));
    SPH_TRY(deformation_and_stress(m, (long)sim->ps->n, err));
  }
  return SPH_OK;
}

static sph_status ul_csph_derive(sph_sim *sim, sph_error *err) {
  ul_csph *m = sim->method_data;
  SPH_TRY(deformation_and_stress(m, (long)sim->ps->n, err));
  return sph_step_leapfrog_derive(sim, &m->ref, &m->lf, m->dp, err);
}

static void ul_csph_energy(sph_sim *sim, double *kinetic, double *strain) {
  ul_csph *m = sim->method_data;
  sph_ref initial = m->ref; /* energy per initial volume */
  initial.V = m->V0;
  sph_ref_energy(sim, &initial, NULL, NULL, kinetic, strain);
}

static void ul_csph_destroy(sph_sim *sim) {
  ul_csph *m = sim->method_data;
  if (!m)
    return;
  sph_ref_destroy(&m->ref);
  free(m->V0);
  free(m->Fr);
  free(m->Jr);
  free(m->hv);
  free(m->gh);
  free(m->rev);
  free(m->sv);
  free(m->sgh);
  free(m->A);
  free(m->f0);
  free(m->S);
  free(m->dp);
  free(m->imgj);
  free(m->imgX);
  free(m->gj);
  free(m->placed);
  free(m);
  sim->method_data = NULL;
}

/* The options of the method block. */
typedef struct ul_csph_options {
  double cfl;
  int update_every;       /* steps between reference updates */
  double update_distance; /* or: the largest displacement, in spacings */
  double eta;             /* Hessian-difference stabilisation (sec. 3.4) */
} ul_csph_options;

static sph_status ul_csph_options_parse(sph_node *opt, ul_csph_options *o,
                                        sph_error *err) {
  static const char *const keys[] = {
      "name", "cfl", "integrator", "update_every", "update_distance",
      "eta",  NULL};
  SPH_TRY(sph_node_check_keys(opt, keys, err));
  SPH_TRY(sph_step_leapfrog_options(opt, &o->cfl, err));
  int by_steps = sph_node_child(opt, "update_every") != NULL;
  long every;
  SPH_TRY(sph_node_get_int(opt, "update_every", 0, 1, &every, err));
  if (every < 1 || every > 1000000000L)
    return sph_node_error(sph_node_child(opt, "update_every"), err,
                          SPH_ERR_RANGE,
                          "update_every must be a number of steps >= 1, got "
                          "%ld",
                          every);
  o->update_every = (int)every;
  SPH_TRY(sph_node_get_double(opt, "update_distance", 0, 0.0,
                              &o->update_distance, err));
  if (!(o->update_distance >= 0.0 && o->update_distance <= 1e6))
    return sph_node_error(
        sph_node_child(opt, "update_distance"), err, SPH_ERR_RANGE,
        "update_distance must be >= 0 spacings, got %g", o->update_distance);
  if (by_steps && o->update_distance > 0.0)
    return sph_node_error(sph_node_child(opt, "update_distance"), err,
                          SPH_ERR_RANGE,
                          "give update_every or update_distance, not both");
  SPH_TRY(sph_node_get_double(opt, "eta", 0, 0.3, &o->eta, err));
  if (!(o->eta >= 0.0 && o->eta <= 100.0))
    return sph_node_error(sph_node_child(opt, "eta"), err, SPH_ERR_RANGE,
                          "eta must be in [0, 100], got %g", o->eta);
  return SPH_OK;
}

static sph_status ul_csph_setup(sph_sim *sim, sph_node *opt, sph_error *err) {
  ul_csph_options o = {0};
  SPH_TRY(ul_csph_options_parse(opt, &o, err));
  ul_csph *m = calloc(1, sizeof *m);
  if (!m)
    return sph_error_set(err, SPH_ERR_NOMEM, "ul-csph");
  sim->method_data = m;
  m->sim = sim;
  m->cfl = o.cfl;
  m->update_every = o.update_every;
  m->update_distance = o.update_distance;
  m->eta = o.eta;
  const sph_scene *s = sim->scene;
  SPH_TRY(sph_ref_create(&m->ref, sim, 1, err));
  size_t ne = m->ref.n_ext;
  m->x = m->ref.x;
  m->p = m->ref.p;
  m->F = m->ref.F;
  m->P = m->ref.P;
  m->dp = calloc(3 * m->ref.cap + 3, sizeof *m->dp);
  m->V0 = malloc((m->ref.cap + 1) * sizeof *m->V0);
  SPH_TRY(sph_ref_alloc(&m->ref, 9, &m->Fr, err));
  SPH_TRY(sph_ref_alloc(&m->ref, 1, &m->Jr, err));
  SPH_TRY(sph_ref_alloc(&m->ref, 9, &m->S, err));
  SPH_TRY(sph_ref_alloc(&m->ref, 9, &m->f0, err));
  SPH_TRY(sph_ref_alloc(&m->ref, 3, &m->sv, err));
  SPH_TRY(sph_ref_alloc(&m->ref, 1, &m->sgh, err));
  SPH_TRY(sph_ref_alloc(&m->ref, 9, &m->A, err));
  /* h of Remark 2: the smoothing length along each axis of the body */
  for (int c = 0; c < s->dimension; ++c)
    m->h[c] = sim->kernel.h;
  if (!m->dp || !m->V0)
    return sph_error_set(err, SPH_ERR_NOMEM, "ul-csph state");
  memcpy(m->V0, m->ref.V, ne * sizeof *m->V0);
  /* the initial reference is X with F^r the initial F (I unless given) */
  memcpy(m->Fr, m->F, 9 * ne * sizeof *m->Fr);
  m->timer_force = sph_sim_add_timer(sim, "internal_force");
  m->timer_update = sph_sim_add_timer(sim, "reference_update");
  m->timer_integration = sph_sim_add_timer(sim, "time_integration");
  if (sim->initial_defgrad) /* the given deformed state is x^r */
    memcpy(m->ref.X, m->x, 3 * ne * sizeof *m->ref.X);
  /* over MPI ranks: what moves with a particle besides the set's fields */
  SPH_TRY(sph_domain_track(sim->domain, m->ref.X, 3, err));
  SPH_TRY(sph_domain_track(sim->domain, m->Fr, 9, err));
  SPH_TRY(sph_domain_track(sim->domain, m->V0, 1, err));
  m->mirrored = m->ref.n_img > m->ref.n || m->ref.all_images;
  SPH_TRY(ul_mirror_setup(m, err));
  SPH_TRY(rebuild(m, err));
  return sph_step_leapfrog_attach(sim, &m->ref, &m->lf, m->dp, ul_csph_rates,
                                  ul_csph_constrain, m, err);
}

static int ul_csph_state(sph_sim *sim, sph_state_array *out) {
  ul_csph *m = sim->method_data;
  size_t n = m->ref.n, ne = m->ref.n_ext;
  /* over MPI ranks: the owned points, also while a checkpoint is read
   * (the ghosts' come from their owners, the images' from their sources) */
  if (sim->domain)
    n = ne = sim->ps->n;
  out[0] = (sph_state_array){"x", m->x, 3 * n};
  out[1] = (sph_state_array){"p", m->p, 3 * n};
  out[2] = (sph_state_array){"F", m->F, 9 * n};
  /* the reference configuration, images included */
  out[3] = (sph_state_array){"Xr", m->ref.X, 3 * ne};
  out[4] = (sph_state_array){"Fr", m->Fr, 9 * ne};
  out[5] = (sph_state_array){"since_update", &m->since, 1};
  return 6;
}

static sph_status ul_csph_restore(sph_sim *sim, sph_error *err) {
  ul_csph *m = sim->method_data;
  double t0 = sph_wtime();
  sph_status st = rebuild(m, err);
  sim->timers[m->timer_update].seconds += sph_wtime() - t0;
  sim->timers[m->timer_update].calls++;
  if (st != SPH_OK)
    return st;
  return sph_step_leapfrog_restore(sim, &m->lf, err);
}

const sph_method_ops ul_csph_method_ops = {
    .name = "ul-csph",
    .title = "Stabilised updated-Lagrangian corrected SPH",
    .reference = "seed 001 (Vidal, Bonet, Huerta 2007) sec. 3-4, eq. 12-21",
    .conserves_angular_momentum = 1,
    .distributed = SPH_DISTRIBUTED_DYNAMIC,
    .fields = SPH_REF_OUTPUT_FIELDS,
    .setup = ul_csph_setup,
    .stable_dt = ul_csph_stable_dt,
    .step = ul_csph_step,
    .derive = ul_csph_derive,
    .energy = ul_csph_energy,
    .state = ul_csph_state,
    .restore = ul_csph_restore,
    .destroy = ul_csph_destroy,
};
