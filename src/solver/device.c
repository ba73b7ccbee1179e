/* Device selection (docs/gpu.md): a scene's `device: cuda` is refused, at
 * its key and before anything is written, by a build without CUDA, on a
 * machine without a CUDA device, and for a method or term that has no GPU
 * path: a part is never run on the CPU in its stead. */
#include <stdio.h>
#include <string.h>

#include "gpu/gpu.h"
#include "scene/node.h"
#include "solver/device.h"

static sph_status refuse(const sph_scene *scene, sph_error *err,
                         const char *why) {
  if (scene->device_at)
    return sph_node_error(scene->device_at, err, SPH_ERR_UNSUPPORTED, "%s",
                          why);
  return sph_error_set(err, SPH_ERR_UNSUPPORTED, "%s", why);
}

sph_status sph_device_available(const sph_scene *scene, sph_error *err) {
  if (scene->device != SPH_DEVICE_CUDA)
    return SPH_OK;
  char why[256];
  if (sph_device_twin() || sph_gpu_probe(why, sizeof why) > 0)
    return SPH_OK;
  return refuse(scene, err, why);
}

sph_status sph_device_attach(sph_sim *sim, sph_error *err) {
  if (sim->scene->device != SPH_DEVICE_CUDA)
    return SPH_OK;
  char plan[2048];
  SPH_TRY(sph_device_plan(sim, plan, sizeof plan, err));
  sph_error e;
  sph_error_clear(&e);
  if (sph_device_run_create(sim, &sim->device, &e) == SPH_OK)
    return SPH_OK;
  /* the configuration the device step lacks, at the device key */
  char why[sizeof e.message + 64];
  snprintf(why, sizeof why, "%s: %s", sim->method->name, e.message);
  return refuse(sim->scene, err, why);
}

/* one line "  KIND NAME  WHERE" into buf at *used */
static void plan_line(char *buf, size_t size, size_t *used, const char *kind,
                      const char *name, int gpu, int cuda) {
  if (*used >= size)
    return;
  int k = snprintf(buf + *used, size - *used, "  %-6s %-30s %s\n", kind, name,
                   !cuda ? "CPU"
                   : gpu ? "GPU"
                         : "no GPU path: refused");
  if (k > 0)
    *used += (size_t)k;
}

sph_status sph_device_plan(const sph_sim *sim, char *buf, size_t size,
                           sph_error *err) {
  int cuda = sim->scene->device == SPH_DEVICE_CUDA;
  size_t used = 0;
  if (size)
    buf[0] = '\0';
  plan_line(buf, size, &used, "method", sim->method->name, sim->method->gpu,
            cuda);
  for (int i = 0; i < sim->nterms; ++i)
    plan_line(buf, size, &used, "term", sim->terms[i].ops->name,
              sim->terms[i].ops->gpu, cuda);
  if (!cuda)
    return SPH_OK;
  char why[256];
  if (!sim->method->gpu) {
    snprintf(why, sizeof why,
             "method %s has no GPU path in sph run (docs/gpu.md says what "
             "runs on the device)",
             sim->method->name);
    return refuse(sim->scene, err, why);
  }
  for (int i = 0; i < sim->nterms; ++i)
    if (!sim->terms[i].ops->gpu) {
      snprintf(why, sizeof why, "term %s of method %s has no GPU path",
               sim->terms[i].ops->name, sim->method->name);
      return refuse(sim->scene, err, why);
    }
  return SPH_OK;
}
