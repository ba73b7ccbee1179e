/* sph bench's parts shared by its files: the suite's case, the overrides
 * that turn a scene's outputs off, the JSON helpers, and --mpi
 * (src/app/bench_mpi.c). */
#ifndef SPH_BENCH_IMPL_H
#define SPH_BENCH_IMPL_H

#include <stdio.h>

#include "solver/run.h"

#define BENCH_SCHEMA 1
#define BENCH_MAX_SETS 8
#define BENCH_MAX_PARTS 24

/* One case: a shipped scene with overrides, run for a fixed step count;
 * `frame` also times a .vtp write and a 1280 x 720 frame of the state. */
typedef struct bench_case {
  const char *name;
  const char *scene;
  const char *sets[BENCH_MAX_SETS];
  long steps;
  int frame;
} bench_case;

/* the overrides that write nothing and never reach the end time */
#define SPH_BENCH_OUTPUTS_OFF 5
extern const char *const sph_bench_outputs_off[SPH_BENCH_OUTPUTS_OFF];

/* a JSON string, escaped */
void sph_bench_json_str(FILE *f, const char *s);
/* the head and the machine; speed[0][t]: the memory bandwidth, speed[1][t]
 * the arithmetic rate on the bench's nthr thread counts (none: nthr 0) */
void sph_bench_json_head(FILE *f, const char *suite, long cores,
                         const double speed[2][2], int nthr);
/* closes the JSON written to tmp and renames it to path; -1 on failure */
int sph_bench_json_finish(FILE *f, const char *tmp, const char *path);

/* `steps` steps of a run that writes nothing; a step that failed is an
 * error (the verdict's reason) */
sph_status sph_bench_steps(sph_run *run, unsigned long steps, sph_error *err);

/* sph bench --mpi: the tl-csph column over the launcher's ranks (weak: a
 * column as tall as the ranks); rank 0 prints and writes the JSON */
int sph_bench_mpi(int quick, int weak, int threads, const char *json);

/* runs work(ctx, out) in a child process and reads its size bytes of out
 * back: 1 when they all came, 0 when not (status: how the child ended), -1
 * when no child could be started */
struct rusage;
int sph_bench_in_child(void (*work)(const void *ctx, void *out),
                       const void *ctx, void *out, size_t size, int *status,
                       struct rusage *ru);
/* a signal asked the suite to stop */
int sph_bench_interrupted(void);

/* the CPU model of /proc/cpuinfo, else "unknown" */
void sph_bench_cpu_model(char *out, size_t len);

/* Karp and Flatt's serial fraction from the wall time of a step on one
 * thread and on p (NaN when p < 2 or a time is not positive) */
double sph_bench_serial_fraction(double step1, double stepp, int p);

/* sph bench peer: the twisting column at 11x61x11 to 0.5 s for every method
 * (those whose name contains `only`) at its defaults, on `threads` threads */
int sph_bench_peer(int threads, const char *only, const char *json);

#endif
