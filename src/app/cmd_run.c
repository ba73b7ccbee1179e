/* sph run: load and validate a scene, then simulate it to time.end through
 * the run of include/sph/sph.h (src/solver/run.c), which writes every
 * output; this command adds the command line, the banner, the progress
 * line, the stop signals, the verdict's text and the exit code. Nothing is
 * written until the scene, its particles and its method have all been
 * validated. */
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "app/app_impl.h"
#include "app/progress_impl.h"
#include "scene/scene.h"
#include "solver/run.h"

/* More ranks x threads on this node than cores: each waits for the
 * others' turns (issue 36); said, as the run may be many times slower. */
static void oversubscribed_note(const sph_sim *sim) {
  long cores = sysconf(_SC_NPROCESSORS_ONLN);
  int ranks = sph_domain_node_ranks();
  if (!sim->domain || cores <= 0 || (long)ranks * sim->threads <= cores)
    return;
  printf("  note       %d rank%s x %d thread%s on %ld core%s: oversubscribed "
         "(docs/mpi.md)\n",
         ranks, ranks == 1 ? "" : "s", sim->threads,
         sim->threads == 1 ? "" : "s", cores, cores == 1 ? "" : "s");
}

static void banner(const sph_sim *sim, const char *dir, const sph_halo *h) {
  const sph_scene *s = sim->scene;
  printf("sph: %s (%s)\n", s->name, s->path);
  printf("  method     %s: %s\n             [%s]\n", sim->method->name,
         sim->method->title, sim->method->reference);
  printf("  particles  %zu in %zu bod%s, dp = %.4g m, kernel %s h = %.4g m\n",
         sph_domain_particles(sim->domain, sim->ps), s->nbodies,
         s->nbodies == 1 ? "y" : "ies", sim->dp,
         sph_kernel_type_name(s->kernel_type), sim->kernel.h);
  printf("  terms     ");
  if (!sim->nterms)
    printf(" (none)");
  for (int i = 0; i < sim->nterms; ++i)
    printf(" %s", sim->terms[i].ops->name);
  printf("\n  time       0 .. %.6g s, output every %.6g s, %d thread%s\n",
         s->t_end, s->output.every, sim->threads, sim->threads == 1 ? "" : "s");
  if (sim->domain)
    printf("  ranks      %d (MPI, recursive coordinate bisection): at most "
           "%.0f owned and %.0f ghost particles a rank; halo %.0f particles "
           "in %.0f messages per exchange\n",
           sph_domain_size(sim->domain), h->max_owned, h->max_ghosts, h->values,
           h->messages);
  oversubscribed_note(sim);
  printf("  output     %s/\n", dir);
  fflush(stdout);
}

/* One line: the wall time of each sink and its share of the run's, and
 * the busy time of a sink's own thread (png: the render thread). */
static void print_sink_times(const sph_sink *sinks, int nsinks, double wall) {
  printf("outputs:");
  for (int i = 0; i < nsinks; ++i) {
    printf("%s %s %.2f s (%.1f %%)", i ? "," : "", sinks[i].ops->name,
           sinks[i].seconds,
           wall > 0.0 ? 100.0 * sinks[i].seconds / wall : 0.0);
    if (sinks[i].thread_seconds > 0.0)
      printf(" + render thread %.2f s", sinks[i].thread_seconds);
  }
  printf(" of %.2f s wall\n", wall);
}

static const int run_allowed[] = {
    SPH_OPT_SET,        SPH_OPT_OUT,       SPH_OPT_THREADS,
    SPH_OPT_RESUME_DIR, SPH_OPT_OVERWRITE, SPH_OPT_QUIET,
    SPH_OPT_MAX_MEMORY, SPH_OPT_DEVICE,    0};
static const sph_app_command run_command = {
    "run",
    "usage: sph run [SCENE] [--set key=value]... [--out DIR] [--threads N]\n"
    "               [--overwrite] [--quiet] [--resume DIR] [--max-memory "
    "SIZE]\n"
    "               [--device cpu|cuda]\n"
    "  simulate SCENE (a file, or a shipped scene's name: sph list; default\n"
    "  twisting_column) to its end time; exit 0 stable, 1 unstable, 2 bad\n"
    "  input or usage, 3 I/O failure; a run estimated to need more than\n"
    "  SIZE (4G, 512M; default 90 % of the memory available) is refused;\n"
    "  --device cuda (the scene's device: cuda) steps on the GPU, refused\n"
    "  (exit 2, nothing written) without CUDA, a GPU, or a GPU path for the\n"
    "  method and its terms (docs/gpu.md)\n",
    run_allowed, NULL, NULL};

/* SIGINT, SIGTERM, SIGHUP, SIGUSR1 (which mpirun forwards to the ranks
 * without ending them): the first asks the run to stop at the next step
 * boundary (outputs finished, a checkpoint, summary.json with stopped_by);
 * a second one ends the process at once. */
static volatile sig_atomic_t stop_signal;

static void on_stop_signal(int signo) {
  if (stop_signal) {
    signal(signo, SIG_DFL);
    raise(signo);
    return;
  }
  stop_signal = signo;
}

static void catch_stop_signals(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  sigaction(SIGHUP, &sa, NULL);
  sigaction(SIGUSR1, &sa, NULL);
}

static void on_step(void *ctx, double t, unsigned long steps) {
  sph_progress_step(ctx, t, steps);
}

static void on_output(void *ctx, double t, unsigned long steps) {
  sph_progress_output(ctx, t, steps);
}

/* loads the scene and sets the run up to its first frame, printing the
 * banner between the folder's checks and the sinks; 0 or the exit code */
static int run_open(const sph_app_args *args, const char *path,
                    sph_scene **scene, sph_run **run, sph_progress *prog) {
  sph_error err;
  sph_error_clear(&err);
  sph_provenance prov;
  sph_app_provenance(&prov);
  sph_run_hooks hooks = {.ctx = prog,
                         .step = on_step,
                         .output = on_output,
                         .command = prov.command};
  const char *given = args->resume ? args->resume : args->out;
  sph_run_options opt = {.out_dir = given,
                         .overwrite = args->overwrite,
                         .resume = args->resume != NULL,
                         .threads = args->threads,
                         .quiet = args->quiet,
                         .stop = &stop_signal};
  sph_status st = sph_scene_load(scene, path, args->sets, args->nsets, &err);
  if (st == SPH_OK) {
    (*scene)->memory_limit = args->max_memory;
    st = sph_run_open(run, *scene, &opt, &hooks, &err);
  }
  if (st != SPH_OK) { /* out of memory: 3, as a run's (issue 36) */
    sph_app_print_load_error(&err, args->sets, args->nsets);
    return st == SPH_ERR_NOMEM ? SPH_EXIT_IO : SPH_EXIT_USAGE;
  }
  if (args->resume && args->out && strcmp(args->resume, args->out)) {
    fprintf(stderr, "sph: --resume continues in its own folder; drop --out "
                    "or give the same folder\n");
    return SPH_EXIT_USAGE;
  }
  if (given && strlen(given) > 900) { /* room for the files' own names */
    fprintf(stderr,
            "sph: the output folder's path is %zu bytes long; at "
            "most 900\n",
            strlen(given));
    return SPH_EXIT_USAGE;
  }
  /* a stop before the folder is touched: nothing written, nothing to do */
  int early = (int)sph_domain_max(sph_run_sim(*run)->domain, stop_signal);
  if (early) {
    printf("stopped by %s before anything was written\n",
           early == SIGINT    ? "SIGINT"
           : early == SIGTERM ? "SIGTERM"
           : early == SIGHUP  ? "SIGHUP"
                              : "a signal");
    return 128 + early;
  }
  if (sph_run_folder(*run, &err) != SPH_OK) {
    sph_app_print_error(&err);
    return sph_app_exit_code(err.code); /* 3: the manifest not written */
  }
  if (!args->quiet)
    banner(sph_run_view(*run), sph_run_dir(*run), sph_run_halo(*run));
  if (sph_run_start(*run, &err) != SPH_OK) {
    sph_app_print_error(&err);
    return SPH_EXIT_USAGE; /* the checkpoint is the run's input */
  }
  int next = 0;
  const char *used = sph_run_resumed_from(*run, &next);
  const sph_sim *sim = sph_run_sim(*run);
  if (args->resume && !args->quiet)
    printf("  resume     %s: t = %.6g s, step %lu, next output %d\n", used,
           sim->t, sim->steps, next);
  return SPH_EXIT_OK;
}

/* the verdict's line and the exit code */
static int print_verdict(sph_run *run, const sph_summary *sum,
                         const sph_run_report *r, const sph_error *err) {
  if (r->io_failed) {
    sph_app_print_error(err);
    return sph_app_exit_code(err->code);
  }
  if (r->stop_signal) {
    printf("stopped by %s at t = %.6g s (%lu steps, %.2f s wall): outputs "
           "and a checkpoint written; continue with --resume %s\n",
           r->stopped_by, sum->t, sum->steps, r->wall, sph_run_dir(run));
    return 128 + r->stop_signal;
  }
  if (!sph_run_verdict(run)->stable) {
    printf("verdict: %s (%lu steps, %.2f s wall)\n", sum->verdict, sum->steps,
           r->wall);
    return SPH_EXIT_FAIL;
  }
  printf("verdict: stable (%lu steps, %.2f s wall, %.3g particle-steps/s)\n",
         sum->steps, r->wall, sum->particle_steps);
  return SPH_EXIT_OK;
}

/* the outputs' times, MPI's statistics and the mp4 */
static void print_outputs(const sph_run_report *r, const sph_sim *sim,
                          int quiet) {
  if (!r->io_failed && !quiet)
    print_sink_times(r->sinks, r->nsinks, r->wall);
  if (sim->domain && !quiet)
    printf("mpi: %d ranks; exchanges and reductions at most %.2f s of a "
           "rank's wall (waits included), the rest at most %.2f s\n",
           sph_domain_size(sim->domain), r->comm, r->work);
  sph_domain_moves mv = sph_domain_moves_of(sim->domain);
  if (mv.rebuilds > 0.0 && !quiet)
    printf("mpi: %.0f halo rebuilds, %.0f particles migrated, %.0f "
           "re-balances (over %.0f %% imbalance); at most %.0f ghost "
           "particles a rank, %.0f particles a halo exchange\n",
           mv.rebuilds, mv.migrated, mv.rebalances,
           100.0 * SPH_DOMAIN_IMBALANCE, mv.ghosts_max, mv.halo_max);
  const sph_mp4_info *mp4 = &r->mp4;
  if (r->mp4_tried && r->mp4_status == SPH_OK)
    printf("mp4: %s (%d frames, %.1f s at %g fps, %s)\n", mp4->path,
           mp4->frames, mp4->frames / mp4->fps, mp4->fps, mp4->codec);
  else if (r->mp4_tried && r->mp4_status == SPH_ERR_UNSUPPORTED)
    printf("mp4 skipped: ffmpeg not found\n");
  else if (r->mp4_tried) {
    char msg[1024];
    sph_error_format(&r->mp4_err, msg, sizeof msg);
    fprintf(stderr, "sph: warning: no mp4: %s\n", msg);
  }
}

int sph_cmd_run(int argc, char **argv) {
  sph_app_args args;
  int rc = sph_app_parse_args(argc, argv, &args, &run_command);
  if (rc != SPH_EXIT_OK)
    return rc == SPH_APP_HELP ? SPH_EXIT_OK : rc;
  const char *path = args.scene ? args.scene : sph_app_default_scene();
  /* over MPI ranks rank 0 prints for all */
  int root = sph_domain_world_rank() == 0;
  if (!root && !freopen("/dev/null", "w", stdout))
    return SPH_EXIT_IO;
  sph_scene *scene = NULL;
  sph_run *run = NULL;
  sph_progress prog;
  /* first: a stop while the scene loads or the folder is made is a stop
   * like any other (issue 36 item 5); over MPI ranks every rank catches
   * them and they agree on stopping */
  catch_stop_signals();
  rc = run_open(&args, path, &scene, &run, &prog);
  if (rc == SPH_EXIT_OK) {
    sph_progress_start(&prog, scene->t_end, args.quiet || !root);
    sph_error err;
    sph_error_clear(&err);
    sph_run_advance(run, scene->t_end, &err); /* close reports a failure */
    sph_progress_finish(&prog);
    sph_summary sum;
    sph_run_close(run, &sum, &err);
    const sph_run_report *r = sph_run_report_of(run);
    rc = print_verdict(run, &sum, r, &err);
    print_outputs(r, sph_run_sim(run), args.quiet);
    rc = sph_domain_bcast_int(sph_run_sim(run)->domain, rc); /* rank 0's */
  }
  sph_run_destroy(run); /* the folder is free for the next run */
  sph_scene_destroy(scene);
  return rc;
}
