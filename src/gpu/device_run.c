/* A run's time step on the device (`device: cuda`, docs/gpu.md): the sim's
 * tl-jst state copied to the device at the first step, each step run there
 * and x, p, F copied back after it, so that everything the host computes
 * from the state (the stable time step from the current wave speed, the
 * verdict, outputs, energies, checkpoints) reads the step's result. With
 * SPH_DEVICE_TWIN=1 in the environment the host twin stands in for the
 * device (tests on machines without a GPU: its results are the CPU's to
 * the bit). */
#include <stdlib.h>
#include <string.h>

#include "gpu/gpu.h"
#include "solver/sim.h"

struct sph_device_run {
  sph_sim *sim;
  sph_gpu_tl_jst h; /* host twin: views and copies of the state */
  int stages;
  int twin;
  int started;
  sph_gpu_step *d;
  double *y[3]; /* the method's x, p, F */
};

int sph_device_twin(void) {
  const char *e = getenv("SPH_DEVICE_TWIN");
  return e && strcmp(e, "1") == 0;
}

sph_status sph_device_run_create(sph_sim *sim, sph_device_run **out,
                                 sph_error *err) {
  *out = NULL;
  sph_device_run *r = calloc(1, sizeof *r);
  if (!r)
    return sph_error_set(err, SPH_ERR_NOMEM, "device run");
  r->sim = sim;
  r->twin = sph_device_twin();
  sph_status st = sph_gpu_tl_jst_host_create(sim, &r->h, &r->stages, err);
  if (st != SPH_OK) {
    free(r);
    return st;
  }
  sph_state_array arr[SPH_MAX_STATE];
  int count = sim->method->state(sim, arr);
  static const char *const names[3] = {"x", "p", "F"};
  for (int i = 0; i < count; ++i)
    for (int f = 0; f < 3; ++f)
      if (strcmp(arr[i].name, names[f]) == 0)
        r->y[f] = arr[i].data;
  *out = r;
  return SPH_OK;
}

/* the state as the host holds it now (after set-up or a checkpoint) */
static sph_status start(sph_device_run *r, sph_error *err) {
  size_t n = r->h.n;
  memcpy(r->h.x, r->y[0], 3 * n * sizeof(double));
  memcpy(r->h.p, r->y[1], 3 * n * sizeof(double));
  memcpy(r->h.F, r->y[2], 9 * n * sizeof(double));
  r->started = 1;
  return r->twin ? SPH_OK : sph_gpu_tl_jst_create(&r->d, &r->h, r->stages, err);
}

sph_status sph_device_run_step(sph_device_run *r, double dt, sph_error *err) {
  if (!r->started)
    SPH_TRY(start(r, err));
  size_t n = r->h.n;
  if (!r->twin) {
    SPH_TRY(sph_gpu_tl_jst_advance(r->d, dt, 1, err));
    return sph_gpu_tl_jst_download(r->d, r->y[0], r->y[1], r->y[2], err);
  }
  sph_gpu_tl_jst_twin_step(&r->h, r->stages, dt);
  memcpy(r->y[0], r->h.x, 3 * n * sizeof(double));
  memcpy(r->y[1], r->h.p, 3 * n * sizeof(double));
  memcpy(r->y[2], r->h.F, 9 * n * sizeof(double));
  return SPH_OK;
}

void sph_device_run_destroy(sph_device_run *r) {
  if (!r)
    return;
  sph_gpu_tl_jst_destroy(r->d);
  sph_gpu_tl_jst_host_destroy(&r->h);
  free(r);
}
