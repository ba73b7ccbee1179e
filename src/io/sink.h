/* Output sinks (docs/design.md sec. 2, 4): each consumes the same read-only
 * Frame at every output time; no sink recomputes physics. */
#ifndef SPH_SINK_H
#define SPH_SINK_H

#include <stdio.h>
#include <sys/types.h>

#include "solver/sim.h"
#include "sph/status.h"

/* What a sink sees at an output time (after method->derive). */
typedef struct sph_frame {
  double time;
  unsigned long step;
  int index; /* 0, 1, ... */
  const sph_sim *sim;
  const sph_particles *ps;
  double kinetic, strain; /* energies of this state */
  /* linear then angular momentum (over MPI ranks: summed in rank order);
   * NULL: sph_momentum of ps */
  const double *momentum;
} sph_frame;

typedef struct sph_sink sph_sink;
/* A sink's ops; every sink is listed once in io/sink_list.h (the registry,
 * sph_sink_list), in the order the run opens and writes them. */
typedef struct sph_sink_ops {
  const char *name; /* as in summary.json's "sinks" */
  /* the scene asks for this sink's files */
  int (*enabled)(const sph_scene *scene);
  /* over MPI ranks, 1: every rank writes its piece (collective hooks);
   * 0: rank 0 writes the whole run's view */
  int distributed;
  sph_status (*open)(sph_sink *sink, const sph_sim *sim, const char *dir,
                     sph_error *err);
  sph_status (*write)(sph_sink *sink, const sph_frame *frame, sph_error *err);
  /* makes what was written so far durable (before a checkpoint; may be
   * NULL) */
  sph_status (*flush)(sph_sink *sink, sph_error *err);
  /* completes the files (renames them into place) */
  sph_status (*close)(sph_sink *sink, sph_error *err);
  void (*destroy)(sph_sink *sink);
} sph_sink_ops;

struct sph_sink {
  const sph_sink_ops *ops;
  void *data;
  /* > 0 when resuming: frames 0 .. resume_frames - 1 exist already and the
   * sink continues after them */
  int resume_frames;
  /* set before close: the run stopped before its end (a signal, a stop
   * request) and may be resumed, so the sink may keep what a resume needs */
  int stopping;
  /* wall time spent in its hooks (kept by the caller; summary.json) */
  double seconds;
  /* wall time the sink's own thread spent working, in parallel with the
   * caller and not part of `seconds` (png: rendering; set by close and
   * destroy, 0 for sinks without a thread) */
  double thread_seconds;
};

/* energy.csv: time, energies, linear and angular momentum */
extern const sph_sink_ops sph_energy_sink_ops;
/* probes.csv: the fields each probe asked for */
extern const sph_sink_ops sph_probe_sink_ops;
/* <scene>_NNNN.vtp per output time and <scene>.pvd (ParaView) */
extern const sph_sink_ops sph_vtk_sink_ops;

/* Every sink of io/sink_list.h, in its order, NULL-terminated. */
const sph_sink_ops *const *sph_sink_list(void);

/* Files written under a temporary name, fsync'd and renamed on commit. */
typedef struct sph_atomic_file {
  FILE *f;
  char path[1024];
  char tmp[1040];
} sph_atomic_file;

sph_status sph_atomic_open(sph_atomic_file *af, const char *path,
                           sph_error *err);
sph_status sph_atomic_commit(sph_atomic_file *af, sph_error *err);
/* A stream under its final name (tmp empty: commit closes it in place,
 * abort keeps it): fresh (lines 0) or keeping the first `lines` complete
 * lines of the file (a resume: the file is cut after them in place, so a
 * resume killed at once loses nothing; fails if it has fewer). */
sph_status sph_stream_open(sph_atomic_file *af, const char *path, size_t lines,
                           sph_error *err);
/* Ends a stream's row: flushed, so it can be read now; the error names the
 * file and the reason (disk full, file too large). */
sph_status sph_stream_row_end(sph_atomic_file *af, sph_error *err);
/* Flushes and fsyncs the temporary file. */
sph_status sph_atomic_flush(sph_atomic_file *af, sph_error *err);
/* Closes and removes the temporary file (safe after a failed commit). */
void sph_atomic_abort(sph_atomic_file *af);

/* Opening files without following links (issue 36; src/io/atomic_file.c).
 * An output: open(2) flags and mode with O_NOFOLLOW added (O_TRUNC applied
 * only once the file is known to be a regular file with one link; a FIFO
 * never blocks). A link, a folder, FIFO or device, or a file with other
 * hard links under the name is refused naming the file, SPH_ERR_IO as any
 * other failure to write (SPH_ERR_ARG when opened read-only). Returns the
 * descriptor or -1 with err filled and errno set. */
int sph_open_nofollow(const char *path, int flags, mode_t mode, sph_error *err);
/* The same as a FILE: mode "r", "w" or "a", with "+" and "x" (O_EXCL). */
FILE *sph_fopen_nofollow(const char *path, const char *mode, sph_error *err);
/* An input (a checkpoint, a .vtp): opened without blocking and refused
 * with SPH_ERR_ARG unless a regular file (a FIFO would hang the read);
 * *size receives its size when size is not NULL. */
sph_status sph_fopen_input(const char *path, FILE **f, long long *size,
                           sph_error *err);

#endif
