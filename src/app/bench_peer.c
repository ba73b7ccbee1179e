/* sph bench peer: the peer's own case side by side in one command (issue
 * 33): SPHinXsys' test_3d_twisting_column is the twisting column of
 * scenes/twisting_column.yaml (omega 105) at 11 x 61 x 11 particles to
 * t = 0.5 s; every method runs it at its defaults (a method block of its
 * name only), each in its own child process, to the end time or to the
 * verdict that stopped it. Prints the step count, the wall time of the
 * steps and the set-up for each; the peer's figures measured on a quiet
 * 16-core Xeon (2,332 steps, 22.8-26.0 s on one thread) are printed beside
 * them for reference, never as a threshold. */
#include <limits.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include "app/app_impl.h"
#include "app/bench_impl.h"
#include "scene/scene.h"
#include "solver/run.h"

#define PEER_STEPS 2332
#define PEER_END "time.end=0.5"
#define PEER_COUNT "bodies.0.particles.count=[11,61,11]"

/* what a child measured, sent back through a pipe */
typedef struct peer_result {
  int ok, stable;
  char error[256];
  long particles;
  unsigned long steps;
  double t, setup_seconds, step_seconds;
} peer_result;

typedef struct peer_job {
  const char *method;
  int threads;
} peer_job;

/* the child: load the column with the method's defaults and run it to the
 * end time; fills out (a peer_result) */
static void peer_work(const void *ctx, void *out) {
  const peer_job *j = ctx;
  peer_result *r = out;
  memset(r, 0, sizeof *r);
  omp_set_num_threads(j->threads);
  char method[96];
  snprintf(method, sizeof method, "method={name: %s}", j->method);
  const char *sets[] = {PEER_COUNT,         method,
                        PEER_END,           "output.vtk=false",
                        "output.png=false", "output.probes=[]"};
  char path[1024];
  snprintf(path, sizeof path, "%s/twisting_column.yaml", sph_app_scenes_dir());
  sph_scene *scene = NULL;
  sph_run *run = NULL;
  sph_error err;
  sph_error_clear(&err);
  double t0 = sph_wtime();
  sph_status st =
      sph_scene_load(&scene, path, sets, sizeof sets / sizeof *sets, &err);
  sph_run_options opt = {.no_files = 1};
  if (st == SPH_OK)
    st = sph_run_create(&run, scene, &opt, &err);
  r->setup_seconds = sph_wtime() - t0;
  if (st == SPH_OK) {
    sph_sim *sim = sph_run_sim(run);
    r->particles = (long)sim->ps->n;
    t0 = sph_wtime();
    st = sph_run_advance_steps(run, ULONG_MAX, &err);
    r->step_seconds = sph_wtime() - t0;
    r->steps = sim->steps;
    r->t = sim->t;
    r->stable = sph_run_state_of(run) != SPH_RUN_UNSTABLE;
    if (!r->stable)
      snprintf(r->error, sizeof r->error, "%s", sph_run_verdict(run)->reason);
  }
  r->ok = st == SPH_OK;
  if (!r->ok)
    sph_error_format(&err, r->error, sizeof r->error);
  sph_run_destroy(run);
  sph_scene_destroy(scene);
}

static void print_peer_row(const char *method, const peer_result *r) {
  if (!r->ok) {
    printf("  %-8s FAILED: %s\n", method, r->error);
    return;
  }
  printf("  %-8s %7ld p %7lu st %6.3f s %9.2f s  setup %.2f s  "
         "%5.2fx the peer's steps  %.3f M p-st/s  %s%s\n",
         method, r->particles, r->steps, r->t, r->step_seconds,
         r->setup_seconds, (double)r->steps / PEER_STEPS,
         r->step_seconds > 0.0
             ? (double)r->particles * (double)r->steps / r->step_seconds / 1e6
             : 0.0,
         r->stable ? "stable" : "UNSTABLE: ", r->stable ? "" : r->error);
}

static int write_peer_json(const char *path, const char *const *names, int n,
                           const peer_result *res, int threads) {
  char tmp[1100];
  snprintf(tmp, sizeof tmp, "%s.part", path);
  FILE *f = fopen(tmp, "w");
  if (!f)
    return -1;
  const double none[2][2] = {{0.0, 0.0}, {0.0, 0.0}};
  sph_bench_json_head(f, "peer", sysconf(_SC_NPROCESSORS_ONLN), none, 0);
  fprintf(f, "  \"peer_steps\": %d,\n  \"cases\": [", PEER_STEPS);
  for (int i = 0; i < n; ++i) {
    const peer_result *r = &res[i];
    fprintf(f, "%s\n    {\"method\": ", i ? "," : "");
    sph_bench_json_str(f, names[i]);
    fprintf(f,
            ", \"ok\": %s, \"stable\": %s, \"threads\": %d, \"particles\": "
            "%ld, \"steps\": %lu, \"t\": %.6g, \"setup_seconds\": %.6g, "
            "\"step_seconds\": %.6g, \"error\": ",
            r->ok ? "true" : "false", r->stable ? "true" : "false", threads,
            r->particles, r->steps, r->t, r->setup_seconds, r->step_seconds);
    sph_bench_json_str(f, r->error);
    fprintf(f, "}");
  }
  fprintf(f, "\n  ]\n}\n");
  return sph_bench_json_finish(f, tmp, path);
}

int sph_bench_peer(int threads, const char *only, const char *json) {
  const sph_method_ops *const *ops = sph_method_list();
  const char *names[64];
  int n = 0;
  for (int i = 0; ops[i] && n < 64; ++i)
    if (!only || strstr(ops[i]->name, only))
      names[n++] = ops[i]->name;
  if (!n) {
    fprintf(stderr, "sph bench peer: no method is named '%s'\n", only);
    return SPH_EXIT_USAGE;
  }
  peer_result *res = calloc((size_t)n, sizeof *res);
  if (!res)
    return SPH_EXIT_IO;
  printf("sph bench peer: the twisting column (omega 105) at 11x61x11 to "
         "t = 0.5 s, every method at its defaults, %d thread%s\n"
         "  the peer (SPHinXsys test_3d_twisting_column, 6,100 particles): "
         "%d steps, 22.8-26.0 s on one thread of a quiet Xeon (issue 33); "
         "wall times here are this machine's\n",
         threads, threads == 1 ? "" : "s", PEER_STEPS);
  int failed = 0;
  for (int i = 0; i < n; ++i) {
    peer_job job = {names[i], threads};
    int status = 0;
    struct rusage ru;
    int got = sph_bench_in_child(peer_work, &job, &res[i], sizeof res[i],
                                 &status, &ru);
    if (got != 1) {
      memset(&res[i], 0, sizeof res[i]);
      snprintf(res[i].error, sizeof res[i].error,
               "the case's process ended (%s %d)",
               WIFSIGNALED(status) ? "signal" : "status",
               WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status));
    }
    failed |= !res[i].ok;
    print_peer_row(names[i], &res[i]);
    if (sph_bench_interrupted())
      break;
  }
  int rc = failed ? SPH_EXIT_FAIL : SPH_EXIT_OK;
  if (json && write_peer_json(json, names, n, res, threads) != 0) {
    fprintf(stderr, "sph bench: cannot write %s\n", json);
    rc = SPH_EXIT_IO;
  }
  free(res);
  return rc;
}
