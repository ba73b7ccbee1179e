/* The device step (docs/gpu.md): whether this build and this machine can run
 * on a CUDA GPU, the host twin of the tl-jst pF step (tl_jst_twin.c, every
 * build) and its device driver (tl_jst_gpu.cu, CUDA builds): the same
 * per-particle functions (tl_jst_gpu_one.h) over host or device arrays. */
#ifndef SPH_GPU_H
#define SPH_GPU_H

#include <stddef.h>

#include "gpu/tl_jst_gpu_one.h"
#include "sph/status.h"

#ifdef __cplusplus
extern "C" {
#endif

struct sph_sim;

/* 1 in a build with CUDA (SPH_CUDA), else 0. */
int sph_gpu_compiled(void);

/* The CUDA devices of this machine (0: none, no driver or a build without
 * CUDA, `why` then says which); with one, `why` names device 0. */
int sph_gpu_probe(char *why, size_t size);

/* ---- the host twin (tl_jst_twin.c) ---- */

/* Host copies of a tl-jst sim's state and views of its reference arrays in
 * g, with the integrator's stage count; refuses (SPH_ERR_ARG, the message
 * naming the part) what the device step does not have: fields other than
 * pF, forces other than the conservative one, mirror images, MPI ranks,
 * materials other than neo-Hookean, terms other than clamped particles. */
sph_status sph_gpu_tl_jst_host_create(struct sph_sim *sim, sph_gpu_tl_jst *g,
                                      int *stages, sph_error *err);
void sph_gpu_tl_jst_host_destroy(sph_gpu_tl_jst *g);

/* One time step of dt by the per-particle functions in plain loops. */
void sph_gpu_tl_jst_twin_step(const sph_gpu_tl_jst *g, int stages, double dt);

/* ---- the device step (tl_jst_gpu.cu; fails in a build without CUDA) ---- */

typedef struct sph_gpu_step sph_gpu_step;

/* Copies the arrays of a host twin (sph_gpu_tl_jst_host_create) to the
 * device once: reference configuration, neighbour lists, state. */
sph_status sph_gpu_tl_jst_create(sph_gpu_step **out, const sph_gpu_tl_jst *h,
                                 int stages, sph_error *err);
/* `steps` time steps of dt on the device, nothing copied. */
sph_status sph_gpu_tl_jst_advance(sph_gpu_step *s, double dt, long steps,
                                  sph_error *err);
/* The state x, p, F (3n, 3n, 9n) copied back to the host. */
sph_status sph_gpu_tl_jst_download(sph_gpu_step *s, double *x, double *p,
                                   double *F, sph_error *err);
/* Bytes of device memory the step holds. */
size_t sph_gpu_tl_jst_bytes(const sph_gpu_step *s);
void sph_gpu_tl_jst_destroy(sph_gpu_step *s);

/* ---- a run's step on the device (device_run.c) ---- */

typedef struct sph_device_run sph_device_run;

/* 1 when SPH_DEVICE_TWIN=1: the host twin stands in for the device (tests
 * on machines without a GPU). */
int sph_device_twin(void);

/* The device step for sim (refused as sph_gpu_tl_jst_host_create refuses);
 * the device is set up at the first step, from the state the host holds
 * then (after a checkpoint's). */
sph_status sph_device_run_create(struct sph_sim *sim, sph_device_run **out,
                                 sph_error *err);
/* One step of dt on the device, x, p and F copied back to the method's
 * arrays. */
sph_status sph_device_run_step(sph_device_run *r, double dt, sph_error *err);
void sph_device_run_destroy(sph_device_run *r);

#ifdef __cplusplus
}
#endif

#endif
