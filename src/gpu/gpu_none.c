/* The device entry points of a build without CUDA (SPH_CUDA=OFF or no nvcc
 * at build time): no device, and every device call refused. */
#include <stdio.h>

#include "gpu/gpu.h"

int sph_gpu_compiled(void) { return 0; }

int sph_gpu_probe(char *why, size_t size) {
  snprintf(why, size,
           "this sph was built without CUDA (SPH_CUDA=OFF, or no nvcc when "
           "it was configured; docs/gpu.md)");
  return 0;
}

sph_status sph_gpu_tl_jst_create(sph_gpu_step **out, const sph_gpu_tl_jst *h,
                                 int stages, sph_error *err) {
  *out = NULL;
  return sph_error_set(err, SPH_ERR_ARG, "this sph was built without CUDA");
}

sph_status sph_gpu_tl_jst_advance(sph_gpu_step *s, double dt, long steps,
                                  sph_error *err) {
  return sph_error_set(err, SPH_ERR_ARG, "this sph was built without CUDA");
}

sph_status sph_gpu_tl_jst_download(sph_gpu_step *s, double *x, double *p,
                                   double *F, sph_error *err) {
  return sph_error_set(err, SPH_ERR_ARG, "this sph was built without CUDA");
}

size_t sph_gpu_tl_jst_bytes(const sph_gpu_step *s) { return 0; }

void sph_gpu_tl_jst_destroy(sph_gpu_step *s) {}
