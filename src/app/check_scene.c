/* The validation of sph check, shared with sph run and the scene loader's
 * fuzz target (tests/fuzz): scene, overrides, memory estimate, particles,
 * method, png block; nothing printed, nothing simulated. */
#include "app/app_impl.h"
#include "render/render.h"
#include "scene/scene.h"
#include "solver/sim.h"

sph_status sph_app_check_scene(const char *path, const char *const *sets,
                               size_t nsets, double max_memory,
                               sph_scene **scene, sph_sim **sim,
                               sph_error *err) {
  *scene = NULL;
  *sim = NULL;
  sph_status st = sph_scene_load(scene, path, sets, nsets, err);
  if (st == SPH_OK) {
    (*scene)->memory_limit = max_memory;
    st = sph_sim_create(sim, *scene, err);
  }
  if (st == SPH_OK)
    st = sph_png_check(*sim, err);
  if (st == SPH_OK)
    return SPH_OK;
  sph_sim_destroy(*sim);
  *sim = NULL;
  sph_scene_destroy(*scene);
  *scene = NULL;
  return st;
}
