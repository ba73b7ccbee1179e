/* The machine's own speed-up with threads, for sph bench: the ceilings of a
 * case bound by memory and of one bound by arithmetic.
 * - Memory: the STREAM triad (McCalpin's a_i = b_i + s c_i) over three
 *   arrays far larger than the caches.
 * - Arithmetic: twelve independent multiply-add chains a thread, in
 *   registers (no memory traffic). Two logical CPUs that are one core's
 *   hardware threads share its arithmetic units: the figure shows it.
 * Each is the best of the repetitions of 0.3 s (at least ten) on a given
 * thread count; bench runs them in a child process, as the cases
 * (cmd_bench.c).
 * - A case's serial fraction: Karp and Flatt's experimentally determined
 *   fraction e = (1/S - 1/p) / (1 - 1/p) of Amdahl's law, S the speed-up of
 *   its step on p threads over one.
 * - The CPU model (the JSON's machine). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/app_impl.h"
#include "app/bench_impl.h"

double sph_bench_serial_fraction(double step1, double stepp, int p) {
  if (!(step1 > 0.0 && stepp > 0.0) || p < 2)
    return NAN;
  double speedup = step1 / stepp;
  return (1.0 / speedup - 1.0 / p) / (1.0 - 1.0 / p);
}

double bench_machine_triad(int threads, size_t bytes) {
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

enum { CHAINS = 12 };

/* `iters` rounds of CHAINS independent x = x m + c: 2 CHAINS iters flops */
static double chains_run(long iters, double seed) {
  double x[CHAINS];
  for (int k = 0; k < CHAINS; ++k)
    x[k] = seed + k;
  const double m = 0.9999999, c = 1e-7;
  for (long i = 0; i < iters; ++i)
    for (int k = 0; k < CHAINS; ++k)
      x[k] = x[k] * m + c;
  double s = 0.0;
  for (int k = 0; k < CHAINS; ++k)
    s += x[k];
  return s;
}

double bench_machine_flops(int threads) {
  const long iters = 2000000; /* about 10 ms a repetition */
  double best = 0.0, sink = 0.0;
  double t_end = omp_get_wtime() + 0.3;
  for (int rep = 0; rep < 10 || omp_get_wtime() < t_end; ++rep) {
    double t = omp_get_wtime();
#pragma omp parallel num_threads(threads) reduction(+ : sink)
    sink += chains_run(iters, 1.0 + rep);
    t = omp_get_wtime() - t;
    double rate = t > 0.0 ? 2.0 * CHAINS * (double)iters * threads / t : 0.0;
    best = rate > best ? rate : best;
  }
  /* the sums are read, so the chains cannot be dropped */
  return sink > 0.0 ? best : 0.0;
}

/* the CPU model of /proc/cpuinfo, else "unknown" */
void sph_bench_cpu_model(char *out, size_t len) {
  snprintf(out, len, "unknown");
  FILE *f = fopen("/proc/cpuinfo", "r");
  char line[512];
  while (f && fgets(line, sizeof line, f))
    if (!strncmp(line, "model name", 10)) {
      const char *v = strchr(line, ':');
      if (v) {
        v += 1 + strspn(v + 1, " \t");
        snprintf(out, len, "%.*s", (int)strcspn(v, "\n"), v);
      }
      break;
    }
  if (f)
    fclose(f);
}
