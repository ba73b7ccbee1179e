/* The run's read side (include/sph/sph.h, solver/run.h): its time and step
 * count, the particle fields as arrays, the energies, the scene's name and
 * end time, the library's version and the provenance it records. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "solver/run_impl.h"

#ifndef SPH_VERSION
#define SPH_VERSION "unknown"
#endif
#ifndef SPH_GIT_COMMIT
#define SPH_GIT_COMMIT "unknown"
#endif

const char *sph_version(void) { return SPH_VERSION; }

const char *sph_scene_name(const sph_scene *scene) { return scene->name; }

double sph_scene_end_time(const sph_scene *scene) { return scene->t_end; }

void sph_run_provenance(const sph_run *run, sph_provenance *prov) {
  prov->version = SPH_VERSION;
  prov->commit = SPH_GIT_COMMIT;
  prov->command = run->hooks.command ? run->hooks.command : "";
}

double sph_run_time(const sph_run *run) { return run->sim->t; }

unsigned long sph_run_steps(const sph_run *run) { return run->sim->steps; }

size_t sph_run_particles(const sph_run *run) { return run->sim->ps->n; }

sph_sim *sph_run_sim(sph_run *run) { return run->sim; }

const sph_sim *sph_run_view(const sph_run *run) { return run->whole; }

const sph_verdict *sph_run_verdict(const sph_run *run) { return run->verdict; }

const char *sph_run_dir(const sph_run *run) { return run->dir; }

const sph_halo *sph_run_halo(const sph_run *run) { return &run->halo; }

const char *sph_run_resumed_from(const sph_run *run, int *next_index) {
  *next_index = run->resumed[0] ? run->index : 0;
  return run->resumed;
}

const sph_run_report *sph_run_report_of(const sph_run *run) {
  return run->closed ? &run->report : NULL;
}

/* the derived fields of the current state (collective over MPI ranks) */
static sph_status run_derive(sph_run *run, sph_error *err) {
  if (run->derived)
    return SPH_OK;
  sph_sim *sim = run->sim;
  sph_status st = sim->method->derive(sim, err);
  SPH_TRY(sph_domain_agree(sim->domain, st, err));
  run->derived = 1;
  return SPH_OK;
}

sph_status sph_run_field(sph_run *run, const char *name, const double **data,
                         int *components, sph_error *err) {
  static const struct {
    const char *name;
    int field; /* -1: id, -2: body */
  } names[] = {{"position", SPH_FIELD_POSITION},
               {"velocity", SPH_FIELD_VELOCITY},
               {"displacement", SPH_FIELD_DISPLACEMENT},
               {"pressure", SPH_FIELD_PRESSURE},
               {"von_mises", SPH_FIELD_VON_MISES},
               {"J", SPH_FIELD_JACOBIAN},
               {"body", -2},
               {"id", -1}};
  const sph_particles *ps = run->sim->ps;
  for (size_t k = 0; k < sizeof names / sizeof *names; ++k) {
    if (strcmp(name, names[k].name))
      continue;
    int f = names[k].field;
    if (f < 0) { /* stored as integers: as doubles in the run's scratch */
      double *out = run->scratch + (f == -1 ? 0 : ps->capacity);
      for (size_t a = 0; a < ps->n; ++a)
        out[a] = f == -1 ? (double)ps->id[a] : (double)ps->body[a];
      *data = out;
      *components = 1;
      return SPH_OK;
    }
    if (!(run->sim->method->fields & 1ul << f) || !ps->field[f])
      return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                           "the method %s does not fill the field %s",
                           run->sim->method->name, name);
    SPH_TRY(run_derive(run, err));
    *data = ps->field[f];
    *components = sph_field_components((sph_field)f);
    return SPH_OK;
  }
  return sph_error_set(err, SPH_ERR_ARG,
                       "no field named '%s' (position, velocity, "
                       "displacement, pressure, von_mises, J, body, id)",
                       name);
}

sph_status sph_run_energy(sph_run *run, double *kinetic, double *strain,
                          sph_error *err) {
  sph_sim *sim = run->sim;
  SPH_TRY(run_derive(run, err));
  double e[2];
  sim->method->energy(sim, &e[0], &e[1]);
  sph_domain_sum(sim->domain, e, 2);
  *kinetic = e[0];
  *strain = e[1];
  return SPH_OK;
}

int sph_mkdir_p(const char *path) {
  char buf[1024];
  snprintf(buf, sizeof buf, "%s", path);
  for (char *p = buf + 1; *p; ++p)
    if (*p == '/') {
      *p = '\0';
      if (mkdir(buf, 0777) != 0 && errno != EEXIST)
        return -1;
      *p = '/';
    }
  return mkdir(buf, 0777) != 0 && errno != EEXIST ? -1 : 0;
}

sph_status sph_run_output_dir(const char *dir, sph_error *err) {
  struct stat st;
  if (sph_mkdir_p(dir) != 0 || stat(dir, &st) != 0)
    return sph_error_set(err, SPH_ERR_ARG,
                         "cannot create the output folder %s: %s", dir,
                         strerror(errno));
  if (!S_ISDIR(st.st_mode))
    return sph_error_set(err, SPH_ERR_ARG,
                         "cannot create the output folder %s: a file of that "
                         "name exists",
                         dir);
  /* permissions do not stop root: a file made and removed again tells */
  char probe[1100];
  snprintf(probe, sizeof probe, "%s/.sph-probe-XXXXXX", dir);
  int fd = mkstemp(probe);
  if (fd < 0)
    return sph_error_set(err, SPH_ERR_ARG,
                         "cannot write in the output folder %s: %s", dir,
                         strerror(errno));
  close(fd);
  unlink(probe);
  return SPH_OK;
}
