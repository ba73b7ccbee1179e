/* The machine's memory bandwidth for sph bench: the STREAM triad
 * (McCalpin's a_i = b_i + s c_i) over three arrays far larger than the
 * caches, the best of the repetitions of 0.3 s (at least ten), on a given
 * thread count. A case
 * whose sweeps stream their data from memory cannot gain more from threads
 * than this bandwidth does, so bench prints it beside the cases (from a
 * child process, as the cases: cmd_bench.c). */
#include <omp.h>
#include <stdlib.h>

#include "app/app_impl.h"

double bench_memory_triad(int threads, size_t bytes) {
  long n = (long)(bytes / sizeof(double));
  double *a = malloc((size_t)n * sizeof *a), *b = malloc((size_t)n * sizeof *b),
         *c = malloc((size_t)n * sizeof *c);
  double best = 0.0;
  if (a && b && c && n > 0) {
    /* first touch by the threads that stream them */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long i = 0; i < n; ++i) {
      a[i] = 0.0;
      b[i] = 1.0;
      c[i] = 2.0;
    }
    double t_end = omp_get_wtime() + 0.3;
    for (int rep = 0; rep < 10 || omp_get_wtime() < t_end; ++rep) {
      double t = omp_get_wtime();
#pragma omp parallel for schedule(static) num_threads(threads)
      for (long i = 0; i < n; ++i)
        a[i] = b[i] + 1.5 * c[i];
      t = omp_get_wtime() - t;
      double rate = t > 0.0 ? 3.0 * (double)n * sizeof *a / t : 0.0;
      best = rate > best ? rate : best;
    }
    /* the result is read, so the loops cannot be dropped */
    if (a[n / 2] != 4.0)
      best = 0.0;
  }
  free(a);
  free(b);
  free(c);
  return best;
}
