/* The host twin of the device step (docs/gpu.md): tl-jst pF over plain
 * arrays by the per-particle functions of tl_jst_gpu_one.h in plain loops,
 * the same functions the CUDA kernels (tl_jst_gpu.cu) call for their
 * thread's index. Set up from a tl-jst sim, whose reference arrays it
 * views and whose state it copies; what the device step lacks is refused
 * here, naming the part. */
#include <stdlib.h>
#include <string.h>

#include "gpu/gpu.h"
#include "materials/material_impl.h"
#include "methods/tl_jst/tl_jst_impl.h"
#include "scene/node.h"
#include "scene/scene.h"
#include "solver/sim.h"

/* the parts of a tl-jst sim the device step does not have, or NULL */
static const char *unsupported(const sph_sim *sim, const tl_jst *m) {
  if (strcmp(sim->method->name, "tl-jst") != 0)
    return "the method (only tl-jst has a device step)";
  if (m->fields != TL_JST_PF)
    return "tl-jst fields pFJ and pFHJ (only pF)";
  if (m->force != TL_JST_CONSERVATIVE)
    return "tl-jst force other than conservative";
  if (m->ref.n_ext != m->ref.n || sim->domain)
    return "mirror images and MPI ranks";
  for (size_t a = 0; a < m->ref.n; ++a)
    if (m->ref.mat[a]->ops != &sph_neo_hookean_ops)
      return "materials other than neo-hookean";
  for (int i = 0; i < sim->nterms; ++i) {
    const char *name = sim->terms[i].ops->name;
    if (strcmp(name, "essential_bc") != 0 &&
        strcmp(name, "jst_dissipation_p") != 0 &&
        strcmp(name, "angular_momentum_projection") != 0)
      return name;
  }
  for (size_t k = 0; k < sim->scene->nboundaries; ++k)
    if (sim->scene->boundaries[k].kind != SPH_BC_CLAMP)
      return "boundaries other than clamp";
  return NULL;
}

static void *host_alloc(size_t count, size_t size, int *ok) {
  void *p = calloc(count ? count : 1, size);
  *ok &= p != NULL;
  return p;
}

/* bit c of fixed[a]: the clamp zeroes dp_c of particle a (the boundary
 * term's rates on a rate of ones) */
static sph_status clamp_mask(sph_sim *sim, const tl_jst *m,
                             unsigned char *fixed, double *ones,
                             sph_error *err) {
  size_t n = m->ref.n;
  for (size_t i = 0; i < 3 * n; ++i)
    ones[i] = 1.0;
  sph_stage s = {.t = sim->t,
                 .x = m->x,
                 .x_moment = m->x,
                 .p = m->p,
                 .F = m->F,
                 .dp = ones};
  /* the boundary term alone: the projections would move the ones too */
  for (int i = 0; i < sim->nterms; ++i)
    if (strcmp(sim->terms[i].ops->name, "essential_bc") == 0)
      SPH_TRY(sim->terms[i].ops->rates(&sim->terms[i], sim, &s, err));
  for (size_t a = 0; a < n; ++a) {
    fixed[a] = 0;
    for (int c = 0; c < 3; ++c)
      if (ones[3 * a + c] == 0.0)
        fixed[a] |= (unsigned char)(1u << c);
  }
  return SPH_OK;
}

sph_status sph_gpu_tl_jst_host_create(sph_sim *sim, sph_gpu_tl_jst *g,
                                      int *stages, sph_error *err) {
  memset(g, 0, sizeof *g);
  const tl_jst *m = sim->method_data;
  const char *why = unsupported(sim, m);
  if (why)
    return sph_error_set(err, SPH_ERR_UNSUPPORTED, "no device step for %s",
                         why);
  size_t n = m->ref.n, slots = m->ref.nl->offset[n];
  *stages = m->integrate == sph_ssp_rk3_step ? 3 : 2;
  g->n = n;
  g->offset = m->ref.nl->offset;
  g->index = m->ref.nl->index;
  g->w = m->ref.w;
  g->X = m->ref.X;
  g->L = m->ref.L;
  g->s = m->ref.s;
  g->rho0 = m->ref.rho0;
  (void)slots;
  int ok = 1;
  double *mu = host_alloc(n, sizeof *mu, &ok);
  double *kappa = host_alloc(n, sizeof *kappa, &ok);
  unsigned char *fixed = host_alloc(n, 1, &ok);
  g->x = host_alloc(3 * n, sizeof(double), &ok);
  g->p = host_alloc(3 * n, sizeof(double), &ok);
  g->F = host_alloc(9 * n, sizeof(double), &ok);
  g->x0 = host_alloc(3 * n, sizeof(double), &ok);
  g->p0 = host_alloc(3 * n, sizeof(double), &ok);
  g->F0 = host_alloc(9 * n, sizeof(double), &ok);
  g->dx = host_alloc(3 * n, sizeof(double), &ok);
  g->dp = host_alloc(3 * n, sizeof(double), &ok);
  g->dF = host_alloc(9 * n, sizeof(double), &ok);
  g->Qt = host_alloc(9 * n, sizeof(double), &ok);
  g->mu = mu;
  g->kappa = kappa;
  g->fixed = fixed;
  if (!ok) {
    sph_gpu_tl_jst_host_destroy(g);
    return sph_error_set(err, SPH_ERR_NOMEM, "device step host arrays");
  }
  for (size_t a = 0; a < n; ++a) {
    mu[a] = m->ref.mat[a]->mu;
    kappa[a] = m->ref.mat[a]->kappa;
  }
  memcpy(g->x, m->x, 3 * n * sizeof(double));
  memcpy(g->p, m->p, 3 * n * sizeof(double));
  memcpy(g->F, m->F, 9 * n * sizeof(double));
  for (int i = 0; i < sim->nterms; ++i)
    g->amp |=
        strcmp(sim->terms[i].ops->name, "angular_momentum_projection") == 0;
  g->xmom = *stages == 2;
  g->V = sim->ps->field[SPH_FIELD_VOLUME0];
  g->body = sim->ps->body;
  g->nbodies = (int)sim->scene->nbodies;
  g->xm = host_alloc(3 * n, sizeof(double), &ok);
  g->part = host_alloc(12 * SPH_PROJ_BLOCKS, sizeof(double), &ok);
  g->coef = host_alloc(SPH_GPU_COEF, sizeof(double), &ok);
  if (m->lu_p) { /* the JST term on p (tl_jst.c's setup_terms) */
    double e2 = 0.0, e4 = 0.0;
    sph_node *jst = sph_node_child(sim->scene->method, "jst");
    sph_node_get_double(jst, "eps2_p", 0, 0.0, &e2, err);
    sph_node_get_double(jst, "eps4_p", 0, 0.125, &e4, err);
    double cp = m->ref.cp, h = sim->dp;
    g->c2 = e2 * cp * h;
    g->c4 = e4 * cp * h * h * h;
    g->lap = m->lap;
    g->lu = host_alloc(3 * n, sizeof(double), &ok);
    int proj = 1;
    if (sph_node_child(sim->scene->method, "jst_projection"))
      sph_node_get_bool(sim->scene->method, "jst_projection", 0, 1, &proj, err);
    if (proj)
      g->d = host_alloc(3 * n, sizeof(double), &ok);
    if (!ok) {
      sph_gpu_tl_jst_host_destroy(g);
      return sph_error_set(err, SPH_ERR_NOMEM, "device step host arrays");
    }
  }
  sph_status st = clamp_mask(sim, m, fixed, g->dp, err);
  if (st != SPH_OK)
    sph_gpu_tl_jst_host_destroy(g);
  return st;
}

void sph_gpu_tl_jst_host_destroy(sph_gpu_tl_jst *g) {
  free((void *)g->mu);
  free((void *)g->kappa);
  free((void *)g->fixed);
  double *own[] = {g->x,  g->p,  g->F,  g->x0, g->p0, g->F0,   g->dx,  g->dp,
                   g->dF, g->Qt, g->lu, g->d,  g->xm, g->part, g->coef};
  for (size_t i = 0; i < sizeof own / sizeof *own; ++i)
    free(own[i]);
  memset(g, 0, sizeof *g);
}

/* the projection of w about X, body by body (sph_momentum_projection) */
static void project(const sph_gpu_tl_jst *g, const double *X, double *w) {
  for (int b = 0; b < g->nbodies; ++b)
    for (int second = 0; second < 2; ++second) {
      for (int k = 0; k < SPH_PROJ_BLOCKS; ++k)
        sph_gpu_proj_block_one(k, g, X, w, b, second);
      sph_gpu_proj_finish(g, second);
      if (second)
        for (size_t a = 0; a < g->n; ++a)
          sph_gpu_proj_apply_one(a, g, X, w, b);
    }
}

void sph_gpu_tl_jst_twin_step(const sph_gpu_tl_jst *g, int stages, double dt) {
  size_t n = g->n;
  for (size_t a = 0; a < n; ++a)
    sph_gpu_save_one(a, g);
  for (int k = 0; k < stages; ++k) {
    double ca, cb;
    sph_gpu_rk_coefficients(stages, k, &ca, &cb);
    for (size_t a = 0; a < n; ++a)
      sph_gpu_stress_one(a, g);
    for (size_t a = 0; a < n; ++a)
      sph_gpu_rates_one(a, g);
    const double *X = g->x;
    if (g->xmom && k > 0 && (g->amp || g->d)) {
      for (size_t a = 0; a < n; ++a)
        sph_gpu_xmoment_one(a, g, dt);
      X = g->xm;
    }
    if (g->amp)
      project(g, X, g->dp);
    if (g->lu)
      for (size_t a = 0; a < n; ++a)
        sph_gpu_jst_one(a, g);
    if (g->d)
      project(g, X, g->d);
    if (g->amp || g->lu)
      for (size_t a = 0; a < n; ++a)
        sph_gpu_finish_one(a, g);
    for (size_t a = 0; a < n; ++a)
      sph_gpu_combine_one(a, g, ca, cb, dt);
  }
}
