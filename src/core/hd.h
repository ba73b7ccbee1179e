/* SPH_HD: the qualifier of the small inline functions that both the CPU
 * build (C11) and the CUDA build (nvcc, docs/gpu.md) compile, so that the
 * device step and the CPU methods share one source of physics: pair
 * functions, tensor math and material laws. Empty in C. */
#ifndef SPH_HD_H
#define SPH_HD_H

#ifdef __CUDACC__
#define SPH_HD __host__ __device__
#else
#define SPH_HD
#endif

#endif
