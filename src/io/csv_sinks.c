/* CSV sinks: energy.csv (energies and momenta) and probes.csv (the fields
 * each probe asks for, at the particle nearest to the probe in the
 * reference configuration). Both are streams (sph_stream_open): written
 * under their final names, each row flushed at its output time. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"
#include "io/sink.h"

static sph_status csv_close(sph_sink *sink, sph_error *err) {
  sph_atomic_file *af = sink->data;
  return sph_atomic_commit(af, err);
}

static sph_status csv_flush(sph_sink *sink, sph_error *err) {
  return sph_atomic_flush(sink->data, err);
}

/* Opens <dir>/<name>: fresh with `header`, or keeping the header and the
 * rows of the frames a resumed run already has. */
static sph_status csv_open(sph_sink *sink, sph_atomic_file *af, const char *dir,
                           const char *name, int *fresh, sph_error *err) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  *fresh = sink->resume_frames <= 0;
  return sph_stream_open(af, path, *fresh ? 0 : 1 + (size_t)sink->resume_frames,
                         err);
}

static void csv_destroy(sph_sink *sink) {
  sph_atomic_file *af = sink->data;
  if (!af)
    return;
  sph_atomic_abort(af);
  free(af);
  sink->data = NULL;
}

/* ---- energy.csv
 * -------------------------------------------------------------- */

static sph_status energy_open(sph_sink *sink, const sph_sim *sim,
                              const char *dir, sph_error *err) {
  sph_atomic_file *af = calloc(1, sizeof *af);
  if (!af)
    return sph_error_set(err, SPH_ERR_NOMEM, "energy sink");
  sink->data = af;
  int fresh;
  sph_status st = csv_open(sink, af, dir, "energy.csv", &fresh, err);
  /* units in the header; plane-strain (2D) runs count per metre of depth */
  int d2 = sim->scene->dimension == 2;
  const char *e = d2 ? "J/m" : "J", *p = d2 ? "kg/s" : "kg m/s",
             *l = d2 ? "kg m/s" : "kg m^2/s";
  if (st == SPH_OK && fresh)
    fprintf(af->f,
            "time [s],kinetic [%s],strain [%s],total [%s],"
            "linear_momentum_x [%s],linear_momentum_y [%s],"
            "linear_momentum_z [%s],angular_momentum_x [%s],"
            "angular_momentum_y [%s],angular_momentum_z [%s]\n",
            e, e, e, p, p, p, l, l, l);
  return st;
}

static sph_status energy_write(sph_sink *sink, const sph_frame *fr,
                               sph_error *err) {
  sph_atomic_file *af = sink->data;
  double lin[3], ang[3];
  if (fr->momentum) {
    memcpy(lin, fr->momentum, sizeof lin);
    memcpy(ang, fr->momentum + 3, sizeof ang);
  } else {
    sph_momentum(fr->ps, lin, ang);
  }
  fprintf(af->f,
          "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
          fr->time, fr->kinetic, fr->strain, fr->kinetic + fr->strain, lin[0],
          lin[1], lin[2], ang[0], ang[1], ang[2]);
  return sph_stream_row_end(af, err);
}

static int energy_enabled(const sph_scene *scene) { return 1; }

const sph_sink_ops sph_energy_sink_ops = {
    .name = "energy.csv",
    .enabled = energy_enabled,
    .distributed = 0,
    .open = energy_open,
    .write = energy_write,
    .flush = csv_flush,
    .close = csv_close,
    .destroy = csv_destroy,
};

/* ---- probes.csv
 * ------------------------------------------------------------------ */

typedef struct probe_sink {
  sph_atomic_file af; /* first: csv_close/csv_destroy use it */
  size_t *particle;   /* nearest particle of each probe */
} probe_sink;

static sph_status probe_open(sph_sink *sink, const sph_sim *sim,
                             const char *dir, sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_particles *ps = sim->ps;
  probe_sink *p = calloc(1, sizeof *p);
  if (!p || !(p->particle = calloc(s->output.nprobes + 1, sizeof(size_t)))) {
    free(p);
    return sph_error_set(err, SPH_ERR_NOMEM, "probe sink");
  }
  sink->data = p;
  for (size_t k = 0; k < s->output.nprobes; ++k) {
    double best = INFINITY;
    for (size_t j = 0; j < ps->n; ++j) { /* ties: the first created */
      size_t a = sph_particles_slot(ps, j);
      const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * a;
      double d = 0.0;
      for (int c = 0; c < 3; ++c)
        d += pow(X[c] - s->output.probes[k].at[c], 2);
      if (d < best) {
        best = d;
        p->particle[k] = a;
      }
    }
  }
  int fresh;
  sph_status st = csv_open(sink, &p->af, dir, "probes.csv", &fresh, err);
  if (st != SPH_OK || !fresh)
    return st;
  static const char *const comp3[] = {"_x", "_y", "_z"};
  static const char *const comp9[] = {"_xx", "_xy", "_xz", "_yx", "_yy",
                                      "_yz", "_zx", "_zy", "_zz"};
  fprintf(p->af.f, "time [s]");
  for (size_t k = 0; k < s->output.nprobes; ++k) {
    const sph_probe *pr = &s->output.probes[k];
    for (int f = 0; f < pr->nfields; ++f) {
      int nc = sph_field_components((sph_field)pr->fields[f]);
      for (int c = 0; c < nc; ++c)
        fprintf(p->af.f, ",%s.%s%s [%s]", pr->name,
                sph_field_name((sph_field)pr->fields[f]),
                nc == 1 ? "" : (nc == 3 ? comp3[c] : comp9[c]),
                sph_field_unit((sph_field)pr->fields[f]));
    }
  }
  fputc('\n', p->af.f);
  return SPH_OK;
}

static sph_status probe_write(sph_sink *sink, const sph_frame *fr,
                              sph_error *err) {
  probe_sink *p = sink->data;
  const sph_scene *s = fr->sim->scene;
  fprintf(p->af.f, "%.17g", fr->time);
  for (size_t k = 0; k < s->output.nprobes; ++k) {
    const sph_probe *pr = &s->output.probes[k];
    for (int f = 0; f < pr->nfields; ++f) {
      int nc = sph_field_components((sph_field)pr->fields[f]);
      const double *v = fr->ps->field[pr->fields[f]];
      for (int c = 0; c < nc; ++c) {
        if (v)
          fprintf(p->af.f, ",%.17g", v[(size_t)nc * p->particle[k] + c]);
        else
          fputs(",", p->af.f); /* the method does not provide this field */
      }
    }
  }
  fputc('\n', p->af.f);
  return sph_stream_row_end(&p->af, err);
}

static void probe_destroy(sph_sink *sink) {
  probe_sink *p = sink->data;
  if (!p)
    return;
  sph_atomic_abort(&p->af);
  free(p->particle);
  free(p);
  sink->data = NULL;
}

static int probe_enabled(const sph_scene *scene) {
  return scene->output.nprobes > 0;
}

const sph_sink_ops sph_probe_sink_ops = {
    .name = "probes.csv",
    .enabled = probe_enabled,
    .distributed = 0,
    .open = probe_open,
    .write = probe_write,
    .flush = csv_flush,
    .close = csv_close,
    .destroy = probe_destroy,
};
