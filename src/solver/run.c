/* The run (include/sph/sph.h; docs/design.md sec. 1-2): the loop over a scene's
 * output times that `sph run`, sph bench, the stability tests and embedding
 * programs share. It steps the method, lands exactly on every output time,
 * hands each frame to the sinks of the registry (io/sink_list.h) and to the
 * stability verdict, writes checkpoints at their cadence, stops at a step
 * boundary when asked, and on close finishes the files, computes the errors
 * against the scene's reference, assembles the mp4 and writes
 * summary.json. Over MPI ranks every call is collective. */
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/checkpoint.h"
#include "solver/device.h"
#include "solver/run_impl.h"

static double run_eps(const sph_run *run) { return 1e-12 * run->scene->t_end; }

/* the output frame `index`'s time: the scene's, or every hooks.every s */
static double output_time(const sph_run *run, int index) {
  if (run->hooks.every > 0.0)
    return fmin(run->scene->t_end, run->hooks.every * index);
  return sph_output_time(run->scene, index);
}

static int is_piece(const sph_run *run, const sph_sink *sink) {
  return run->sim->domain && sink->ops->distributed;
}

/* the sinks of the registry the scene asks for (none without files) */
static sph_status sinks_create(sph_run *run, sph_error *err) {
  const sph_sink_ops *const *list = sph_sink_list();
  int n = 0;
  for (int i = 0; list[i]; ++i)
    n += !run->opt.no_files && list[i]->enabled(run->scene);
  run->sinks = calloc((size_t)n + 1, sizeof *run->sinks);
  if (!run->sinks)
    return sph_error_set(err, SPH_ERR_NOMEM, "sinks");
  for (int i = 0; list[i]; ++i)
    if (!run->opt.no_files && list[i]->enabled(run->scene))
      run->sinks[run->nsinks++] = (sph_sink){.ops = list[i]};
  return SPH_OK;
}

sph_status sph_run_open(sph_run **out, const sph_scene *scene,
                        const sph_run_options *options,
                        const sph_run_hooks *hooks, sph_error *err) {
  *out = NULL;
  sph_run *run = calloc(1, sizeof *run);
  if (!run)
    return sph_error_set(err, SPH_ERR_NOMEM, "run");
  run->scene = scene;
  if (options)
    run->opt = *options;
  if (hooks)
    run->hooks = *hooks;
  run->lock_fd = -1;
  run->root = sph_domain_world_rank() == 0;
  if (run->opt.threads > 0)
    omp_set_num_threads(run->opt.threads);
  /* device: cuda refused before the particles are built, and before
   * anything is written */
  sph_status st = sph_device_available(scene, err);
  if (st == SPH_OK)
    st = sph_sim_create(&run->sim, scene, err);
  if (st == SPH_OK)
    st = sph_device_attach(run->sim, err);
  if (st == SPH_OK && !run->opt.no_files) /* no frames without files */
    st = sph_png_check(run->sim, err);
  if (st == SPH_OK)
    st = sinks_create(run, err);
  if (st == SPH_OK) {
    size_t cap = run->sim->ps->capacity;
    run->scratch = malloc((2 * cap + 1) * sizeof *run->scratch);
    if (!run->scratch)
      st = sph_error_set(err, SPH_ERR_NOMEM, "run");
  }
  if (st != SPH_OK) {
    sph_run_destroy(run);
    return st;
  }
  run->view = *run->sim;
  run->whole = run->sim->domain ? &run->view : run->sim;
  *out = run;
  return SPH_OK;
}

int sph_run_frame_count(const sph_run *run) {
  int n = 0;
  while (n < 100000 && output_time(run, n) < run->scene->t_end - run_eps(run))
    ++n;
  return n + 1;
}

/* rank 0 makes, locks and checks the folder for every rank */
static sph_status folder_check(sph_run *run, sph_error *err) {
  const char *given = run->opt.out_dir;
  if (given && strlen(given) > 900) /* room for the files' own names */
    return sph_error_set(err, SPH_ERR_ARG,
                         "the output folder's path is %zu bytes long; at "
                         "most 900",
                         strlen(given));
  if (given)
    snprintf(run->dir, sizeof run->dir, "%s", given);
  else
    snprintf(run->dir, sizeof run->dir, "outputs/%s", run->scene->name);
  if (!run->root)
    return SPH_OK;
  struct stat rst;
  sph_status st;
  if (run->opt.resume && stat(run->dir, &rst) != 0) /* not made to resume */
    return sph_error_set(err, SPH_ERR_ARG, "nothing to resume in %s: %s",
                         run->dir, strerror(errno));
  /* a folder that cannot be made or written in: bad input either way */
  SPH_TRY(sph_run_output_dir(run->dir, err));
  SPH_TRY(sph_run_lock(run, err));
  /* after the lock: a folder in use says so, whatever it holds */
  st = SPH_OK;
  if (!run->opt.overwrite && !run->opt.resume &&
      (sph_run_file_exists(run->dir, "summary.json") ||
       sph_run_file_exists(run->dir, "scene_used.yaml")))
    st = sph_error_set(
        err, SPH_ERR_ARG,
        "%s holds the results of an earlier run; pass %s--overwrite to "
        "replace them or --out DIR to write elsewhere",
        run->dir,
        sph_run_file_exists(run->dir, SPH_CHECKPOINT_FILE)
            ? "--resume to continue it if it stopped, "
            : "");
  /* then only files of earlier runs (their manifest) are replaced */
  if (st == SPH_OK)
    st = sph_run_manifest_start(
        run->dir, run->scene, sph_run_frame_count(run),
        run->sim->domain ? sph_domain_size(run->sim->domain) : 1,
        run->opt.overwrite && !run->opt.resume, err);
  return st;
}

sph_status sph_run_folder(sph_run *run, sph_error *err) {
  sph_sim *sim = run->sim;
  sph_status st = SPH_OK;
  if (!run->opt.no_files)
    st = folder_check(run, err);
  SPH_TRY(sph_domain_agree(sim->domain, st, err));
  if (run->opt.no_files)
    return SPH_OK;
  run->halo = sph_domain_halo(sim->domain); /* collective */
  /* rank 0's probes' particles, from their owners */
  if (sim->domain && run->scene->output.nprobes) {
    SPH_TRY(sph_probe_view_create(&run->pv, sim, err));
    if (run->root)
      run->view.ps = run->pv.ps;
  }
  return SPH_OK;
}

/* the sinks' open hooks (pieces on every rank, the rest on rank 0) */
static sph_status sinks_open(sph_run *run, sph_error *err) {
  sph_status st = SPH_OK;
  for (int i = 0; i < run->nsinks && st == SPH_OK; ++i) {
    sph_sink *s = &run->sinks[i];
    int piece = is_piece(run, s);
    if (!run->root && !piece)
      continue;
    double t0 = sph_wtime();
    s->resume_frames = run->index;
    st = s->ops->open(s, piece ? run->sim : run->whole, run->dir, err);
    s->seconds += sph_wtime() - t0;
  }
  return sph_domain_agree(run->sim->domain, st, err);
}

/* whether the checkpoint resumed from is one the cadence wrote (its step
 * passed a multiple of checkpoint_every), not a stop's */
static int on_cadence(const sph_run *run) {
  double every = run->scene->output.checkpoint_every, eps = run_eps(run);
  double t = run->sim->t, t0 = t - run->sim->dt_last;
  return every > 0.0 && floor((t + eps) / every) > floor((t0 + eps) / every);
}

sph_status sph_run_start(sph_run *run, sph_error *err) {
  sph_sim *sim = run->sim;
  SPH_TRY(sph_verdict_create(&run->verdict, sim, err)); /* collective */
  if (run->opt.resume && !run->opt.no_files) {
    SPH_TRY(sph_checkpoint_resume(run->dir, sim, run->verdict, &run->index,
                                  run->resumed, sizeof run->resumed, err));
    run->ckpt_replace = !on_cadence(run);
  }
  run->started = 1;
  if (run->opt.no_files)
    return SPH_OK;
  /* from here a failure ends the run with its outputs closed (advance and
   * close report it) */
  if (run->root)
    run->st = sph_run_write_scene_used(run, &run->err);
  if (run->st == SPH_OK)
    run->st = sinks_open(run, &run->err);
  else
    run->st = sph_domain_agree(sim->domain, run->st, &run->err);
  return SPH_OK;
}

/* derive, then every sink and the verdict see the same frame; over MPI
 * ranks the energies and momenta are summed over them, every rank judges
 * its particles for the verdict and draws its part of the PNG frame, and
 * rank 0's sinks see the view, the run with its probes' particles */
static sph_status output_frame(sph_run *run, int index, sph_error *err) {
  sph_sim *sim = run->sim, *view = &run->view;
  sph_status st = sim->method->derive(sim, err);
  if ((st = sph_domain_agree(sim->domain, st, err)) != SPH_OK)
    return st;
  double momentum[6];
  sph_frame fr = {.time = sim->t,
                  .step = sim->steps,
                  .index = index,
                  .sim = sim,
                  .ps = sim->ps,
                  .momentum = momentum};
  sim->method->energy(sim, &fr.kinetic, &fr.strain);
  sph_momentum(sim->ps, momentum, momentum + 3);
  sph_frame whole = fr;
  int root = sph_domain_rank(sim->domain) == 0;
  if (sim->domain) {
    double e[2] = {fr.kinetic, fr.strain};
    sph_domain_sum(sim->domain, e, 2);
    sph_domain_sum(sim->domain, momentum, 6);
    fr.kinetic = whole.kinetic = e[0];
    fr.strain = whole.strain = e[1];
    if (run->pv.ps)
      SPH_TRY(sph_probe_view_fill(&run->pv, sim, 0, err));
    if (root) {
      sph_particles *all = view->ps;
      *view = *sim;
      view->ps = all;
      whole.sim = view;
      whole.ps = all;
    }
  }
  for (int i = 0; i < run->nsinks; ++i) {
    sph_sink *s = &run->sinks[i];
    int piece = is_piece(run, s);
    if ((st != SPH_OK && !piece) || (!root && !piece))
      continue; /* pieces are collective: every rank writes its own */
    double t0 = sph_wtime();
    sph_status sst = s->ops->write(s, piece ? &fr : &whole, err);
    st = st == SPH_OK ? sst : st;
    s->seconds += sph_wtime() - t0;
  }
  /* the verdict is collective: every rank observes once the sinks agree */
  st = sph_domain_agree(sim->domain, st, err);
  if (st == SPH_OK)
    st = sph_verdict_observe(run->verdict, &fr, err);
  if (st == SPH_OK && sim->reference) /* collective: from its owner */
    sph_reference_observe(sim->reference, &fr);
  st = sph_domain_agree(sim->domain, st, err);
  run->derived = 1;
  if (st == SPH_OK && run->hooks.frame)
    run->hooks.frame(run, &fr, run->hooks.ctx);
  return st;
}

/* an I/O failure or a broken invariant of the code (src/core/check.h) ends
 * the run as failed, with no verdict */
static int run_broken(sph_status st) {
  return st == SPH_ERR_IO || st == SPH_ERR_INTERNAL;
}

/* a failed step or output: a broken run ends as failed, any other failure
 * trips the verdict's step (or nan) indicator */
static void run_fail(sph_run *run) {
  if (run->st != SPH_OK && !run_broken(run->st))
    sph_verdict_fail_step(run->verdict, run->sim->t, &run->err);
}

/* the first output frame (t = 0; none after a resume) and the clocks */
static void run_begin(sph_run *run) {
  sph_sim *sim = run->sim;
  run->begun = 1;
  run->wall0 = sph_wtime();
  run->comm0 = sph_domain_seconds(sim->domain);
  if (run->st == SPH_OK && run->index == 0)
    run->st = output_frame(run, run->index++, &run->err);
  double ckpt = run->scene->output.checkpoint_every;
  run->next_ckpt =
      ckpt > 0.0 ? ckpt * (floor(sim->t / ckpt + 1e-9) + 1.0) : INFINITY;
  run_fail(run);
}

/* rows written so far reach the disk (before a checkpoint) */
static sph_status sinks_flush(sph_run *run, int timed, sph_error *err) {
  sph_status st = SPH_OK;
  for (int i = 0; i < run->nsinks && st == SPH_OK; ++i) {
    sph_sink *s = &run->sinks[i];
    if (!s->ops->flush || !(run->root || is_piece(run, s)))
      continue;
    double t0 = sph_wtime();
    st = s->ops->flush(s, err);
    if (timed)
      s->seconds += sph_wtime() - t0;
  }
  return sph_domain_agree(run->sim->domain, st, err);
}

/* the stop flag, agreed over the ranks (collective when there is one) */
static int stop_asked(const sph_run *run) {
  return run->opt.stop ? (int)sph_domain_max(run->sim->domain, *run->opt.stop)
                       : 0;
}

static int run_going(const sph_run *run) {
  return run->st == SPH_OK && !run->stopped && !run->closed &&
         (run->verdict->stable || run->hooks.keep_going);
}

/* one step and what follows it: the output frame it lands on, the
 * checkpoint whose time it passed */
static sph_status step_once(sph_run *run, sph_error *err) {
  sph_sim *sim = run->sim;
  double eps = run_eps(run), t_end = run->scene->t_end;
  double next = output_time(run, run->index);
  int at_steps = run->hooks.at_steps || run->scene->output.at_steps;
  SPH_TRY(sph_sim_step(sim, (at_steps ? t_end : next) - sim->t, err));
  run->derived = 0;
  if (run->hooks.step)
    run->hooks.step(run->hooks.ctx, sim->t, sim->steps);
  sph_status st = SPH_OK;
  if (sim->t >= next - eps) {
    if (!at_steps)
      sim->t = next; /* land exactly on the output time */
    else if (sim->t >= t_end - eps)
      sim->t = t_end;
    /* at_steps: a frame for every output time this step reached */
    do {
      st = output_frame(run, run->index++, err);
      if (run->hooks.output)
        run->hooks.output(run->hooks.ctx, sim->t, sim->steps);
    } while (st == SPH_OK && at_steps &&
             run->index < sph_run_frame_count(run) &&
             output_time(run, run->index) <= sim->t + eps);
  }
  if (st == SPH_OK && !run->opt.no_files && sim->t >= run->next_ckpt - eps &&
      sim->t < t_end - eps) {
    double ckpt = run->scene->output.checkpoint_every;
    st = sinks_flush(run, 1, err);
    if (st == SPH_OK)
      st = sph_checkpoint_write_as(run->dir, sim, run->verdict, run->index,
                                   run->ckpt_replace, err);
    run->ckpt_replace = 0;
    run->next_ckpt += ckpt * floor((sim->t - run->next_ckpt) / ckpt + 1.0);
  }
  return st;
}

/* stopped between steps: what was written reaches the disk, then a
 * checkpoint to resume from */
static void run_stop(sph_run *run, int value) {
  run->stopped = value;
  if (run->opt.no_files)
    return;
  run->st = sinks_flush(run, 0, &run->err);
  if (run->st == SPH_OK)
    run->st = sph_checkpoint_write_as(run->dir, run->sim, run->verdict,
                                      run->index, run->ckpt_replace, &run->err);
  run->ckpt_replace = 1; /* off the cadence: the next one replaces it */
}

/* a started, open run with its first output frame written */
static sph_status run_ready(sph_run *run, sph_error *err) {
  if (!run->started || run->closed)
    return sph_error_set(err, SPH_ERR_ARG,
                         run->closed ? "the run is closed"
                                     : "the run was not started");
  if (!run->begun)
    run_begin(run);
  return SPH_OK;
}

/* the loop over output times to t_stop or for max_steps steps */
static sph_status run_loop(sph_run *run, double t_stop, unsigned long max_steps,
                           sph_error *err) {
  SPH_TRY(run_ready(run, err));
  sph_sim *sim = run->sim;
  double eps = run_eps(run), t_end = run->scene->t_end;
  if (run_going(run)) {
    for (unsigned long k = 0;
         run->st == SPH_OK && (run->verdict->stable || run->hooks.keep_going) &&
         sim->t < t_stop - eps && k < max_steps && !stop_asked(run);
         ++k)
      run->st = step_once(run, &run->err);
    int stop = stop_asked(run);
    if (stop && run->st == SPH_OK && sim->t < t_end - eps)
      run_stop(run, stop);
    run_fail(run);
  }
  if (run_broken(run->st)) {
    if (err)
      *err = run->err;
    return run->st;
  }
  return SPH_OK;
}

sph_status sph_sim_advance(sph_sim *sim, double t_until,
                           unsigned long max_steps, sph_error *err) {
  double eps = 1e-12 * fabs(t_until);
  for (unsigned long k = 0; k < max_steps && sim->t < t_until - eps; ++k)
    SPH_TRY(sph_sim_step(sim, t_until - sim->t, err));
  return SPH_OK;
}

sph_status sph_run_advance(sph_run *run, double t_until, sph_error *err) {
  return run_loop(run, fmin(t_until, run->scene->t_end), (unsigned long)-1,
                  err);
}

sph_status sph_run_advance_steps(sph_run *run, unsigned long steps,
                                 sph_error *err) {
  return run_loop(run, run->scene->t_end, steps, err);
}

sph_status sph_run_create(sph_run **out, const sph_scene *scene,
                          const sph_run_options *options, sph_error *err) {
  return sph_run_create_hooked(out, scene, options, NULL, err);
}

sph_status sph_run_create_hooked(sph_run **out, const sph_scene *scene,
                                 const sph_run_options *options,
                                 const sph_run_hooks *hooks, sph_error *err) {
  sph_run *run = NULL;
  *out = NULL;
  sph_status st = sph_run_open(&run, scene, options, hooks, err);
  if (st == SPH_OK)
    st = sph_run_folder(run, err);
  if (st == SPH_OK)
    st = sph_run_start(run, err);
  if (st == SPH_OK)
    run_begin(run);
  if (st == SPH_OK && run_broken(run->st)) {
    st = run->st;
    if (err)
      *err = run->err;
  }
  if (st != SPH_OK) {
    sph_run_destroy(run);
    return st;
  }
  *out = run;
  return SPH_OK;
}

static const char *signal_name(int signo) {
  return signo == SIGINT             ? "SIGINT"
         : signo == SIGTERM          ? "SIGTERM"
         : signo == SIGHUP           ? "SIGHUP"
         : signo == SIGUSR1          ? "SIGUSR1"
         : signo < 0                 ? "sph_run_close"
         : signo == SPH_STOP_REQUEST ? "request"
                                     : "a signal";
}

sph_run_state sph_run_state_of(const sph_run *run) {
  if (run_broken(run->st) || run->report.io_failed)
    return SPH_RUN_FAILED;
  if (run->verdict && !run->verdict->stable)
    return SPH_RUN_UNSTABLE;
  if (run->st != SPH_OK)
    return SPH_RUN_FAILED;
  if (run->stopped)
    return SPH_RUN_STOPPED;
  if (run->sim->t >= run->scene->t_end - run_eps(run))
    return SPH_RUN_COMPLETED;
  return SPH_RUN_GOING;
}

/* the sinks' close hooks (files renamed into place), then destroy */
static void sinks_close(sph_run *run, sph_run_report *r) {
  sph_error cerr;
  for (int i = 0; i < run->nsinks; ++i) {
    sph_sink *s = &run->sinks[i];
    double t0 = sph_wtime();
    s->stopping = run->stopped != 0 && run->st == SPH_OK;
    if (s->data && !r->io_failed && s->ops->close(s, &cerr) != SPH_OK) {
      r->io_failed = 1;
      run->err = cerr;
    }
    if (s->ops->destroy)
      s->ops->destroy(s);
    s->seconds += sph_wtime() - t0;
  }
}

/* summary.json (rank 0): the counts and timers of the end of the run */
static void summary_write(sph_run *run, sph_run_report *r, int completed) {
  char spath[1200];
  snprintf(spath, sizeof spath, "%s/summary.json", run->dir);
  sph_provenance prov;
  sph_run_provenance(run, &prov);
  sph_particles *all = run->view.ps;
  run->view = *run->sim;
  run->view.ps = all;
  sph_error cerr;
  if (sph_summary_write(spath, run->whole, &prov, run->verdict,
                        run->sim->reference ? &run->ref_err : NULL, r->wall,
                        run->sinks, run->nsinks,
                        r->mp4_tried && r->mp4_status == SPH_OK ? r->mp4.seconds
                                                                : -1.0,
                        completed, r->stopped_by, &cerr) != SPH_OK) {
    r->io_failed = 1;
    run->err = cerr;
  }
}

static void summary_fill(const sph_run *run, sph_summary *out) {
  const sph_sim *sim = run->sim;
  const sph_verdict *v = run->verdict;
  memset(out, 0, sizeof *out);
  out->state = sph_run_state_of(run);
  out->t = sim->t;
  out->steps = sim->steps;
  out->wall = run->report.wall;
  out->particle_steps =
      out->wall > 0
          ? (double)sim->steps *
                (double)sph_domain_particles(sim->domain, sim->ps) / out->wall
          : 0.0;
  if (v->stable)
    snprintf(out->verdict, sizeof out->verdict, "stable");
  else
    snprintf(out->verdict, sizeof out->verdict,
             "UNSTABLE - %s tripped at t = %.6g s: %s",
             sph_indicator_key(v->first), v->t_tripped, v->reason);
  snprintf(out->method, sizeof out->method, "%s", sim->method->name);
  snprintf(out->reference, sizeof out->reference, "%s", sim->method->reference);
  snprintf(out->out_dir, sizeof out->out_dir, "%s", run->dir);
}

sph_status sph_run_close(sph_run *run, sph_summary *summary, sph_error *err) {
  SPH_TRY(run_ready(run, err));
  sph_sim *sim = run->sim;
  const sph_scene *s = run->scene;
  /* closed before its end: as if stopped */
  if (run_going(run) && sim->t < s->t_end - run_eps(run))
    run_stop(run, -1);
  run->closed = 1;
  sph_run_report *r = &run->report;
  int completed = run->st == SPH_OK && run->verdict->stable && !run->stopped;
  r->stop_signal = run->stopped;
  r->stopped_by = run->stopped ? signal_name(run->stopped) : NULL;
  r->io_failed = run_broken(run->st);
  sinks_close(run, r);
  r->sinks = run->sinks;
  r->nsinks = run->nsinks;
  /* the run's wall time includes waiting for the last frames */
  r->wall = sph_wtime() - run->wall0;
  /* over MPI ranks: the most a rank spent in exchanges and reductions
   * (waits included) and outside them (collective) */
  double comm = sph_domain_seconds(sim->domain) - run->comm0;
  r->work = sph_domain_max(sim->domain, r->wall - comm);
  r->comm = sph_domain_max(sim->domain, comm);
  /* the errors against the reference, in the serial order (collective) */
  sph_error cerr;
  if (sim->reference &&
      sph_reference_errors(sim->reference, sim, &run->ref_err, &cerr) !=
          SPH_OK &&
      !r->io_failed) {
    r->io_failed = 1;
    run->err = cerr;
  }
  /* the animation of the frames, once the run has ended */
  r->mp4_tried = !run->opt.no_files && s->output.png.enabled &&
                 s->output.png.mp4 && !r->io_failed && run->index > 0 &&
                 run->root;
  if (r->mp4_tried)
    r->mp4_status = sph_mp4_assemble(run->dir, s->name, run->index,
                                     s->output.png.fps, &r->mp4, &r->mp4_err);
  if (!run->opt.no_files && !r->io_failed && run->root)
    summary_write(run, r, completed);
  /* the manifest: the files written and their sizes */
  if (!run->opt.no_files && run->root &&
      sph_run_manifest_close(run->dir, &cerr) != SPH_OK && !r->io_failed) {
    r->io_failed = 1;
    run->err = cerr;
  }
  if (summary)
    summary_fill(run, summary);
  if (r->io_failed) {
    if (err)
      *err = run->err;
    return run->err.code != SPH_OK ? run->err.code : SPH_ERR_IO;
  }
  return SPH_OK;
}

void sph_run_destroy(sph_run *run) {
  if (!run)
    return;
  for (int i = 0; run->sinks && i < run->nsinks; ++i)
    if (!run->closed && run->sinks[i].ops->destroy)
      run->sinks[i].ops->destroy(&run->sinks[i]);
  free(run->sinks);
  sph_verdict_destroy(run->verdict);
  sph_probe_view_destroy(&run->pv);
  sph_sim_destroy(run->sim);
  free(run->scratch);
  if (run->lock_fd >= 0)
    close(run->lock_fd); /* the folder is free for the next run */
  free(run);
}
