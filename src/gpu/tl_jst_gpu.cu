/* The device driver of the tl-jst pF step (docs/gpu.md): the arrays of a
 * host twin (tl_jst_twin.c) copied to the device once, then each stage as
 * three kernels of one thread per particle, each calling the per-particle
 * function of tl_jst_gpu_one.h that the twin calls in a loop: the stress
 * (Q = P L), the rates (a gather over the particle's neighbour slots in
 * their fixed order: no atomics), with the JST term a second gather over
 * the neighbours' L[p], the momentum projections (per-body sums over the
 * CPU's 64 blocks, one thread each, added in block order by one thread: the
 * CPU's order), and the Runge-Kutta combination with the clamp. Built
 * with --fmad=false, so that products and sums round as the CPU's do; only pow
 * in the stress may differ by an ulp from glibc's. */
#include <cuda_runtime.h>
#include <stdlib.h>
#include <string.h>

extern "C" {
#include "sph/status.h"
}
#include "gpu/gpu.h"

struct sph_gpu_step {
  sph_gpu_tl_jst d; /* device pointers */
  int stages;
  size_t bytes;
  void *blocks[32];
  int nblocks;
};

#define THREADS 128

/* NAME_kernel: one thread per particle calling sph_gpu_NAME_one */
#define PER_PARTICLE_KERNEL(NAME)                                              \
  __global__ void NAME##_kernel(sph_gpu_tl_jst g) {                            \
    size_t a = (size_t)blockIdx.x * blockDim.x + threadIdx.x;                  \
    if (a < g.n)                                                               \
      sph_gpu_##NAME##_one(a, &g);                                             \
  }
PER_PARTICLE_KERNEL(save)
PER_PARTICLE_KERNEL(stress)
PER_PARTICLE_KERNEL(rates)
PER_PARTICLE_KERNEL(jst)
PER_PARTICLE_KERNEL(finish)

__global__ void xmoment_kernel(sph_gpu_tl_jst g, double dt) {
  size_t a = (size_t)blockIdx.x * blockDim.x + threadIdx.x;
  if (a < g.n)
    sph_gpu_xmoment_one(a, &g, dt);
}

/* one thread per block of the projection's sums: the CPU's blocks, each
 * summed in particle order, then added in block order by one thread */
__global__ void proj_block_kernel(sph_gpu_tl_jst g, const double *X,
                                  const double *w, int b, int second) {
  int k = (int)threadIdx.x;
  if (k < SPH_PROJ_BLOCKS)
    sph_gpu_proj_block_one(k, &g, X, w, b, second);
}

__global__ void proj_finish_kernel(sph_gpu_tl_jst g, int second) {
  sph_gpu_proj_finish(&g, second);
}

__global__ void proj_apply_kernel(sph_gpu_tl_jst g, const double *X, double *w,
                                  int b) {
  size_t a = (size_t)blockIdx.x * blockDim.x + threadIdx.x;
  if (a < g.n)
    sph_gpu_proj_apply_one(a, &g, X, w, b);
}

__global__ void combine_kernel(sph_gpu_tl_jst g, double ca, double cb,
                               double dt) {
  size_t a = (size_t)blockIdx.x * blockDim.x + threadIdx.x;
  if (a < g.n)
    sph_gpu_combine_one(a, &g, ca, cb, dt);
}

static sph_status cuda_error(sph_error *err, cudaError_t e, const char *what) {
  return sph_error_set(err, SPH_ERR_IO, "CUDA: %s: %s", what,
                       cudaGetErrorString(e));
}

/* a device copy of count elements of size bytes from host (or zeroed) */
static sph_status upload(sph_gpu_step *s, const void *host, size_t count,
                         size_t size, void **out, sph_error *err) {
  size_t bytes = (count ? count : 1) * size;
  void *d = NULL;
  cudaError_t e = cudaMalloc(&d, bytes);
  if (e != cudaSuccess)
    return cuda_error(err, e, "cudaMalloc");
  s->blocks[s->nblocks++] = d;
  s->bytes += bytes;
  e = host ? cudaMemcpy(d, host, count * size, cudaMemcpyHostToDevice)
           : cudaMemset(d, 0, bytes);
  if (e != cudaSuccess)
    return cuda_error(err, e, "copy to the device");
  *out = d;
  return SPH_OK;
}

#define UP(field, count, type)                                                 \
  do {                                                                         \
    void *p_;                                                                  \
    SPH_TRY(upload(s, h->field, count, sizeof(type), &p_, err));               \
    d->field = (type *)p_;                                                     \
  } while (0)

static sph_status create_arrays(sph_gpu_step *s, const sph_gpu_tl_jst *h,
                                sph_error *err) {
  sph_gpu_tl_jst *d = &s->d;
  size_t n = h->n, slots = h->offset[n];
  d->n = n;
  UP(offset, n + 1, size_t);
  UP(index, slots, int32_t);
  UP(w, slots, double);
  UP(X, 3 * n, double);
  UP(L, 9 * n, double);
  UP(s, 3 * n, double);
  UP(rho0, n, double);
  UP(mu, n, double);
  UP(kappa, n, double);
  UP(fixed, n, unsigned char);
  UP(x, 3 * n, double);
  UP(p, 3 * n, double);
  UP(F, 9 * n, double);
  UP(x0, 3 * n, double);
  UP(p0, 3 * n, double);
  UP(F0, 9 * n, double);
  UP(dx, 3 * n, double);
  UP(dp, 3 * n, double);
  UP(dF, 9 * n, double);
  UP(Qt, 9 * n, double);
  d->lap = NULL;
  d->lu = NULL;
  d->c2 = h->c2;
  d->c4 = h->c4;
  if (h->lu) { /* the JST term */
    UP(lap, slots, double);
    UP(lu, 3 * n, double);
  }
  d->d = NULL;
  if (h->d)
    UP(d, 3 * n, double);
  d->amp = h->amp;
  d->xmom = h->xmom;
  d->nbodies = h->nbodies;
  UP(V, n, double);
  UP(body, n, int32_t);
  UP(xm, 3 * n, double);
  UP(part, 12 * SPH_PROJ_BLOCKS, double);
  UP(coef, SPH_GPU_COEF, double);
  return SPH_OK;
}

extern "C" sph_status sph_gpu_tl_jst_create(sph_gpu_step **out,
                                            const sph_gpu_tl_jst *h, int stages,
                                            sph_error *err) {
  *out = NULL;
  sph_gpu_step *s = (sph_gpu_step *)calloc(1, sizeof *s);
  if (!s)
    return sph_error_set(err, SPH_ERR_NOMEM, "device step");
  s->stages = stages;
  sph_status st = create_arrays(s, h, err);
  if (st != SPH_OK) {
    sph_gpu_tl_jst_destroy(s);
    return st;
  }
  *out = s;
  return SPH_OK;
}

/* the projection of w about X, body by body (sph_momentum_projection) */
static void project(const sph_gpu_tl_jst &g, unsigned blocks, const double *X,
                    double *w) {
  for (int b = 0; b < g.nbodies; ++b)
    for (int second = 0; second < 2; ++second) {
      proj_block_kernel<<<1, SPH_PROJ_BLOCKS>>>(g, X, w, b, second);
      proj_finish_kernel<<<1, 1>>>(g, second);
      if (second)
        proj_apply_kernel<<<blocks, THREADS>>>(g, X, w, b);
    }
}

extern "C" sph_status sph_gpu_tl_jst_advance(sph_gpu_step *s, double dt,
                                             long steps, sph_error *err) {
  const sph_gpu_tl_jst g = s->d;
  unsigned blocks = (unsigned)((g.n + THREADS - 1) / THREADS);
  for (long i = 0; i < steps; ++i) {
    save_kernel<<<blocks, THREADS>>>(g);
    for (int k = 0; k < s->stages; ++k) {
      double ca, cb;
      sph_gpu_rk_coefficients(s->stages, k, &ca, &cb);
      stress_kernel<<<blocks, THREADS>>>(g);
      rates_kernel<<<blocks, THREADS>>>(g);
      const double *X = g.x;
      if (g.xmom && k > 0 && (g.amp || g.d)) {
        xmoment_kernel<<<blocks, THREADS>>>(g, dt);
        X = g.xm;
      }
      if (g.amp)
        project(g, blocks, X, g.dp);
      if (g.lu)
        jst_kernel<<<blocks, THREADS>>>(g);
      if (g.d)
        project(g, blocks, X, g.d);
      if (g.amp || g.lu)
        finish_kernel<<<blocks, THREADS>>>(g);
      combine_kernel<<<blocks, THREADS>>>(g, ca, cb, dt);
    }
  }
  cudaError_t e = cudaGetLastError();
  if (e == cudaSuccess)
    e = cudaDeviceSynchronize();
  return e == cudaSuccess ? SPH_OK : cuda_error(err, e, "the step's kernels");
}

extern "C" sph_status sph_gpu_tl_jst_download(sph_gpu_step *s, double *x,
                                              double *p, double *F,
                                              sph_error *err) {
  size_t n = s->d.n;
  cudaError_t e =
      cudaMemcpy(x, s->d.x, 3 * n * sizeof(double), cudaMemcpyDeviceToHost);
  if (e == cudaSuccess)
    e = cudaMemcpy(p, s->d.p, 3 * n * sizeof(double), cudaMemcpyDeviceToHost);
  if (e == cudaSuccess)
    e = cudaMemcpy(F, s->d.F, 9 * n * sizeof(double), cudaMemcpyDeviceToHost);
  return e == cudaSuccess ? SPH_OK : cuda_error(err, e, "copy to the host");
}

extern "C" size_t sph_gpu_tl_jst_bytes(const sph_gpu_step *s) {
  return s ? s->bytes : 0;
}

extern "C" void sph_gpu_tl_jst_destroy(sph_gpu_step *s) {
  if (!s)
    return;
  for (int i = 0; i < s->nblocks; ++i)
    cudaFree(s->blocks[i]);
  free(s);
}
