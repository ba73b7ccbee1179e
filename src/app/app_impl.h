/* The sph command: sub-commands and the helpers they share. Only this layer
 * prints and chooses exit codes (0 success, 1 failed run or comparison,
 * 2 bad input or usage). */
#ifndef SPH_APP_IMPL_H
#define SPH_APP_IMPL_H

#include <stddef.h>

#include "sph/status.h"

#define SPH_EXIT_OK 0
#define SPH_EXIT_FAIL 1
#define SPH_EXIT_USAGE 2

#define SPH_MAX_SETS 64

/* Options common to commands that take a scene. */
typedef struct sph_app_args {
  const char *scene;              /* path (default scene when NULL) */
  const char *sets[SPH_MAX_SETS]; /* --set k=v */
  size_t nsets;
  const char *out;    /* --out DIR */
  const char *resume; /* --resume DIR */
  int threads;        /* --threads N (0 = OpenMP default) */
  int overwrite;      /* --overwrite */
  int quiet;          /* --quiet */
} sph_app_args;

/* Parses argv[first..] into args; prints usage errors; returns 0 or 2. */
int sph_app_parse_args(int argc, char **argv, int first, sph_app_args *args,
                       const char *command);

/* The shipped scenes folder and the default scene. */
/* mkdir -p: 0, or -1 with errno set */
int sph_app_mkdir_p(const char *path);

const char *sph_app_scenes_dir(void);
const char *sph_app_default_scene(void);

/* Version, commit and this process's command line (set by main). */
struct sph_provenance;
void sph_app_provenance(struct sph_provenance *prov);

/* Prints "sph: file:line:col: key: message" to stderr. */
void sph_app_print_error(const sph_error *err);

struct sph_scene;
struct sph_sim;
/* Loads the scene with its overrides and creates the simulation; prints the
 * error and returns SPH_EXIT_USAGE on bad input. */
int sph_app_load(const sph_app_args *args, const char *path,
                 struct sph_scene **scene, struct sph_sim **sim);

int sph_cmd_run(int argc, char **argv);
int sph_cmd_check(int argc, char **argv);
int sph_cmd_list(int argc, char **argv);
/* sph study SCENE --vary k=a,b...: 0 done, 1 failed, 2 bad input */
int sph_cmd_study(int argc, char **argv);
/* sph imgdiff A.png B.png [options]: 0 passed, 1 different, 2 bad input */
int sph_cmd_imgdiff(int argc, char **argv);
/* sph bench [--quick] [--json FILE] [--threads N]: 0 every case ran, 1 a
 * case failed, 2 usage, 3 I/O */
int sph_cmd_bench(int argc, char **argv);

#endif
