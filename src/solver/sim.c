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
