/* The run's state, shared by src/solver/run*.c only. */
#ifndef SPH_RUN_IMPL_H
#define SPH_RUN_IMPL_H

#include <stdint.h>

#include "solver/reference.h"
#include "solver/run.h"

/* Over MPI ranks rank 0's probes read a set of their particles only: the
 * nearest to each probe in the reference configuration (ties: the first
 * created, as the probe sink picks them), by particle id, their fields
 * taken from their owners at every frame. */
typedef struct sph_probe_view {
  sph_particles *ps;    /* the probes' distinct particles by id */
  double *rows, *got;   /* a flag then the fields, per particle */
  unsigned long fields; /* the probes' (bit 1ul << f) */
  int w;                /* doubles a row */
} sph_probe_view;

struct sph_run {
  const sph_scene *scene;
  sph_sim *sim;
  sph_run_options opt;
  sph_run_hooks hooks;
  int root;    /* rank 0 (or no MPI) */
  int lock_fd; /* the output folder's lock, -1 */
  char dir[1024];
  /* rank 0's view of a distributed run: its probes' particles */
  sph_sim view;
  sph_probe_view pv;
  const sph_sim *whole; /* &view over MPI ranks, else sim */
  sph_halo halo;
  sph_verdict *verdict;
  sph_sink *sinks;
  int nsinks;
  int index; /* the next output frame */
  char resumed[1200];
  int started, begun, closed, derived;
  sph_status st; /* the first failure of the set-up, a step or an output */
  sph_error err;
  int stopped;      /* the stop flag's value, agreed over the ranks */
  int ckpt_replace; /* the newest checkpoint is a stop's: replaced next */
  double wall0, comm0, next_ckpt;
  double *scratch; /* id and body as doubles (2 * capacity) */
  sph_run_report report;
  sph_reference_error ref_err;
};

/* run_folder.c */
sph_status sph_run_lock(sph_run *run, sph_error *err);
/* rank 0, before anything is written: refuses a file under a name the run
 * writes that no earlier run wrote (the manifest DIR/.sph.manifest), with
 * overwrite removes the earlier runs' files, then writes the manifest of
 * what this run may write */
sph_status sph_run_manifest_start(const char *dir, const sph_scene *scene,
                                  int frames, int ranks, int overwrite,
                                  sph_error *err);
/* rank 0, once the run is closed: the manifest lists the files written,
 * with their sizes */
sph_status sph_run_manifest_close(const char *dir, sph_error *err);
int sph_run_frame_count(const sph_run *run);
int sph_run_file_exists(const char *dir, const char *name);
sph_status sph_run_write_scene_used(const sph_run *run, sph_error *err);
void sph_run_provenance(const sph_run *run, sph_provenance *prov);

/* run_probe.c */
sph_status sph_probe_view_create(sph_probe_view *pv, sph_sim *sim,
                                 sph_error *err);
sph_status sph_probe_view_fill(sph_probe_view *pv, sph_sim *sim, int X,
                               sph_error *err);
void sph_probe_view_destroy(sph_probe_view *pv);

#endif
