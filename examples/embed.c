/* Embedding sph through its public API (include/sph/sph.h) only: load a
 * scene, run it to a few times, printing the time, the energies and the
 * largest displacement from the particle fields, then close the run (its
 * outputs finished, summary.json written) and print the verdict.
 *
 *   cc embed.c $(pkg-config --cflags --libs sph) -lm -o embed
 *   ./embed SCENE [key=value]...       (outputs in the current folder)    */
#include <math.h>
#include <stdio.h>

#include "sph/sph.h"

/* the largest |u| of this process's particles */
static sph_status max_displacement(sph_run *run, double *umax, sph_error *err) {
  const double *u;
  int nc;
  sph_status st = sph_run_field(run, "displacement", &u, &nc, err);
  *umax = 0.0;
  for (size_t a = 0; st == SPH_OK && a < sph_run_particles(run); ++a)
    *umax =
        fmax(*umax, sqrt(u[nc * a] * u[nc * a] + u[nc * a + 1] * u[nc * a + 1] +
                         u[nc * a + 2] * u[nc * a + 2]));
  return st;
}

static sph_status report(sph_run *run, sph_error *err) {
  double kinetic, strain, umax;
  sph_status st = sph_run_energy(run, &kinetic, &strain, err);
  if (st == SPH_OK)
    st = max_displacement(run, &umax, err);
  if (st == SPH_OK)
    printf("t = %.6g s  kinetic %.6g J  strain %.6g J  max |u| %.6g m\n",
           sph_run_time(run), kinetic, strain, umax);
  return st;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: %s SCENE [key=value]...\n", argv[0]);
    return 2;
  }
  sph_scene *scene = NULL;
  sph_run *run = NULL;
  sph_summary summary;
  sph_error err;
  sph_error_clear(&err);
  sph_status st = sph_scene_load(&scene, argv[1], (const char **)argv + 2,
                                 (size_t)(argc - 2), &err);
  sph_run_options options = {.out_dir = ".", .overwrite = 1};
  if (st == SPH_OK)
    st = sph_run_create(&run, scene, &options, &err);
  if (st == SPH_OK)
    printf("sph %s: %s, %zu particles, to %g s\n", sph_version(),
           sph_scene_name(scene), sph_run_particles(run),
           sph_scene_end_time(scene));
  /* four stops on the way to the end time */
  for (int k = 0; st == SPH_OK && k <= 4; ++k) {
    if (k > 0)
      st = sph_run_advance(run, 0.25 * k * sph_scene_end_time(scene), &err);
    if (st == SPH_OK)
      st = report(run, &err);
    if (sph_run_state_of(run) != SPH_RUN_GOING)
      break;
  }
  if (run) {
    sph_status cst = sph_run_close(run, &summary, st == SPH_OK ? &err : NULL);
    st = st == SPH_OK ? cst : st;
  }
  if (st == SPH_OK)
    printf("done: %lu steps, %.2f s wall, verdict %s\n", summary.steps,
           summary.wall, summary.verdict);
  else {
    char msg[1024];
    sph_error_format(&err, msg, sizeof msg);
    fprintf(stderr, "embed: %s\n", msg);
  }
  sph_run_destroy(run);
  sph_scene_destroy(scene);
  return st != SPH_OK ? 2 : summary.state == SPH_RUN_COMPLETED ? 0 : 1;
}
