/* The sph command: sub-commands and the helpers they share. Only this layer
 * prints and chooses exit codes (0 success, 1 unstable run or failed
 * comparison, 2 bad input or usage, 3 I/O or system failure). */
#ifndef SPH_APP_IMPL_H
#define SPH_APP_IMPL_H

#include <stddef.h>

#include "solver/run.h"
#include "sph/status.h"

#define SPH_EXIT_OK 0
#define SPH_EXIT_FAIL 1
#define SPH_EXIT_USAGE 2
#define SPH_EXIT_IO 3

/* The exit code of a library status: 3 for I/O, memory and a failed
 * internal check, 2 otherwise (bad input); 0 for SPH_OK. */
int sph_app_exit_code(sph_status st);

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
  int keys;           /* check --keys */
  int resolved;       /* check --resolved */
  double max_memory;  /* --max-memory BYTES (0: the memory available) */
} sph_app_args;

/* The options of every command (ids of options.c's shared table). */
enum {
  SPH_OPT_HELP = 256,
  SPH_OPT_SET,
  SPH_OPT_OUT,
  SPH_OPT_THREADS,
  SPH_OPT_RESUME_DIR, /* run: --resume DIR */
  SPH_OPT_RESUME,     /* study: --resume */
  SPH_OPT_OVERWRITE,
  SPH_OPT_QUIET,
  SPH_OPT_VARY,
  SPH_OPT_REPEAT,
  SPH_OPT_RESOLUTION,
  SPH_OPT_DRY_RUN,
  SPH_OPT_QUICK,
  SPH_OPT_JSON,
  SPH_OPT_TOLERANCE,
  SPH_OPT_SHIFT,
  SPH_OPT_MAX_FRACTION,
  SPH_OPT_MAX_CLUSTER,
  SPH_OPT_DIFF,
  SPH_OPT_FIELD,
  SPH_OPT_RANGE,
  SPH_OPT_WIDTH,
  SPH_OPT_HEIGHT,
  SPH_OPT_MP4,
  SPH_OPT_KEYS,
  SPH_OPT_MAX_MEMORY,
  SPH_OPT_RESOLVED,
  SPH_OPT_CASE,  /* bench: --case TEXT */
  SPH_OPT_MPI,   /* bench: --mpi */
  SPH_OPT_DEVICE /* run, check: --device cpu|cuda (--set device=...) */
};

/* A command for sph_app_getopt: its usage text, the option ids it allows
 * (0-terminated), and what each option and operand does (0 or 2). */
typedef struct sph_app_command {
  const char *name;
  const char *usage;
  const int *allowed;
  int (*option)(void *ctx, int id, const char *value);
  int (*operand)(void *ctx, const char *arg); /* NULL: none taken */
} sph_app_command;

/* sph_app_getopt's return when --help or -h printed the usage. */
#define SPH_APP_HELP (-1)

/* Parses argv[2..] with getopt_long (--opt=V and --opt V); prints usage
 * errors with the usage; returns 0, 2 or SPH_APP_HELP. */
int sph_app_getopt(const sph_app_command *cmd, int argc, char **argv,
                   void *ctx);

/* A count option's value in [1, max], or 2 with a message. */
int sph_app_count(const char *command, const char *opt, const char *val,
                  int max, int *out);

/* --max-memory's value: bytes, or a number with the suffix k, M, G or T
 * (powers of 1000; "4G", "512M", "1.5e9"); 0 or 2 with a message. */
int sph_app_bytes(const char *val, double *out);

struct sph_scene;
struct sph_sim;
/* What sph check validates, without printing: the scene at `path` with the
 * overrides, its memory estimate against max_memory (0: the memory
 * available), the particles, the method and its terms, the png block. On
 * success *scene and *sim are the caller's; on failure both are NULL and
 * err says why. */
sph_status sph_app_check_scene(const char *path, const char *const *sets,
                               size_t nsets, double max_memory,
                               struct sph_scene **scene, struct sph_sim **sim,
                               sph_error *err);

/* Parses run's and check's argv into args; returns 0, 2 or SPH_APP_HELP. */
int sph_app_parse_args(int argc, char **argv, sph_app_args *args,
                       const sph_app_command *cmd);

/* The shipped scenes folder and the default scene. */
const char *sph_app_scenes_dir(void);
const char *sph_app_default_scene(void);
/* The shipped scene files (NAME.yaml), sorted, each strdup'd; their count. */
size_t sph_app_scene_files(char **names, size_t max);
/* SCENE as given on the command line: an existing path, else a shipped
 * scene's name (NAME or NAME.yaml); returns 0 with the path in path, or
 * prints the shipped names and returns 2. */
int sph_app_scene_path(const char *arg, char *path, size_t size);

/* Version, commit and this process's command line (set by main). */
struct sph_provenance;
void sph_app_provenance(struct sph_provenance *prov);

/* Prints "sph: file:line:col: key: message" to stderr. */
void sph_app_print_error(const sph_error *err);
void sph_app_print_load_error(const sph_error *err, const char *const *sets,
                              size_t nsets);

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
/* sph bench [--quick] [--json FILE] [--threads N] [--case TEXT]: 0 every case
 * ran, 1 a case failed, 2 usage, 3 I/O */
int sph_cmd_bench(int argc, char **argv);
/* Bytes per second of the STREAM triad over three arrays of `bytes` each on
 * `threads` threads, the best of 0.3 s of repetitions (0 when they cannot be
 * allocated); it starts an OpenMP team, so bench calls it in a child. */
double bench_machine_triad(int threads, size_t bytes);
/* Flops per second of independent multiply-add chains in registers on
 * `threads` threads, the best of 0.3 s of repetitions; in a child too. */
double bench_machine_flops(int threads);
/* sph render RUN [options]: 0 done, 2 bad input (missing or damaged files),
 * 3 I/O */
int sph_cmd_render(int argc, char **argv);

#endif
