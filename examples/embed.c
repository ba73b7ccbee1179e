/* Embedding sph: load a scene, step it to its end time through the library,
 * and at every output time derive the fields, hand the frame to a sink of
 * our own (the largest displacement) and to the library's energy.csv sink.
 *
 *   cc embed.c $(pkg-config --cflags --libs sph) -o embed
 *   ./embed SCENE.yaml [key=value]...                                      */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "sph/sph.h"

/* a sink of our own: prints the time, the energies and max |u| */
static sph_status print_write(sph_sink *sink, const sph_frame *fr,
                              sph_error *err) {
  const double *u = fr->ps->field[SPH_FIELD_DISPLACEMENT];
  double umax = 0.0;
  for (size_t a = 0; u && a < fr->ps->n; ++a)
    umax = fmax(umax, sqrt(u[3 * a] * u[3 * a] + u[3 * a + 1] * u[3 * a + 1] +
                           u[3 * a + 2] * u[3 * a + 2]));
  printf("t = %.6g s  kinetic %.6g J  strain %.6g J  max |u| %.6g m\n",
         fr->time, fr->kinetic, fr->strain, umax);
  return SPH_OK;
}

static const sph_sink_ops print_sink_ops = {.name = "print",
                                            .write = print_write};

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: %s SCENE.yaml [key=value]...\n", argv[0]);
    return 2;
  }
  sph_scene *scene = NULL;
  sph_sim *sim = NULL;
  sph_error err;
  sph_error_clear(&err);
  sph_status st = sph_scene_load(&scene, argv[1], (const char **)argv + 2,
                                 (size_t)(argc - 2), &err);
  if (st == SPH_OK)
    st = sph_sim_create(&sim, scene, &err);
  sph_sink sinks[2] = {{.ops = &print_sink_ops}, {.ops = &sph_energy_sink_ops}};
  if (st == SPH_OK)
    st = sinks[1].ops->open(&sinks[1], sim, ".", &err);
  printf("%s: %zu particles, method %s [%s]\n", scene ? scene->name : "?",
         sim ? sim->ps->n : 0, sim ? sim->method->name : "?",
         sim ? sim->method->reference : "?");
  for (int index = 0; st == SPH_OK; ++index) {
    double next = sph_output_time(scene, index);
    while (st == SPH_OK && sim->t < next - 1e-12 * scene->t_end)
      st = sph_sim_step(sim, next - sim->t, &err);
    if (st != SPH_OK)
      break;
    st = sim->method->derive(sim, &err);
    sph_frame fr = {.time = sim->t,
                    .step = sim->steps,
                    .index = index,
                    .sim = sim,
                    .ps = sim->ps};
    sim->method->energy(sim, &fr.kinetic, &fr.strain);
    for (int k = 0; k < 2 && st == SPH_OK; ++k)
      st = sinks[k].ops->write(&sinks[k], &fr, &err);
    if (next >= scene->t_end)
      break;
  }
  if (st == SPH_OK)
    st = sinks[1].ops->close(&sinks[1], &err);
  if (sinks[1].ops->destroy)
    sinks[1].ops->destroy(&sinks[1]);
  if (st != SPH_OK) {
    char msg[1024];
    sph_error_format(&err, msg, sizeof msg);
    fprintf(stderr, "embed: %s\n", msg);
  } else {
    printf("done: %lu steps\n", sim->steps);
  }
  sph_sim_destroy(sim);
  sph_scene_destroy(scene);
  return st == SPH_OK ? 0 : 1;
}
