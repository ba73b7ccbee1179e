/* libFuzzer target for the checkpoint reader (src/io/checkpoint.c, issue
 * 36): what `sph run --resume DIR` reads, into a small simulation of the
 * spinning cube (3 x 3 x 3 particles, tl-jst) made once.
 *
 * The input is a checkpoint without its last four bytes: the harness
 * appends the CRC-32 of the input, so mutations pass the checksum and reach
 * the header, the verdict, the call counts and the array table. It is
 * written as
 * DIR/checkpoint.sphc and resumed from. With SPH_FUZZ_SEED_DIR set, a valid
 * checkpoint of that simulation is written there first as the seed
 * (tests/fuzz/run_fuzz.sh). A crash, a sanitizer report, a leak or a hang
 * is a finding; every refusal is fine. tests/fuzz/replay_main.c runs the
 * same function over tests/fuzz/regressions_checkpoint/ in the normal
 * build. */
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "app/app_impl.h"
#include "io/checkpoint.h"
#include "scene/scene.h"
#include "solver/sim.h"
#include "solver/stability.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64], path[128];
static sph_scene *scene;
static sph_sim *sim;
static sph_verdict *verdict;

static void clean(void) {
  unlink(path);
  rmdir(dir);
  sph_verdict_destroy(verdict);
  sph_sim_destroy(sim);
  sph_scene_destroy(scene);
}

/* the seed: a valid checkpoint of the simulation, less its checksum */
static void write_seed(const char *to) {
  sph_error err;
  if (sph_checkpoint_write(dir, sim, verdict, 1, &err) != SPH_OK) {
    fprintf(stderr, "fuzz_checkpoint: %s\n", err.message);
    abort();
  }
  FILE *f = fopen(path, "rb");
  static unsigned char buf[1 << 20];
  size_t len = f ? fread(buf, 1, sizeof buf, f) : 0;
  if (f)
    fclose(f);
  char out[1200];
  snprintf(out, sizeof out, "%s/checkpoint_seed", to);
  FILE *o = fopen(out, "wb");
  if (len < 4 || !o || fwrite(buf, 1, len - 4, o) != len - 4 || fclose(o))
    abort();
  char prev[160];
  snprintf(prev, sizeof prev, "%s/" SPH_CHECKPOINT_PREVIOUS, dir);
  unlink(prev);
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc;
  (void)argv;
  omp_set_num_threads(1);
  static const char *const sets[] = {"bodies.0.particles.count=[3,3,3]",
                                     "output.png=false"};
  sph_error err;
  sph_error_clear(&err);
  if (sph_app_check_scene(SPH_FUZZ_SOURCE_DIR "/scenes/spinning_cube.yaml",
                          sets, 2, 64e6, &scene, &sim, &err) != SPH_OK ||
      sph_verdict_create(&verdict, sim, &err) != SPH_OK) {
    fprintf(stderr, "fuzz_checkpoint: %s\n", err.message);
    abort();
  }
  snprintf(dir, sizeof dir, "/tmp/sph_fuzz_ckpt_XXXXXX");
  if (!mkdtemp(dir))
    abort();
  snprintf(path, sizeof path, "%s/" SPH_CHECKPOINT_FILE, dir);
  atexit(clean);
  const char *seed = getenv("SPH_FUZZ_SEED_DIR");
  if (seed && *seed)
    write_seed(seed);
  return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  FILE *f = fopen(path, "wb");
  uint32_t crc = (uint32_t)crc32(crc32(0L, Z_NULL, 0), data, (uInt)size);
  if (!f || fwrite(data, 1, size, f) != size || fwrite(&crc, 4, 1, f) != 1 ||
      fclose(f) != 0)
    abort();
  sph_error err;
  sph_error_clear(&err);
  int next = 0;
  char used[256];
  sph_checkpoint_resume(dir, sim, verdict, &next, used, sizeof used, &err);
  return 0;
}
