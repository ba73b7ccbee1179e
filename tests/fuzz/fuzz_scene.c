/* libFuzzer target for the scene loader (issue 21, "make it stay fixed").
 *
 * The input is a scene file, optionally followed by a NUL byte and --set
 * overrides, each ended by a NUL (or the end of the input);
 * tests/fuzz/replay_regressions.sh turns such a file back into
 * `sph check SCENE --set=...`. It goes through what
 * `sph check` validates, sph_app_check_scene: the YAML, the overrides, the
 * schema, the memory estimate (against FUZZ_MAX_MEMORY, as
 * `--max-memory 16M`), the particles, the method with its terms and the png
 * block; then the first time step is computed as `sph check` prints it, and
 * the resolved tree is written and loaded again as a run's
 * scene_used.yaml is. Nothing is simulated. A crash, a sanitizer report, a
 * leak, or a resolved scene that does not load back is a finding. */
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "app/app_impl.h"
#include "scene/node.h"
#include "scene/scene.h"
#include "solver/sim.h"

#define FUZZ_MAX_MEMORY 16e6
/* the particle relaxation is work a scene asks for, linear in its steps
 * (up to 100,000: a minute of sph check, half an hour under the
 * sanitizers); a scene asking for more steps than this, over its bodies, is
 * checked up to its schema only */
#define FUZZ_MAX_RELAX_STEPS 200

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* the scene and its resolved copy live in memory files, read by path as
 * sph check reads its scene */
static int scene_fd = -1, used_fd = -1;
static char scene_path[64], used_path[64];

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc;
  (void)argv;
  omp_set_num_threads(1);
  scene_fd = memfd_create("scene.yaml", MFD_CLOEXEC);
  used_fd = memfd_create("scene_used.yaml", MFD_CLOEXEC);
  if (scene_fd < 0 || used_fd < 0) {
    perror("fuzz_scene: memfd_create");
    abort();
  }
  snprintf(scene_path, sizeof scene_path, "/proc/self/fd/%d", scene_fd);
  snprintf(used_path, sizeof used_path, "/proc/self/fd/%d", used_fd);
  return 0;
}

static void put(int fd, const void *data, size_t len) {
  const char *p = data;
  if (ftruncate(fd, 0) != 0)
    abort();
  for (size_t at = 0; at < len;) {
    ssize_t k = pwrite(fd, p + at, len - at, (off_t)at);
    if (k <= 0)
      abort();
    at += (size_t)k;
  }
}

/* the resolved scene, written as scene_used.yaml is, must load again */
static void load_back(const sph_scene *scene) {
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  sph_error err;
  sph_error_clear(&err);
  if (!f || sph_node_write(scene->root, f, &err) != SPH_OK)
    abort();
  fclose(f);
  put(used_fd, text, len);
  sph_scene *again;
  sph_sim *sim;
  if (sph_app_check_scene(used_path, NULL, 0, FUZZ_MAX_MEMORY, &again, &sim,
                          &err) != SPH_OK) {
    char msg[2048];
    sph_error_format(&err, msg, sizeof msg);
    fprintf(stderr, "fuzz_scene: the resolved scene does not load back: %s\n%s",
            msg, text);
    abort();
  }
  free(text);
  sph_sim_destroy(sim);
  sph_scene_destroy(again);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const uint8_t *nul = memchr(data, 0, size);
  size_t scene_len = nul ? (size_t)(nul - data) : size;
  const char *sets[SPH_MAX_SETS];
  size_t nsets = 0;
  char *rest = NULL;
  if (nul) { /* the overrides, each NUL-terminated in a copy */
    size_t rl = size - scene_len - 1;
    rest = malloc(rl + 1);
    if (!rest)
      return 0;
    memcpy(rest, nul + 1, rl);
    rest[rl] = '\0';
    /* a NUL ends each override; a last one without is taken too */
    for (char *p = rest; p < rest + rl; p += strlen(p) + 1) {
      if (nsets == SPH_MAX_SETS) { /* sph refuses more as usage */
        free(rest);
        return 0;
      }
      sets[nsets++] = p;
    }
  }
  put(scene_fd, data, scene_len);
  sph_scene *scene;
  sph_sim *sim;
  sph_error err;
  sph_error_clear(&err);
  if (sph_scene_load(&scene, scene_path, sets, nsets, &err) == SPH_OK) {
    long steps = 0;
    for (size_t b = 0; b < scene->nbodies; ++b)
      steps += scene->bodies[b].relax_steps;
    sph_scene_destroy(scene);
    if (steps > FUZZ_MAX_RELAX_STEPS) {
      free(rest);
      return 0;
    }
  }
  sph_status st = sph_app_check_scene(scene_path, sets, nsets, FUZZ_MAX_MEMORY,
                                      &scene, &sim, &err);
  if (st == SPH_OK) {
    volatile double dt = sim->method->stable_dt(sim); /* as check prints */
    (void)dt;
    load_back(scene);
    sph_sim_destroy(sim);
    sph_scene_destroy(scene);
  } else {
    char msg[2048]; /* what sph prints */
    sph_error_format(&err, msg, sizeof msg);
  }
  free(rest);
  return 0;
}
