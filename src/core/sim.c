/* The simulation object and its time step: particles from the scene, the
 * method from the registry, the terms the method created (DESIGN.md sec. 2,
 * 4). The loop calls method->stable_dt and method->step once per step. */
#include "sph/sim.h"

#include "sph/reference.h"
#include "sph/tensor.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

double sph_wtime(void) { return omp_get_wtime(); }

sph_status sph_sim_create(sph_sim **out, const sph_scene *scene,
                          sph_error *err) {
  *out = NULL;
  sph_node *name_node = sph_node_child(scene->method, "name");
  const sph_method_ops *method = sph_method_find(scene->method_name);
  if (!method) {
    const char *names[16];
    size_t k = 0;
    for (const sph_method_ops *const *m = sph_method_list(); *m && k < 15; ++m)
      names[k++] = (*m)->name;
    names[k] = NULL;
    const char *hint = sph_suggest(scene->method_name, names);
    char known[256] = "";
    for (size_t i = 0; i < k; ++i) {
      strncat(known, i ? ", " : "", sizeof known - strlen(known) - 1);
      strncat(known, names[i], sizeof known - strlen(known) - 1);
    }
    if (hint)
      return sph_node_error(
          name_node ? name_node : scene->method, err, SPH_ERR_ARG,
          "unknown method '%s'; did you mean '%s'?", scene->method_name, hint);
    return sph_node_error(name_node ? name_node : scene->method, err,
                          SPH_ERR_ARG, "unknown method '%s' (known: %s)",
                          scene->method_name, known);
  }
  sph_sim *sim = calloc(1, sizeof *sim);
  if (!sim)
    return sph_error_set(err, SPH_ERR_NOMEM, "simulation");
  sim->scene = scene;
  sim->method = method;
  sim->threads = omp_get_max_threads();
  sim->dt_min = INFINITY;
  sph_status st = sph_scene_build_particles(scene, &sim->ps, err);
  if (st == SPH_OK) {
    sim->dp = sph_scene_min_spacing(scene);
    st = sph_kernel_create(&sim->kernel, scene->kernel_type, scene->dimension,
                           scene->h_over_dp * sim->dp, err);
  }
  /* neighbours near in memory: cells of one kernel support in Morton order */
  if (st == SPH_OK)
    st = sph_particles_sort_morton(sim->ps, sim->kernel.support, err);
  if (st == SPH_OK)
    st = sph_reference_create(&sim->reference, scene, err);
  if (st == SPH_OK && sim->reference)
    st = sph_reference_initialise(sim->reference, sim, err);
  if (st == SPH_OK)
    st = method->setup(sim, scene->method, err);
  /* the time step rule (a wave speed per particle) is work of every step */
  if (st == SPH_OK)
    sim->timer_stable_dt = sph_sim_add_timer(sim, "stable_dt");
  if (st != SPH_OK) {
    sph_sim_destroy(sim);
    return st;
  }
  *out = sim;
  return SPH_OK;
}

void sph_sim_destroy(sph_sim *sim) {
  if (!sim)
    return;
  for (int i = 0; i < sim->nterms; ++i)
    if (sim->terms[i].ops->destroy)
      sim->terms[i].ops->destroy(&sim->terms[i]);
  if (sim->method && sim->method->destroy)
    sim->method->destroy(sim);
  sph_particles_destroy(sim->ps);
  sph_reference_destroy(sim->reference);
  free(sim);
}

sph_status sph_sim_step(sph_sim *sim, double dt_cap, sph_error *err) {
  double t0 = sph_wtime();
  double dt = sim->method->stable_dt(sim);
  sim->timers[sim->timer_stable_dt].seconds += sph_wtime() - t0;
  sim->timers[sim->timer_stable_dt].calls++;
  if (!(dt > 0.0) || !isfinite(dt))
    return sph_error_set(err, SPH_ERR_NUMERIC,
                         "stable time step %g at t = %g is not positive", dt,
                         sim->t);
  if (dt > dt_cap)
    dt = dt_cap;
  sph_status st = sim->method->step(sim, dt, err);
  if (st != SPH_OK)
    return st;
  sim->t += dt;
  sim->steps++;
  sim->dt_last = dt;
  sim->dt_min = dt < sim->dt_min ? dt : sim->dt_min;
  sim->dt_max = dt > sim->dt_max ? dt : sim->dt_max;
  return SPH_OK;
}

sph_status sph_sim_add_term(sph_sim *sim, const sph_term_ops *ops, void *data,
                            sph_error *err) {
  if (sim->nterms >= SPH_MAX_TERMS)
    return sph_error_set(err, SPH_ERR_ARG, "more than %d terms", SPH_MAX_TERMS);
  sph_term *t = &sim->terms[sim->nterms++];
  memset(t, 0, sizeof *t);
  t->ops = ops;
  t->data = data;
  return SPH_OK;
}

int sph_sim_add_timer(sph_sim *sim, const char *name) {
  if (sim->ntimers >= SPH_MAX_TIMERS)
    return SPH_MAX_TIMERS - 1;
  sim->timers[sim->ntimers].name = name;
  return sim->ntimers++;
}

sph_status sph_sim_terms_rates(sph_sim *sim, sph_stage *stage, sph_error *err) {
  for (int i = 0; i < sim->nterms; ++i) {
    sph_term *t = &sim->terms[i];
    if (!t->ops->rates)
      continue;
    double t0 = sph_wtime();
    sph_status st = t->ops->rates(t, sim, stage, err);
    t->seconds += sph_wtime() - t0;
    t->calls++;
    if (st != SPH_OK)
      return st;
  }
  return SPH_OK;
}

sph_status sph_sim_terms_constrain(sph_sim *sim, sph_stage *state,
                                   sph_error *err) {
  for (int i = 0; i < sim->nterms; ++i) {
    sph_term *t = &sim->terms[i];
    if (!t->ops->constrain)
      continue;
    double t0 = sph_wtime();
    sph_status st = t->ops->constrain(t, sim, state, err);
    t->seconds += sph_wtime() - t0;
    t->calls++;
    if (st != SPH_OK)
      return st;
  }
  return SPH_OK;
}

void sph_momentum(const sph_particles *ps, double lin[3], double ang[3]) {
  const double *m = ps->field[SPH_FIELD_MASS];
  const double *v = ps->field[SPH_FIELD_VELOCITY];
  const double *x = ps->field[SPH_FIELD_POSITION]
                        ? ps->field[SPH_FIELD_POSITION]
                        : ps->field[SPH_FIELD_POSITION0];
  for (int c = 0; c < 3; ++c)
    lin[c] = ang[c] = 0.0;
  if (!m || !v)
    return;
  for (size_t a = 0; a < ps->n; ++a) {
    double mv[3] = {m[a] * v[3 * a], m[a] * v[3 * a + 1], m[a] * v[3 * a + 2]};
    double t[3];
    sph_vec3_cross(x + 3 * a, mv, t);
    for (int c = 0; c < 3; ++c) {
      lin[c] += mv[c];
      ang[c] += t[c];
    }
  }
}

void sph_mirror_vector(const sph_mirror *m, double *v) {
  long ng = (long)m->n_ghost;
  if (m->vmat) {
#pragma omp parallel for schedule(static)
    for (long g = 0; g < ng; ++g) {
      size_t s = (size_t)m->src[g], d = m->n_real + (size_t)g;
      const double *M = m->vmat + 9 * g;
      for (int c = 0; c < 3; ++c)
        v[3 * d + c] = M[3 * c] * v[3 * s] + M[3 * c + 1] * v[3 * s + 1] +
                       M[3 * c + 2] * v[3 * s + 2];
    }
    return;
  }
#pragma omp parallel for schedule(static)
  for (long g = 0; g < ng; ++g) {
    size_t s = (size_t)m->src[g], d = m->n_real + (size_t)g;
    for (int c = 0; c < 3; ++c)
      v[3 * d + c] = m->vsign[3 * g + c] * v[3 * s + c];
  }
}

void sph_mirror_scalar(const sph_mirror *m, double *f, double ref) {
  long ng = (long)m->n_ghost;
#pragma omp parallel for schedule(static)
  for (long g = 0; g < ng; ++g)
    f[m->n_real + (size_t)g] = ref + m->ssign[g] * (f[(size_t)m->src[g]] - ref);
}
