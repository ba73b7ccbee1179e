/* Whether this machine has a CUDA device (a CUDA build): the runtime is
 * linked statically and opens the driver library at run time, so a machine
 * without a driver or a GPU gets a reason, not a loader error. */
#include <cuda_runtime.h>
#include <stdio.h>

extern "C" {
#include "sph/status.h"
}
#include "gpu/gpu.h"

extern "C" int sph_gpu_compiled(void) { return 1; }

extern "C" int sph_gpu_probe(char *why, size_t size) {
  int count = 0;
  cudaError_t e = cudaGetDeviceCount(&count);
  if (e != cudaSuccess || count <= 0) {
    snprintf(why, size, "no CUDA device on this machine (%s)",
             e != cudaSuccess ? cudaGetErrorString(e) : "none found");
    return 0;
  }
  cudaDeviceProp prop;
  if (cudaGetDeviceProperties(&prop, 0) == cudaSuccess)
    snprintf(why, size, "%s (sm_%d%d, %.1f GiB)", prop.name, prop.major,
             prop.minor, (double)prop.totalGlobalMem / 1073741824.0);
  else
    snprintf(why, size, "CUDA device 0");
  return count;
}
