/* Where a run's time step runs (docs/gpu.md): the scene's `device` (or
 * `--device`), checked before anything is written. */
#ifndef SPH_DEVICE_H
#define SPH_DEVICE_H

#include <stddef.h>

#include "scene/scene.h"
#include "solver/sim.h"

/* A scene with `device: cuda` needs a build with CUDA and a CUDA device on
 * this machine: else SPH_ERR_UNSUPPORTED at the scene's device key, saying
 * which is missing. SPH_OK for a CPU scene. */
sph_status sph_device_available(const sph_scene *scene, sph_error *err);

/* Where each part of sim (the method, every term) runs under its scene's
 * device, one line each into buf ("  tl-jst    GPU"); SPH_OK when every
 * part has a path there, else SPH_ERR_UNSUPPORTED at the device key naming
 * the first that has none (never run on the CPU instead). */
sph_status sph_device_plan(const sph_sim *sim, char *buf, size_t size,
                           sph_error *err);

/* With `device: cuda`: sph_device_plan, then the method's device step set
 * up in sim->device (its configuration refused at the device key, e.g.
 * "tl-jst: no device step for tl-jst fields pFJ and pFHJ (only pF)").
 * Nothing for a CPU scene. */
sph_status sph_device_attach(sph_sim *sim, sph_error *err);

#endif
