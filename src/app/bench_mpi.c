/* sph bench --mpi: one case, the tl-csph twisting column, run in this
 * process over the ranks its launcher started (mpirun -np N sph bench
 * --mpi; one rank without a launcher), with the halo traffic and the time
 * in exchanges added to the figures. */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "app/app_impl.h"
#include "app/bench_impl.h"
#include "parallel/domain.h"
#include "scene/scene.h"
#include "solver/run.h"

/* --mpi: the tl-csph column at 202,771 particles, as docs/results.md's
 * 1 -> 2 rank scaling (full: 100 steps, quick: 10) */
static const bench_case mpi_cases[2] = {
    {"twisting column tl-csph over MPI ranks",
     "twisting_column",
     {"bodies.0.particles.count=[31,211,31]", "method={name: tl-csph}"},
     100,
     0},
    {"twisting column tl-csph over MPI ranks",
     "twisting_column",
     {"bodies.0.particles.count=[31,211,31]", "method={name: tl-csph}"},
     10,
     0},
};

/* what --mpi measured (the slowest rank's times, the sums' traffic) */
typedef struct mpi_result {
  long particles, steps;
  double setup, first, wall, comm, values, messages, rss_mb;
  sph_halo halo;
} mpi_result;

/* the case on this process's rank; collective over the ranks */
static sph_status mpi_measure(const bench_case *c, int weak, mpi_result *m,
                              sph_error *err) {
  const char *sets[BENCH_MAX_SETS + 8];
  size_t n = 0;
  for (int i = 0; i < BENCH_MAX_SETS && c->sets[i]; ++i)
    sets[n++] = c->sets[i];
  /* weak: 101,866 particles a rank, the column 3 m a rank tall at the
   * strong case's spacing */
  char count[64], height[64];
  int R = sph_domain_world_size();
  snprintf(count, sizeof count, "bodies.0.particles.count=[31,%d,31]",
           105 * R + 1);
  snprintf(height, sizeof height, "bodies.0.shape.box.max=[0.5,%d,0.5]", 3 * R);
  if (weak) {
    sets[0] = count;
    sets[n++] = height;
  }
  for (size_t i = 0; i < SPH_BENCH_OUTPUTS_OFF; ++i)
    sets[n++] = sph_bench_outputs_off[i];
  char path[1024];
  snprintf(path, sizeof path, "%s/%s.yaml", sph_app_scenes_dir(), c->scene);
  sph_scene *scene = NULL;
  sph_run *run = NULL;
  double t0 = sph_wtime();
  sph_status st = sph_scene_load(&scene, path, sets, n, err);
  sph_run_options opt = {.no_files = 1};
  if (st == SPH_OK) /* errors before and in the partition: on every rank */
    st = sph_run_create(&run, scene, &opt, err);
  if (st == SPH_OK) {
    sph_sim *sim = sph_run_sim(run);
    sph_domain *d = sim->domain;
    m->setup = sph_domain_max(d, sph_wtime() - t0);
    t0 = sph_wtime(); /* first touch of the work arrays, timed apart */
    st = sph_bench_steps(run, 1, err);
    m->first = sph_domain_max(d, sph_wtime() - t0);
    double v0, k0, v1, k1, comm0 = sph_domain_seconds(d);
    sph_domain_traffic(d, &v0, &k0);
    t0 = sph_wtime();
    if (st == SPH_OK)
      st = sph_bench_steps(run, (unsigned long)c->steps, err);
    m->wall = sph_domain_max(d, sph_wtime() - t0);
    m->comm = sph_domain_max(d, sph_domain_seconds(d) - comm0);
    m->steps = c->steps;
    sph_domain_traffic(d, &v1, &k1);
    double sums[3] = {v1 - v0, k1 - k0, (double)sim->ps->n};
    sph_domain_sum(d, sums, 3);
    m->values = sums[0] / (double)c->steps;
    m->messages = sums[1] / (double)c->steps;
    m->particles = (long)sums[2];
    m->halo = sph_domain_halo(d);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    m->rss_mb = sph_domain_max(d, (double)ru.ru_maxrss / 1024.0);
  }
  sph_run_destroy(run);
  sph_scene_destroy(scene);
  return st;
}

static int mpi_json(const char *path, const bench_case *c, const mpi_result *m,
                    int quick, int weak, int ranks, int threads) {
  char tmp[1100];
  snprintf(tmp, sizeof tmp, "%s.part", path);
  FILE *f = fopen(tmp, "w");
  if (!f)
    return -1;
  sph_bench_json_head(f, quick ? "mpi-quick" : "mpi",
                      sysconf(_SC_NPROCESSORS_ONLN), NULL, 0);
  fprintf(f, "  \"scaling\": \"%s\",\n  \"cases\": [\n    {\"name\": ",
          weak ? "weak" : "strong");
  sph_bench_json_str(f, c->name);
  fprintf(f,
          ", \"ok\": true, \"ranks\": %d, \"threads\": %d, "
          "\"particles\": %ld, \"steps\": %ld, \"setup_seconds\": %.6g, "
          "\"first_step_seconds\": %.6g, \"step_seconds\": %.6g, "
          "\"particle_steps_per_second\": %.6g, "
          "\"exchange_seconds\": %.6g, \"halo_values_per_step\": %.6g, "
          "\"halo_messages_per_step\": %.6g, \"max_owned\": %.0f, "
          "\"max_ghosts\": %.0f, \"peak_rss_mb_per_rank\": %.3f}\n  ]\n}\n",
          ranks, threads, m->particles, m->steps, m->setup, m->first, m->wall,
          (double)m->particles * (double)m->steps / m->wall, m->comm, m->values,
          m->messages, m->halo.max_owned, m->halo.max_ghosts, m->rss_mb);
  return sph_bench_json_finish(f, tmp, path);
}

/* sph bench --mpi: rank 0 prints and writes the JSON */
int sph_bench_mpi(int quick, int weak, int threads, const char *json) {
  const bench_case *c = &mpi_cases[quick];
  int root = sph_domain_world_rank() == 0, ranks = sph_domain_world_size();
  if (!root && !freopen("/dev/null", "w", stdout))
    return SPH_EXIT_IO;
  omp_set_num_threads(threads);
  printf("sph bench --mpi (%s%s): %s, %ld steps on %d rank%s of %d "
         "thread%s, %ld cores here\n",
         quick ? "quick" : "full",
         weak ? ", weak: 31 x (105 N + 1) x 31" : ", strong: 31 x 211 x 31",
         c->name, c->steps, ranks, ranks == 1 ? " (no launcher)" : "s (MPI)",
         threads, threads == 1 ? "" : "s", sysconf(_SC_NPROCESSORS_ONLN));
  fflush(stdout);
  mpi_result m;
  memset(&m, 0, sizeof m);
  sph_error err;
  sph_error_clear(&err);
  if (mpi_measure(c, weak, &m, &err) != SPH_OK) {
    sph_app_print_error(&err);
    return SPH_EXIT_FAIL;
  }
  double rate = (double)m.particles * (double)m.steps / m.wall;
  printf("  %ld particles, %ld steps: %.3f s, %.4g particle-steps/s (%.4g a "
         "rank); set-up %.2f s, first step %.3f s\n",
         m.particles, m.steps, m.wall, rate, rate / ranks, m.setup, m.first);
  if (ranks > 1)
    printf("  halo: at most %.0f owned and %.0f ghost particles a rank; %.0f "
           "values (%.0f kB) in %.0f messages per step\n",
           m.halo.max_owned, m.halo.max_ghosts, m.values, 8e-3 * m.values,
           m.messages);
  printf("  exchanges and reductions: at most %.3f s of a rank's %.3f s "
         "(%.1f %%, waits included); peak resident set %.0f MB a rank\n",
         m.comm, m.wall, 100.0 * m.comm / m.wall, m.rss_mb);
  if (ranks == 1)
    printf("  no halo on one rank; over N ranks: mpirun -np N sph bench "
           "--mpi%s (or srun)\n",
           quick ? " --quick" : "");
  int rc = SPH_EXIT_OK;
  if (root && json && mpi_json(json, c, &m, quick, weak, ranks, threads) != 0) {
    fprintf(stderr, "sph bench: cannot write %s\n", json);
    rc = SPH_EXIT_IO;
  }
  return rc;
}
