/* sph bench: a fixed suite of throughput cases built from the shipped scenes
 * (docs/design.md sec. 1), each run in its own child process so that its peak
 * memory (the child's maximum resident set) is its own, on one thread and
 * on every core. Prints a table and, with --json FILE, writes the figures.
 * It times the solver's own steps and timers (those summary.json reports);
 * nothing here is a test threshold: machines are shared and noisy. With
 * --mpi it runs one case in this process over the ranks its launcher
 * started (mpirun -np N sph bench --mpi; one rank without a launcher) and
 * adds the halo traffic and the time in exchanges to the figures. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "app/app_impl.h"
#include "io/sink.h"
#include "parallel/domain.h"
#include "render/render.h"
#include "scene/scene.h"
#include "solver/run.h"

#include "app/bench_impl.h"

#define PLATE30                                                                \
  "bodies.0.particles.spacing=0.00066666666666666667",                         \
      "bodies.0.shape.box.min=[-0.0026666666666666667,-0.01]"

static const bench_case full_cases[] = {
    {"twisting column 11x61x11 tl-jst pF",
     "twisting_column",
     {"bodies.0.particles.count=[11,61,11]", "method.fields=pF"},
     200,
     0},
    {"twisting column 11x61x11 tl-jst pFJ",
     "twisting_column",
     {"bodies.0.particles.count=[11,61,11]", "method.fields=pFJ"},
     200,
     0},
    {"twisting column 11x61x11 tl-jst pFHJ",
     "twisting_column",
     {"bodies.0.particles.count=[11,61,11]", "method.fields=pFHJ"},
     200,
     0},
    {"twisting column 11x61x11 tl-csph",
     "twisting_column",
     {"bodies.0.particles.count=[11,61,11]", "method={name: tl-csph}"},
     400,
     0},
    {"twisting column 11x66x11 tl-bond SSP-RK3",
     "twisting_column_bond",
     {"bodies.0.particles.count=[11,66,11]"},
     200,
     0},
    {"2D plate H/dp 10 ul-sph ENOG dual", "oscillating_plate_2d", {0}, 4000, 0},
    {"2D plate H/dp 30 ul-sph ENOG dual",
     "oscillating_plate_2d",
     {PLATE30},
     1000,
     0},
    {"colliding rings dp 0.001 ul-sph ENOG", "colliding_rings", {0}, 1000, 0},
    {"1M particles tl-jst pF, 3 steps, .vtp, frame",
     "twisting_column",
     {"bodies.0.particles.count=[55,330,55]", "method.fields=pF"},
     3,
     1},
};

static const bench_case quick_cases[] = {
    {"twisting column 5x25x5 tl-jst pF",
     "twisting_column",
     {"bodies.0.particles.count=[5,25,5]", "method.fields=pF"},
     100,
     0},
    {"twisting column 5x25x5 tl-jst pFJ",
     "twisting_column",
     {"bodies.0.particles.count=[5,25,5]", "method.fields=pFJ"},
     100,
     0},
    {"twisting column 5x25x5 tl-jst pFHJ",
     "twisting_column",
     {"bodies.0.particles.count=[5,25,5]", "method.fields=pFHJ"},
     100,
     0},
    {"twisting column 5x25x5 tl-csph",
     "twisting_column",
     {"bodies.0.particles.count=[5,25,5]", "method={name: tl-csph}"},
     200,
     0},
    {"twisting column 5x25x5 tl-bond SSP-RK3",
     "twisting_column_bond",
     {"bodies.0.particles.count=[5,25,5]"},
     100,
     0},
    {"2D plate H/dp 10 ul-sph ENOG dual", "oscillating_plate_2d", {0}, 400, 0},
    {"2D plate H/dp 30 ul-sph ENOG dual",
     "oscillating_plate_2d",
     {PLATE30},
     20,
     0},
    {"colliding rings dp 0.002 ul-sph ENOG",
     "colliding_rings",
     {"bodies.0.particles.spacing=0.002", "bodies.1.particles.spacing=0.002"},
     100,
     0},
    {"48k particles tl-jst pF, 3 steps, .vtp, frame",
     "twisting_column",
     {"bodies.0.particles.count=[20,120,20]", "method.fields=pF"},
     3,
     1},
};

/* what a child measured, sent back through a pipe */
typedef struct bench_result {
  int ok;
  char error[256];
  long particles, steps;
  int threads;
  double setup_seconds, first_step_seconds, step_seconds, vtp_seconds,
      frame_seconds;
  double step_cpu_seconds; /* the process's CPU time over the steps */
  int nparts;
  char part[BENCH_MAX_PARTS][48];
  double part_seconds[BENCH_MAX_PARTS];
  long max_rss_kb; /* filled by the parent */
} bench_result;

/* a bench case runs a set number of steps: an end and an output interval
 * far beyond them (below the scene check of 1e12 steps) */
const char *const sph_bench_outputs_off[SPH_BENCH_OUTPUTS_OFF] = {
    "output.vtk=false", "output.png=false", "output.probes=[]", "time.end=1e6",
    "output.every=1e5"};

/* the frame case keeps the scene's png block and the vtk sink */
static const char *const outputs_frame[] = {
    "output.vtk=true", "output.png={width: 1280, height: 720, mp4: false}",
    "output.probes=[]", "time.end=1e6", "output.every=1e5"};

sph_status sph_bench_steps(sph_run *run, unsigned long steps, sph_error *err) {
  SPH_TRY(sph_run_advance_steps(run, steps, err));
  if (sph_run_state_of(run) == SPH_RUN_UNSTABLE) /* a step failed */
    return sph_error_set(err, SPH_ERR_NUMERIC, "%s",
                         sph_run_verdict(run)->reason);
  return SPH_OK;
}

/* the method's timers and the terms, in that order; with `since`, the
 * seconds spent after that snapshot (set-up work excluded) */
static void collect_parts(const sph_sim *sim, bench_result *r,
                          const bench_result *since) {
  r->nparts = 0;
  for (int i = 0; i < sim->ntimers && r->nparts < BENCH_MAX_PARTS; ++i) {
    snprintf(r->part[r->nparts], sizeof r->part[0], "%s", sim->timers[i].name);
    r->part_seconds[r->nparts++] = sim->timers[i].seconds;
  }
  for (int i = 0; i < sim->nterms && r->nparts < BENCH_MAX_PARTS; ++i) {
    snprintf(r->part[r->nparts], sizeof r->part[0], "%s",
             sim->terms[i].ops->name);
    r->part_seconds[r->nparts++] = sim->terms[i].seconds;
  }
  for (int i = 0; since && i < r->nparts && i < since->nparts; ++i)
    r->part_seconds[i] -= since->part_seconds[i];
}

static sph_status time_sink(const sph_sink_ops *ops, sph_sim *sim,
                            const char *dir, double *seconds, sph_error *err) {
  sph_sink sink = {.ops = ops};
  sph_status st = sim->method->derive(sim, err);
  sph_frame fr = {
      .time = sim->t, .step = sim->steps, .sim = sim, .ps = sim->ps};
  sim->method->energy(sim, &fr.kinetic, &fr.strain);
  if (st == SPH_OK)
    st = ops->open(&sink, sim, dir, err);
  double t0 = sph_wtime();
  if (st == SPH_OK)
    st = ops->write(&sink, &fr, err);
  if (st == SPH_OK)
    st = ops->close(&sink, err);
  *seconds = sph_wtime() - t0;
  if (ops->destroy)
    ops->destroy(&sink);
  return st;
}

/* CPU time of this process (all its threads) */
static double cpu_seconds(void) {
  struct timespec ts;
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0)
    return 0.0;
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* the child: load, step, time; fills r */
static void bench_child(const bench_case *c, int threads, const char *dir,
                        bench_result *r) {
  omp_set_num_threads(threads);
  const char *sets[BENCH_MAX_SETS + 8];
  size_t n = 0;
  for (int i = 0; i < BENCH_MAX_SETS && c->sets[i]; ++i)
    sets[n++] = c->sets[i];
  const char *const *extra = c->frame ? outputs_frame : sph_bench_outputs_off;
  size_t nextra = c->frame ? sizeof outputs_frame / sizeof *outputs_frame
                           : SPH_BENCH_OUTPUTS_OFF;
  for (size_t i = 0; i < nextra; ++i)
    sets[n++] = extra[i];
  char path[1024];
  snprintf(path, sizeof path, "%s/%s.yaml", sph_app_scenes_dir(), c->scene);
  sph_scene *scene = NULL;
  sph_run *run = NULL;
  sph_sim *sim = NULL;
  sph_error err;
  sph_error_clear(&err);
  double t0 = sph_wtime();
  sph_status st = sph_scene_load(&scene, path, sets, n, &err);
  sph_run_options opt = {.no_files = 1};
  if (st == SPH_OK)
    st = sph_run_create(&run, scene, &opt, &err);
  r->setup_seconds = sph_wtime() - t0;
  if (st == SPH_OK) {
    sim = sph_run_sim(run);
    r->particles = (long)sim->ps->n;
    r->threads = sim->threads;
    /* the first step touches the work arrays' pages for the first time
     * (about 1 s at 1M particles): timed apart, so the case's figure is
     * the steady step rate a long run sees */
    t0 = sph_wtime();
    st = sph_bench_steps(run, 1, &err);
    r->first_step_seconds = sph_wtime() - t0;
    bench_result *before = calloc(1, sizeof *before);
    if (before)
      collect_parts(sim, before, NULL);
    double c0 = cpu_seconds();
    t0 = sph_wtime();
    if (st == SPH_OK)
      st = sph_bench_steps(run, (unsigned long)c->steps, &err);
    r->step_seconds = sph_wtime() - t0;
    r->step_cpu_seconds = cpu_seconds() - c0;
    r->steps = (long)sim->steps - 1;
    collect_parts(sim, r, before);
    free(before);
  }
  if (st == SPH_OK && c->frame)
    st = time_sink(&sph_vtk_sink_ops, sim, dir, &r->vtp_seconds, &err);
  if (st == SPH_OK && c->frame)
    st = time_sink(&sph_png_sink_sync_ops, sim, dir, &r->frame_seconds, &err);
  r->ok = st == SPH_OK;
  if (!r->ok)
    sph_error_format(&err, r->error, sizeof r->error);
  sph_run_destroy(run);
  sph_scene_destroy(scene);
}

/* Runs work(ctx, out) in a child process (an OpenMP team started in this
 * process would not survive the next fork) and reads its size bytes of
 * out back; 1 when they all came, 0 when not (status: how the child
 * ended), -1 when no child could be started. */
/* SIGINT, SIGTERM, SIGHUP and SIGPIPE (the reader of the output gone) end
 * the case running, start no other, and the suite removes its folder
 * before the signal ends it (bench_end_on_signal) */
static volatile sig_atomic_t bench_signal, running_child;
static const int bench_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};

static void on_bench_signal(int signo) {
  bench_signal = signo;
  if (running_child > 0)
    kill((pid_t)running_child, SIGTERM);
}

static void bench_catch_signals(void (*handler)(int)) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = handler;
  sa.sa_flags = SA_RESTART;
  sigemptyset(&sa.sa_mask);
  for (size_t i = 0; i < sizeof bench_signals / sizeof *bench_signals; ++i)
    sigaction(bench_signals[i], &sa, NULL);
}

static void remove_dir_files(const char *dir);

int sph_bench_interrupted(void) { return bench_signal != 0; }

static void bench_end_on_signal(const char *dir) {
  int signo = bench_signal;
  if (!signo)
    return;
  if (dir)
    remove_dir_files(dir);
  fflush(stdout); /* the rows printed so far */
  signal(signo, SIG_DFL);
  raise(signo);
}

int sph_bench_in_child(void (*work)(const void *ctx, void *out),
                       const void *ctx, void *out, size_t size, int *status,
                       struct rusage *ru) {
  int fd[2];
  fflush(NULL);
  if (bench_signal || pipe(fd) != 0)
    return -1;
  pid_t pid = fork();
  if (pid < 0) {
    close(fd[0]);
    close(fd[1]);
    return -1;
  }
  if (pid == 0) {
    close(fd[0]);
    bench_catch_signals(SIG_DFL);
    work(ctx, out);
    ssize_t w = write(fd[1], out, size);
    _exit(w == (ssize_t)size ? 0 : 1);
  }
  close(fd[1]);
  running_child = pid;
  if (bench_signal) /* it came between the fork and here */
    kill(pid, SIGTERM);
  size_t got = 0;
  while (got < size) {
    ssize_t k = read(fd[0], (char *)out + got, size - got);
    if (k <= 0)
      break;
    got += (size_t)k;
  }
  close(fd[0]);
  int waited = wait4(pid, status, 0, ru) >= 0;
  running_child = 0;
  return waited ? got == size : -1;
}

typedef struct case_job {
  const bench_case *c;
  int threads;
  const char *dir;
} case_job;

static void case_work(const void *ctx, void *out) {
  const case_job *j = ctx;
  bench_child(j->c, j->threads, j->dir, out);
}

/* runs one case in a child process; returns 0, or -1 when it could not */
static int bench_run(const bench_case *c, int threads, const char *dir,
                     bench_result *r) {
  memset(r, 0, sizeof *r);
  case_job job = {c, threads, dir};
  int status = 0;
  struct rusage ru;
  int got = sph_bench_in_child(case_work, &job, r, sizeof *r, &status, &ru);
  if (got < 0)
    return -1;
  if (!got) {
    memset(r, 0, sizeof *r);
    snprintf(r->error, sizeof r->error, "the case's process ended (%s %d)",
             WIFSIGNALED(status) ? "signal" : "status",
             WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status));
  }
  r->max_rss_kb = ru.ru_maxrss;
  return 0;
}

typedef struct machine_job {
  int threads, arithmetic; /* arithmetic: the multiply-add chains */
} machine_job;

static void machine_work(const void *ctx, void *out) {
  const machine_job *j = ctx;
  *(double *)out = j->arithmetic
                       ? bench_machine_flops(j->threads)
                       : bench_machine_triad(j->threads, (size_t)64 << 20);
}

/* the STREAM triad (bytes per second) or the multiply-add chains (flops per
 * second) on `threads` threads; 0 if it failed */
static double machine_rate(int threads, int arithmetic) {
  machine_job job = {threads, arithmetic};
  double rate = 0.0;
  int status = 0;
  struct rusage ru;
  return sph_bench_in_child(machine_work, &job, &rate, sizeof rate, &status,
                            &ru) == 1
             ? rate
             : 0.0;
}

static double per_thread_rate(const bench_result *r) {
  return r->step_seconds > 0.0 ? (double)r->particles * (double)r->steps /
                                     r->step_seconds / r->threads
                               : 0.0;
}

/* the serial fraction of the step from a case's 1- and N-thread rows */
static double case_serial_fraction(const bench_result *one,
                                   const bench_result *r) {
  return sph_bench_serial_fraction(one->step_seconds / (double)one->steps,
                                   r->step_seconds / (double)r->steps,
                                   r->threads);
}

static void print_row(const bench_case *c, const bench_result *r,
                      long baseline_kb) {
  if (!r->ok) {
    printf("  %-46s %2d thr  FAILED: %s\n", c->name, r->threads, r->error);
    return;
  }
  double bytes = r->particles > 0 ? (double)(r->max_rss_kb - baseline_kb) *
                                        1024.0 / (double)r->particles
                                  : 0.0;
  char per[32] = "";
  /* below 10,000 particles the baseline's noise outweighs the state */
  if (r->particles >= 10000)
    snprintf(per, sizeof per, " (%.2f kB/p)", bytes / 1024.0);
  /* below 100 % the threads waited for the cores (a shared machine) */
  double cpu = r->step_seconds > 0.0 ? 100.0 * r->step_cpu_seconds /
                                           (r->step_seconds * r->threads)
                                     : 0.0;
  printf("  %-46s %2d thr %9ld p %6ld st %8.3f s %7.3f M p-st/s/thr  "
         "cpu %.0f %%  setup %.2f s  first step %.3f s  peak %.0f MB%s",
         c->name, r->threads, r->particles, r->steps, r->step_seconds,
         per_thread_rate(r) / 1e6, cpu, r->setup_seconds, r->first_step_seconds,
         (double)r->max_rss_kb / 1024.0, per);
  if (c->frame)
    printf("  .vtp %.3f s  frame %.3f s", r->vtp_seconds, r->frame_seconds);
  printf("\n");
  /* the step's split, largest first */
  int order[BENCH_MAX_PARTS];
  for (int i = 0; i < r->nparts; ++i)
    order[i] = i;
  for (int i = 1; i < r->nparts; ++i)
    for (int j = i;
         j > 0 && r->part_seconds[order[j]] > r->part_seconds[order[j - 1]];
         --j) {
      int t = order[j];
      order[j] = order[j - 1];
      order[j - 1] = t;
    }
  double covered = 0.0;
  printf("      split:");
  for (int i = 0; i < r->nparts; ++i) {
    const double sec = r->part_seconds[order[i]];
    covered += sec;
    if (r->step_seconds > 0.0 && sec >= 0.01 * r->step_seconds)
      printf(" %s %.0f %%", r->part[order[i]], 100.0 * sec / r->step_seconds);
  }
  if (r->step_seconds > 0.0)
    printf("; timed %.0f %% of the steps\n", 100.0 * covered / r->step_seconds);
  else
    printf("\n");
}

void sph_bench_json_str(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; ++s)
    if (*s == '"' || *s == '\\')
      fprintf(f, "\\%c", *s);
    else if ((unsigned char)*s < 0x20)
      fprintf(f, "\\u%04x", (unsigned char)*s);
    else
      fputc(*s, f);
  fputc('"', f);
}

/* the JSON's opening: schema, suite and machine */
/* the head and the machine; speed[0][t]: the memory bandwidth, speed[1][t]
 * the arithmetic rate on the bench's nthr thread counts (none: nthr 0) */
void sph_bench_json_head(FILE *f, const char *suite, long cores,
                         const double speed[2][2], int nthr) {
  char cpu[256];
  sph_bench_cpu_model(cpu, sizeof cpu);
  fprintf(f, "{\n  \"schema_version\": %d,\n  \"suite\": \"%s\",\n",
          BENCH_SCHEMA, suite);
  fprintf(f, "  \"machine\": {\"cores\": %ld, \"cpu\": ", cores);
  sph_bench_json_str(f, cpu);
  const char *keys[2] = {"triad_gb_per_s", "multiply_add_gflop_per_s"};
  for (int k = 0; k < 2 && nthr > 0; ++k) {
    fprintf(f, ", \"%s\": [", keys[k]);
    for (int t = 0; t < nthr; ++t)
      fprintf(f, "%s%.4g", t ? ", " : "", speed[k][t] / 1e9);
    fprintf(f, "]");
  }
  fprintf(f, "},\n");
}

/* closes the JSON written to tmp and renames it to path; -1 on failure */
int sph_bench_json_finish(FILE *f, const char *tmp, const char *path) {
  int bad = ferror(f) != 0;
  bad |= fflush(f) != 0 || fsync(fileno(f)) != 0;
  bad |= fclose(f) != 0;
  if (bad || rename(tmp, path) != 0) {
    remove(tmp);
    return -1;
  }
  return 0;
}

static int write_json(const char *path, const bench_case *cases, int ncases,
                      const bench_result *res, int nthr, int quick, long cores,
                      long baseline_kb, const double speed[2][2]) {
  char tmp[1100];
  snprintf(tmp, sizeof tmp, "%s.part", path);
  FILE *f = fopen(tmp, "w");
  if (!f)
    return -1;
  sph_bench_json_head(f, quick ? "quick" : "full", cores, speed, nthr);
  fprintf(f, "  \"baseline_rss_mb\": %.3f,\n  \"cases\": [",
          baseline_kb / 1024.0);
  for (int c = 0; c < ncases; ++c)
    for (int t = 0; t < nthr; ++t) {
      const bench_result *r = &res[c * nthr + t];
      fprintf(f, "%s\n    {\"name\": ", c || t ? "," : "");
      sph_bench_json_str(f, cases[c].name);
      fprintf(f, ", \"ok\": %s", r->ok ? "true" : "false");
      if (!r->ok) {
        fprintf(f, ", \"error\": ");
        sph_bench_json_str(f, r->error);
        fprintf(f, "}");
        continue;
      }
      fprintf(f,
              ", \"threads\": %d, \"particles\": %ld, \"steps\": %ld, "
              "\"setup_seconds\": %.6g, \"first_step_seconds\": %.6g, "
              "\"step_seconds\": %.6g, \"step_cpu_seconds\": %.6g, "
              "\"particle_steps_per_second_per_thread\": %.6g, "
              "\"peak_rss_mb\": %.3f, \"bytes_per_particle\": %.6g",
              r->threads, r->particles, r->steps, r->setup_seconds,
              r->first_step_seconds, r->step_seconds, r->step_cpu_seconds,
              per_thread_rate(r), r->max_rss_kb / 1024.0,
              (double)(r->max_rss_kb - baseline_kb) * 1024.0 /
                  (double)r->particles);
      if (cases[c].frame)
        fprintf(f, ", \"vtp_seconds\": %.6g, \"frame_seconds\": %.6g",
                r->vtp_seconds, r->frame_seconds);
      if (t == 1 && res[c * nthr].ok)
        fprintf(f, ", \"serial_fraction\": %.6g",
                case_serial_fraction(&res[c * nthr], r));
      fprintf(f, ", \"parts\": {");
      for (int i = 0; i < r->nparts; ++i) {
        fprintf(f, "%s", i ? ", " : "");
        sph_bench_json_str(f, r->part[i]);
        fprintf(f, ": %.6g", r->part_seconds[i]);
      }
      fprintf(f, "}}");
    }
  fprintf(f, "\n  ]\n}\n");
  return sph_bench_json_finish(f, tmp, path);
}

/* empties and removes the suite's own temporary folder (one level of
 * sub-folders: frames/) */
static void remove_dir_files(const char *dir) {
  char sub[1200], path[1500];
  snprintf(sub, sizeof sub, "%s/frames", dir);
  const char *const dirs[] = {sub, dir};
  for (int i = 0; i < 2; ++i) {
    DIR *d = opendir(dirs[i]);
    struct dirent *e;
    while (d && (e = readdir(d)))
      if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
        snprintf(path, sizeof path, "%s/%s", dirs[i], e->d_name);
        remove(path);
      }
    if (d)
      closedir(d);
    rmdir(dirs[i]);
  }
}

typedef struct bench_args {
  int quick, threads, mpi, peer;
  const char *json;
  const char *only; /* run only the cases whose name contains it */
} bench_args;

static int bench_option(void *ctx, int id, const char *val) {
  bench_args *b = ctx;
  switch (id) {
  case SPH_OPT_QUICK:
    b->quick = 1;
    return SPH_EXIT_OK;
  case SPH_OPT_JSON:
    b->json = val;
    return SPH_EXIT_OK;
  case SPH_OPT_CASE:
    b->only = val;
    return SPH_EXIT_OK;
  case SPH_OPT_MPI:
    b->mpi = 1;
    return SPH_EXIT_OK;
  case SPH_OPT_THREADS:
    return sph_app_count("bench", "threads", val, 1024, &b->threads);
  default:
    return SPH_EXIT_USAGE;
  }
}

/* the one operand: `peer`, the peer's own case (src/app/bench_peer.c) */
static int bench_operand(void *ctx, const char *val) {
  bench_args *b = ctx;
  if (strcmp(val, "peer")) {
    fprintf(stderr, "sph bench: the only operand is 'peer', not '%s'\n", val);
    return SPH_EXIT_USAGE;
  }
  b->peer = 1;
  return SPH_EXIT_OK;
}

static const int bench_allowed[] = {
    SPH_OPT_QUICK, SPH_OPT_JSON, SPH_OPT_THREADS, SPH_OPT_CASE, SPH_OPT_MPI, 0};
static const sph_app_command bench_command = {
    "bench",
    "usage: sph bench [--quick] [--json FILE] [--threads N] [--case TEXT]\n"
    "       [mpirun -np N] sph bench --mpi [--quick] [--json FILE] "
    "[--threads N]\n"
    "       sph bench peer [--threads N] [--case METHOD] [--json FILE]\n"
    "  throughput, split and memory of a fixed suite of the shipped scenes\n"
    "  (--case: only the case named TEXT, else those whose name contains\n"
    "  it); --mpi: the tl-csph column at 202,771 particles over the ranks\n"
    "  the launcher started (one without), N threads a rank (default 1);\n"
    "  --mpi --case weak: 101,866 particles a rank; peer: the twisting\n"
    "  column at 11x61x11 to 0.5 s (SPHinXsys' case), every method at its\n"
    "  defaults (--case: those whose name contains METHOD), one thread\n"
    "  unless --threads N: steps and wall time\n",
    bench_allowed, bench_option, bench_operand};

/* the suite, or with --case the case of that name, else the cases whose
 * name contains the text (none: a message); NULL without memory */
static bench_case *select_cases(int quick, const char *only, int *ncases) {
  const bench_case *suite = quick ? quick_cases : full_cases;
  int nsuite = quick ? (int)(sizeof quick_cases / sizeof *quick_cases)
                     : (int)(sizeof full_cases / sizeof *full_cases);
  bench_case *cases = malloc((size_t)nsuite * sizeof *cases);
  int exact = 0;
  *ncases = 0;
  for (int c = 0; only && c < nsuite; ++c)
    exact |= !strcmp(suite[c].name, only);
  for (int c = 0; cases && c < nsuite; ++c)
    if (!only || (exact ? !strcmp(suite[c].name, only)
                        : strstr(suite[c].name, only) != NULL))
      cases[(*ncases)++] = suite[c];
  if (cases && !*ncases)
    fprintf(stderr, "sph bench: no case of the %s suite is named '%s'\n",
            quick ? "quick" : "full", only);
  return cases;
}

/* sph bench peer (src/app/bench_peer.c), in one process (no mpirun) */
static int bench_peer(const bench_args *b) {
  if (b->mpi || b->quick || sph_domain_world_size() > 1) {
    fprintf(stderr, "sph bench: peer takes neither --mpi nor --quick, and "
                    "runs without mpirun\n");
    return SPH_EXIT_USAGE;
  }
  bench_catch_signals(on_bench_signal);
  int rc = sph_bench_peer(b->threads ? b->threads : 1, b->only, b->json);
  bench_end_on_signal(NULL);
  return rc;
}

int sph_cmd_bench(int argc, char **argv) {
  bench_args b = {0, 0, 0, 0, NULL, NULL};
  int rc = sph_app_getopt(&bench_command, argc, argv, &b);
  if (rc != SPH_EXIT_OK)
    return rc == SPH_APP_HELP ? SPH_EXIT_OK : rc;
  int weak = b.only && !strcmp(b.only, "weak");
  if (b.mpi && b.only && !weak && strcmp(b.only, "strong")) {
    if (sph_domain_world_rank() == 0)
      fprintf(stderr,
              "sph bench: --mpi runs the case strong (the "
              "default) or weak, not '%s'\n",
              b.only);
    return SPH_EXIT_USAGE;
  }
  if (b.peer)
    return bench_peer(&b);
  if (b.mpi)
    return sph_bench_mpi(b.quick, weak, b.threads ? b.threads : 1, b.json);
  if (sph_domain_world_size() > 1) { /* forks a process per case */
    if (sph_domain_world_rank() == 0)
      fprintf(stderr, "sph bench: under mpirun only 'sph bench --mpi' "
                      "runs\n");
    return SPH_EXIT_USAGE;
  }
  int quick = b.quick, threads = b.threads;
  const char *json = b.json;
  int ncases = 0;
  bench_case *cases = select_cases(quick, b.only, &ncases);
  if (!cases || !ncases) {
    free(cases);
    return cases ? SPH_EXIT_USAGE : SPH_EXIT_IO;
  }
  long cores = sysconf(_SC_NPROCESSORS_ONLN);
  int thr[2] = {1, threads ? threads : (int)(cores > 0 ? cores : 1)};
  int nthr = thr[1] == 1 ? 1 : 2;
  const char *tmp = getenv("TMPDIR");
  char dir[1024];
  snprintf(dir, sizeof dir, "%s/sph_bench_XXXXXX", tmp && *tmp ? tmp : "/tmp");
  bench_catch_signals(on_bench_signal);
  if (!mkdtemp(dir)) {
    fprintf(stderr, "sph bench: cannot create a temporary folder: %s\n",
            strerror(errno));
    free(cases);
    return SPH_EXIT_IO;
  }
  /* the resident set of a process that sets up the smallest scene (the
   * default column, 625 particles) and takes no step: subtracted before
   * dividing by a case's particle count */
  bench_case none = {"baseline", "twisting_column", {0}, 0, 0};
  bench_result base;
  bench_run(&none, 1, dir, &base);
  bench_end_on_signal(dir);
  long baseline_kb = base.max_rss_kb;
  char thr2[32] = "";
  if (nthr > 1)
    snprintf(thr2, sizeof thr2, " and %d", thr[1]);
  printf("sph bench (%s suite): %ld cores, threads %d%s; baseline "
         "resident set %.0f MB\n",
         quick ? "quick" : "full", cores, thr[0], thr2, baseline_kb / 1024.0);
  /* the machine's own speed-up with threads: the ceilings of a case that
   * streams its data (3 arrays of 64 MB, beyond any cache) and of one bound
   * by arithmetic, the best of three turns in alternation, as a shared
   * machine's load comes and goes */
  double speed[2][2] = {{0.0, 0.0}, {0.0, 0.0}};
  for (int turn = 0; turn < 3; ++turn)
    for (int k = 0; k < 2; ++k)
      for (int t = 0; t < nthr; ++t) {
        double r = machine_rate(thr[t], k);
        speed[k][t] = r > speed[k][t] ? r : speed[k][t];
      }
  bench_end_on_signal(dir);
  static const char *const what[2] = {"memory bandwidth (STREAM triad",
                                      "arithmetic (multiply-add chains"};
  static const char *const unit[2] = {"GB/s", "GFlop/s"};
  static const char *const bound[2] = {"memory", "arithmetic"};
  for (int k = 0; k < 2; ++k) {
    printf("  %s, best of 3 turns): %d thr %.1f %s", what[k], thr[0],
           speed[k][0] / 1e9, unit[k]);
    if (nthr > 1 && speed[k][0] > 0.0)
      printf(", %d thr %.1f %s (%.2fx): the most a case bound by %s gains "
             "from threads",
             thr[1], speed[k][1] / 1e9, unit[k], speed[k][1] / speed[k][0],
             bound[k]);
    printf("\n");
  }
  bench_result *res = calloc((size_t)(ncases * nthr), sizeof *res);
  if (!res) {
    free(cases);
    remove_dir_files(dir);
    return SPH_EXIT_IO;
  }
  int failed = 0;
  for (int c = 0; c < ncases; ++c)
    for (int t = 0; t < nthr; ++t) {
      bench_result *r = &res[c * nthr + t];
      if (bench_run(&cases[c], thr[t], dir, r) != 0)
        snprintf(r->error, sizeof r->error, "could not start: %s",
                 strerror(errno));
      if (!r->threads)
        r->threads = thr[t];
      bench_end_on_signal(dir);
      failed |= !r->ok;
      print_row(&cases[c], r, baseline_kb);
      if (t == 1 && r->ok && res[c * nthr].ok)
        printf("      serial fraction %.3f (Karp-Flatt: 1 and %d threads)\n",
               case_serial_fraction(&res[c * nthr], r), r->threads);
    }
  rc = failed ? SPH_EXIT_FAIL : SPH_EXIT_OK;
  if (json && write_json(json, cases, ncases, res, nthr, quick, cores,
                         baseline_kb, speed) != 0) {
    fprintf(stderr, "sph bench: cannot write %s\n", json);
    rc = SPH_EXIT_IO;
  }
  free(res);
  free(cases);
  remove_dir_files(dir);
  return rc;
}
