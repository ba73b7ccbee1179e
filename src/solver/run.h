/* The run's extras for the sph command and the tests, beside the public run
 * API of include/sph/sph.h (implemented in src/solver/run*.c): the set-up in
 * phases (so `sph run` prints its banner between them), hooks called at
 * every step and output frame, a fixed count of steps (sph bench), and what
 * the close found (the sinks' times, the mp4, the MPI statistics). */
#ifndef SPH_RUN_H
#define SPH_RUN_H

#include "io/sink.h"
#include "parallel/domain.h"
#include "render/render.h"
#include "solver/sim.h"
#include "solver/stability.h"
#include "sph/sph.h"

/* Called by the run (each may be NULL). */
typedef struct sph_run_hooks {
  void *ctx;
  /* after every step */
  void (*step)(void *ctx, double t, unsigned long steps);
  /* after every output frame but the first (t = 0 or the resumed one) */
  void (*output)(void *ctx, double t, unsigned long steps);
  /* after every output frame, its verdict observed (the stability tests) */
  void (*frame)(sph_run *run, const sph_frame *frame, void *ctx);
  /* > 0: the output frames every `every` s instead of the scene's
   * output.every (no_files runs: the stability tests) */
  double every;
  /* 1: go on to the end time after an indicator tripped */
  int keep_going;
  /* 1: steps independent of the output times (every step its stable
   * step, the last one landing on the end time), each frame written at the
   * first step that reaches its output time and stamped with that step's
   * time, so the trajectory does not depend on the outputs; 0: a step is
   * shortened to land on each output time (docs/results.md, issue 35) */
  int at_steps;
  /* the command line recorded in scene_used.yaml and summary.json (NULL:
   * "") */
  const char *command;
} sph_run_hooks;

/* sph_run_create in phases: open validates the scene, its particles, its
 * method and its png block (nothing written; errors: bad input); folder
 * makes, locks and checks the output folder and removes an earlier run's
 * files (--overwrite); start creates the verdict, restores the checkpoint
 * (errors: bad input), writes scene_used.yaml and opens the sinks (their
 * failures come back from advance and close). The first output frame is
 * written by the first advance. `hooks` may be NULL. */
sph_status sph_run_open(sph_run **out, const sph_scene *scene,
                        const sph_run_options *options,
                        const sph_run_hooks *hooks, sph_error *err);
sph_status sph_run_folder(sph_run *run, sph_error *err);
sph_status sph_run_start(sph_run *run, sph_error *err);
/* sph_run_create with hooks: every phase, then the first output frame. */
sph_status sph_run_create_hooked(sph_run **out, const sph_scene *scene,
                                 const sph_run_options *options,
                                 const sph_run_hooks *hooks, sph_error *err);

/* The simulation the run steps (the sinks' view of the whole run over MPI
 * ranks: sph_run_view). */
sph_sim *sph_run_sim(sph_run *run);
const sph_sim *sph_run_view(const sph_run *run);
const sph_verdict *sph_run_verdict(const sph_run *run);
const char *sph_run_dir(const sph_run *run);
/* the halo of the partition (sph_domain_halo, taken by sph_run_folder) */
const sph_halo *sph_run_halo(const sph_run *run);
/* after a resume: the checkpoint used and the next output frame's index
 * (0: not resumed) */
const char *sph_run_resumed_from(const sph_run *run, int *next_index);

/* Takes up to `steps` steps (fewer at the end time, an instability or a
 * stop), through the output times on the way, as sph_run_advance. */
sph_status sph_run_advance_steps(sph_run *run, unsigned long steps,
                                 sph_error *err);

/* For the tests that drive a simulation without a run: steps, each capped
 * to land on t_until, while t < t_until (to 1e-12 of it, relative) and
 * fewer than max_steps were taken. */
sph_status sph_sim_advance(sph_sim *sim, double t_until,
                           unsigned long max_steps, sph_error *err);

/* What sph_run_close found, for the command's last lines. */
typedef struct sph_run_report {
  int io_failed;          /* an output failed: no summary.json */
  int stop_signal;        /* the stop flag's value that stopped it (0) */
  const char *stopped_by; /* its name: "SIGTERM" ..., NULL */
  double wall;            /* s, the first output frame to the close */
  double comm, work;      /* MPI: the most a rank spent in exchanges, and not */
  const sph_sink *sinks;
  int nsinks;
  int mp4_tried; /* the frames were to be assembled (rank 0) */
  sph_status mp4_status;
  sph_mp4_info mp4;
  sph_error mp4_err;
} sph_run_report;

/* NULL before sph_run_close. */
const sph_run_report *sph_run_report_of(const sph_run *run);

/* An output folder made when missing (parents too) and tried by writing a
 * file in it; SPH_ERR_ARG naming it otherwise. */
sph_status sph_run_output_dir(const char *dir, sph_error *err);
/* mkdir -p: 0, or -1 with errno */
int sph_mkdir_p(const char *path);

#endif
