/* The sph library's public C API (libsph.so; pkg-config --cflags --libs sph,
 * or find_package(sph) in CMake). Everything a program that embeds the
 * solver needs: load a scene, run it to chosen times with every output the
 * scene asks for, read the particle fields as arrays, close the run with its
 * verdict and summary.json. examples/embed.c and python/sph use only this.
 *
 * Units are SI throughout (m, s, kg, Pa, J). Every call that can fail
 * returns an sph_status and fills the sph_error it is given (which may be
 * NULL); the library never prints to stderr or exits. */
#ifndef SPH_SPH_H
#define SPH_SPH_H

#include <stddef.h>

#include "sph/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define SPH_API __attribute__((visibility("default")))
#else
#define SPH_API
#endif

/* The library's version, "MAJOR.MINOR.PATCH" (the project's). */
SPH_API const char *sph_version(void);

/* --- scenes ----------------------------------------------------------------
 * A scene is a YAML file (scenes/NAME.yaml, docs/scenes.md). `sets` are
 * overrides "key.path=value" applied in order, as `sph run --set` does (the
 * value is YAML: "time.end=0.01", "method={name: tl-bond}"). A shipped
 * scene's name ("twisting_column") is found in the installed scenes folder
 * when `path` is not a file. Errors name the file, line, column and key. */
typedef struct sph_scene sph_scene;

SPH_API sph_status sph_scene_load(sph_scene **out, const char *path,
                                  const char *const *sets, size_t nsets,
                                  sph_error *err);
SPH_API void sph_scene_destroy(sph_scene *scene);
/* The scene's name (its file's stem) and end time in s. */
SPH_API const char *sph_scene_name(const sph_scene *scene);
SPH_API double sph_scene_end_time(const sph_scene *scene);

/* --- runs ------------------------------------------------------------------
 * A run owns the simulation of one scene and the loop over its output
 * times: it steps the method, lands exactly on every output time, hands
 * each output frame to the scene's sinks (VTK, CSV, probes, PNG frames),
 * judges the stability verdict, writes checkpoints, and on close writes
 * summary.json. `sph run` is this loop with a command line around it. */
typedef struct sph_run sph_run;

/* The stop flag's value for a stop that no signal asked for. */
#define SPH_STOP_REQUEST 256

typedef struct sph_run_options {
  /* output folder: NULL writes outputs/<scene name>; made if missing */
  const char *out_dir;
  /* 1: replace an earlier run's files in out_dir (only files sph wrote);
   * 0: refuse a folder holding an earlier run's results */
  int overwrite;
  /* 1: continue the run whose checkpoint is in out_dir */
  int resume;
  /* OpenMP threads (0: the library's default) */
  int threads;
  /* 1: no start-up banner and no progress line on stdout (the library
   * itself never prints: sph run prints them unless --quiet) */
  int quiet;
  /* polled between steps: non-zero asks the run to stop at the next step
   * boundary with outputs finished and a checkpoint written (a signal
   * handler sets it to the signal's number, which summary.json names in
   * stopped_by; SPH_STOP_REQUEST: a request that is no signal; NULL:
   * never). Over MPI ranks the ranks agree on it. */
  const volatile int *stop;
  /* 1: write nothing (no folder, sinks, checkpoints or summary.json): the
   * run is only stepped and judged, as `sph bench` and the tests do */
  int no_files;
} sph_run_options;

/* Sets up particles, the method and its terms, the verdict and the sinks,
 * and writes the output frame at t = 0 (or restores a checkpoint).
 * `options` may be NULL (defaults above). Nothing is written until the
 * scene, its particles and its method have been validated. The scene must
 * outlive the run. */
SPH_API sph_status sph_run_create(sph_run **out, const sph_scene *scene,
                                  const sph_run_options *options,
                                  sph_error *err);

/* Advances to t_until (s), clamped to the scene's end time, through every
 * output time on the way: to the first step boundary at or after t_until,
 * exactly on it when it is an output time (the steps keep to the scene's
 * output times, so the outputs do not depend on how a run is advanced).
 * Returns SPH_OK also when the verdict turned unstable (a step that failed
 * trips its `step` indicator) or a stop was requested (the run then stays
 * where it stopped: sph_run_state_of says why); an output that failed is
 * SPH_ERR_IO and SPH_RUN_FAILED. */
SPH_API sph_status sph_run_advance(sph_run *run, double t_until,
                                   sph_error *err);

typedef enum sph_run_state {
  SPH_RUN_GOING = 0, /* stable, before the end time */
  SPH_RUN_COMPLETED, /* stable at the end time */
  SPH_RUN_UNSTABLE,  /* an indicator of the verdict tripped */
  SPH_RUN_STOPPED,   /* the stop flag was seen; resumable */
  SPH_RUN_FAILED     /* a step or an output failed (the error says) */
} sph_run_state;

SPH_API sph_run_state sph_run_state_of(const sph_run *run);
SPH_API double sph_run_time(const sph_run *run);         /* s */
SPH_API unsigned long sph_run_steps(const sph_run *run); /* steps so far */

/* --- fields ----------------------------------------------------------------
 * The particle fields of the current state of this process's particles
 * (over MPI ranks: its owned ones), as arrays of n * components doubles,
 * particle-major, in the run's storage order ("id" is each particle's
 * creation index), valid until the next advance or close. Derived fields
 * (pressure, von Mises, J, displacement) are refreshed on demand. Names and
 * units are those of docs/outputs.md: "position" (m, 3), "velocity" (m/s,
 * 3), "displacement" (m, 3), "pressure" (Pa, 1; tr(sigma)/3, positive in
 * tension), "von_mises" (Pa, 1), "J" (1, det F), "body" (body index, 1), "id"
 * (1). A field the method does not fill is SPH_ERR_UNSUPPORTED. */
SPH_API size_t sph_run_particles(const sph_run *run);
SPH_API sph_status sph_run_field(sph_run *run, const char *name,
                                 const double **data, int *components,
                                 sph_error *err);
/* Kinetic and strain energy of the current state (J; J/m in 2D). */
SPH_API sph_status sph_run_energy(sph_run *run, double *kinetic, double *strain,
                                  sph_error *err);

/* --- the end ----------------------------------------------------------------
 * Finishes the outputs (files renamed into place, the mp4), computes the
 * errors against the scene's reference, writes summary.json and fills
 * `summary` (may be NULL). A run that was not advanced to its end is closed
 * as stopped. The run must still be destroyed. */
typedef struct sph_summary {
  sph_run_state state;
  double t; /* s reached */
  unsigned long steps;
  double wall;           /* s, set-up excluded */
  double particle_steps; /* per wall second */
  char verdict[512];     /* "stable" or "UNSTABLE - <indicator> ..." */
  char method[64];       /* e.g. "tl-jst" */
  char reference[256];   /* the method's paper and equations */
  char out_dir[1024];
} sph_summary;

SPH_API sph_status sph_run_close(sph_run *run, sph_summary *summary,
                                 sph_error *err);
SPH_API void sph_run_destroy(sph_run *run);

#ifdef __cplusplus
}
#endif

#endif
