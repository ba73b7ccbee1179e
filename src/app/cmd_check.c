/* sph check: validate a scene, build its particles and method, and print
 * what a run would simulate (bodies, method, terms, time step, memory). */
#include <stdio.h>
#include <sys/resource.h>

#include "app/app_impl.h"
#include "scene/cloud.h"
#include "scene/mesh.h"
#include "scene/node.h"
#include "scene/polygon.h"
#include "scene/scene.h"
#include "solver/device.h"
#include "solver/sim.h"

static double peak_rss_mib(void) {
  struct rusage ru;
  if (getrusage(RUSAGE_SELF, &ru) != 0)
    return 0.0;
  return (double)ru.ru_maxrss / 1024.0; /* ru_maxrss is in KiB on Linux */
}

/* the particles' volume (area in 2D) of body b */
static double body_volume(const sph_particles *ps, size_t b) {
  double v = 0.0;
  for (size_t i = 0; i < ps->n; ++i)
    if (ps->body[i] == (int32_t)b)
      v += ps->field[SPH_FIELD_VOLUME0][i];
  return v;
}

/* a mesh body's surface: size, soundness, and the particles' volume */
static void print_mesh(const sph_body *body, const sph_particles *ps,
                       size_t b) {
  const sph_mesh_info *in = sph_mesh_get_info(body->shape.mesh);
  double v = body_volume(ps, b);
  printf("  %-16s mesh %s: %zu triangles, %zu open edges, box [%.4g, %.4g, "
         "%.4g] to [%.4g, %.4g, %.4g] m\n",
         "", body->shape.file, in->triangles, in->open_edges, in->lo[0],
         in->lo[1], in->lo[2], in->hi[0], in->hi[1], in->hi[2]);
  printf("  %-16s volume %.6g m^3 (signed); particles %.6g m^3, %.2f %% of "
         "it\n",
         "", in->volume, v, 100.0 * v / in->volume);
}

static void print_plan(const sph_scene *s, sph_sim *sim) {
  const sph_particles *ps = sim->ps;
  printf("scene      %s (%s)\n", s->name, s->path);
  printf("dimension  %d\n", s->dimension);
  printf("method     %s: %s [%s]\n", sim->method->name, sim->method->title,
         sim->method->reference);
  printf("kernel     %s, h = %.4g m (h/dp = %.3g), support %.4g m\n",
         sph_kernel_type_name(s->kernel_type), sim->kernel.h, s->h_over_dp,
         sim->kernel.support);
  printf("bodies     %zu\n", s->nbodies);
  for (size_t b = 0; b < s->nbodies; ++b) {
    size_t count = 0;
    for (size_t i = 0; i < ps->n; ++i)
      count += ps->body[i] == (int32_t)b;
    const sph_body *body = &s->bodies[b];
    printf("  %-16s %8zu particles, dp = %.4g m, material %s (%s)\n",
           body->name, count, body->spacing, s->materials[body->material].name,
           s->materials[body->material].ops->name);
    if (body->shape.kind == SPH_SHAPE_MESH)
      print_mesh(body, ps, b);
    if (body->shape.kind == SPH_SHAPE_PARTICLES)
      printf("  %-16s particles %s: %zu, total volume %.6g m^%d (%s); dp "
             "%s\n",
             "", body->shape.file, body->shape.cloud->n,
             sph_cloud_volume(body->shape.cloud), s->dimension,
             body->shape.cloud->has_volume ? "the file's" : "dp^d each",
             body->shape.spacing_estimated
                 ? "estimated: the median nearest-neighbour distance"
                 : "given");
    if (body->shape.kind == SPH_SHAPE_POLYGON) {
      double v = body_volume(ps, b), A = sph_polygon_area(body->shape.polygon);
      printf("  %-16s polygon: area %.6g m^2; particles %.6g m^2, %.2f %% of "
             "it\n",
             "", A, v, 100.0 * v / A);
    }
  }
  printf("particles  %zu\n", ps->n);
  printf("terms      %d\n", sim->nterms);
  for (int i = 0; i < sim->nterms; ++i)
    printf("  %-32s [%s]\n", sim->terms[i].ops->name,
           sim->terms[i].ops->reference);
  double dt = sph_sim_stable_dt(sim);
  double steps = dt > 0.0 ? s->t_end / dt : 0.0;
  printf("time       end %.6g s, first dt %.4g s, about %.0f steps\n", s->t_end,
         dt, steps);
  printf("outputs    every %.6g s (%.0f frames)\n", s->output.every,
         s->t_end / s->output.every + 1.0);
  printf("memory     %.1f MiB peak resident after set-up (fields %.1f MiB)\n",
         peak_rss_mib(), (double)sph_particles_bytes(ps) / 1048576.0);
}

/* with a `device` key (or --device): where each part runs, then whether
 * this build and machine can; exit 2 (the reason printed) when not */
static int print_device(const sph_scene *s, sph_sim *sim) {
  char plan[4096];
  sph_error err, avail;
  sph_error_clear(&err);
  sph_error_clear(&avail);
  sph_status st = sph_device_plan(sim, plan, sizeof plan, &err);
  printf("device     %s\n%s", s->device == SPH_DEVICE_CUDA ? "cuda" : "cpu",
         plan);
  if (st == SPH_OK)
    st = sph_device_attach(sim, &err);
  sph_status sa = sph_device_available(s, &avail);
  if (st == SPH_OK && sa == SPH_OK)
    return SPH_EXIT_OK;
  sph_app_print_error(sa != SPH_OK ? &avail : &err);
  return SPH_EXIT_USAGE;
}

static const int check_allowed[] = {SPH_OPT_SET,      SPH_OPT_KEYS,
                                    SPH_OPT_RESOLVED, SPH_OPT_MAX_MEMORY,
                                    SPH_OPT_DEVICE,   0};
static const sph_app_command check_command = {
    "check",
    "usage: sph check SCENE [--set key=value]... [--keys | --resolved]\n"
    "                 [--max-memory SIZE] [--device cpu|cuda]\n"
    "  validate SCENE (a file or a shipped scene's name) and print what a\n"
    "  run would simulate: bodies, method, terms, time step, memory;\n"
    "  --keys: every key the scene has, defaults filled in, as --set writes\n"
    "  it (bodies.0.particles.count), one per line; --resolved: the scene\n"
    "  with every default filled in, as a run's scene_used.yaml holds it;\n"
    "  --max-memory: refuse a scene estimated to need more than SIZE (4G,\n"
    "  512M; default 90 % of the memory available); --device: where each\n"
    "  part would run, exit 2 when one cannot run there (docs/gpu.md)\n",
    check_allowed, NULL, NULL};

/* --keys: the resolved tree's key paths in --set's form ([k] -> .k) */
static void print_keys(const sph_node *n) {
  if (n->path && n->path[0]) {
    for (const char *c = n->path; *c; ++c)
      if (*c == '[')
        putchar('.');
      else if (*c != ']')
        putchar(*c);
    putchar('\n');
  }
  for (size_t i = 0; i < n->count; ++i)
    print_keys(n->items[i]);
}

int sph_cmd_check(int argc, char **argv) {
  sph_app_args args;
  int rc = sph_app_parse_args(argc, argv, &args, &check_command);
  if (rc != SPH_EXIT_OK)
    return rc == SPH_APP_HELP ? SPH_EXIT_OK : rc;
  if (!args.scene) {
    fprintf(stderr, "sph check: which scene? (usage: sph check SCENE "
                    "[--set k=v]...)\n");
    return SPH_EXIT_USAGE;
  }
  sph_scene *scene;
  sph_sim *sim;
  if ((rc = sph_app_load(&args, args.scene, &scene, &sim)) != SPH_EXIT_OK)
    return rc;
  sph_error err;
  if (args.keys)
    print_keys(scene->root);
  else if (args.resolved &&
           sph_node_write(scene->root, stdout, &err) != SPH_OK) {
    sph_app_print_error(&err); /* stdout closed or full */
    rc = SPH_EXIT_IO;
  } else if (!args.resolved) {
    print_plan(scene, sim);
    if (scene->device_at)
      rc = print_device(scene, sim);
  }
  sph_sim_destroy(sim);
  sph_scene_destroy(scene);
  return rc;
}
