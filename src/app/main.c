/* sph: a headless simulator for large-strain elastic solid dynamics with
 * SPH. Dispatches to the sub-commands (docs/design.md sec. 1). */
#include <errno.h>
#include <omp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/app_impl.h"
#include "parallel/domain.h"
#include "render/render.h"
#include "scene/scene.h"
#include "solver/sim.h"
#include "solver/stability.h"

static void usage(FILE *out) {
  fprintf(out,
          "usage: sph <command> [options]\n"
          "\n"
          "commands:\n"
          "  run [SCENE] [--set k=v]... [--out DIR] [--threads N] "
          "[--overwrite] [--quiet]\n"
          "      [--resume DIR]   continue a killed run from its newest "
          "checkpoint\n"
          "                       simulate a scene (default: the twisting "
          "column)\n"
          "  check SCENE [--set k=v]...\n"
          "                       validate a scene and print what will be "
          "simulated\n"
          "  study SCENE --vary k=v1,v2,... [--vary ...] [--set k=v]... "
          "[--repeat N]\n"
          "        [--threads N] [--resolution KEY] [--out DIR] "
          "[--resume] [--dry-run]\n"
          "                       run every combination, write "
          "results.csv, report.md\n"
          "                       and plots (default outputs/<scene>_study)\n"
          "  list                 list the shipped scenes\n"
          "  imgdiff A.png B.png [--tolerance N] [--shift N] "
          "[--max-fraction F]\n"
          "          [--max-cluster N] [--diff OUT.png]\n"
          "                       compare two images (exit 0 same, 1 "
          "different)\n"
          "  bench [--quick] [--json FILE] [--threads N] [--case TEXT]\n"
          "                       throughput, split and memory of a fixed "
          "suite\n"
          "  render RUN_DIR [--field F] [--range R] [--width W] [--height H]\n"
          "         [--set output.png.KEY=V]... [--out DIR] [--mp4]\n"
          "                       draw a finished run's frames again from "
          "its .vtp files\n"
          "  help [COMMAND]       this text, or COMMAND's (also COMMAND "
          "--help, -h)\n"
          "  --version            version and git commit\n"
          "\n"
          "SCENE is a file or a shipped scene's name (sph list). Exit "
          "status: 0 done\n"
          "(stable), 1 unstable or different, 2 bad input or usage, 3 I/O "
          "failure.\n");
}

/* The shipped scenes: $SPH_SCENES_DIR, else the installed copy beside the
 * binary (<prefix>/bin/sph -> <prefix>/share/sph/scenes), else the source
 * tree's. */
const char *sph_app_scenes_dir(void) {
  const char *env = getenv("SPH_SCENES_DIR");
  if (env && *env)
    return env;
  static char installed[1200];
  if (!installed[0]) {
    char exe[1024];
    ssize_t k = readlink("/proc/self/exe", exe, sizeof exe - 1);
    struct stat st;
    installed[0] = '-'; /* looked, not found */
    if (k > 0) {
      exe[k] = '\0';
      char *slash = strrchr(exe, '/');
      if (slash) {
        *slash = '\0';
        snprintf(installed, sizeof installed, "%s/../share/sph/scenes", exe);
        if (stat(installed, &st) != 0 || !S_ISDIR(st.st_mode))
          snprintf(installed, sizeof installed, "-");
      }
    }
  }
  return installed[0] != '-' ? installed : SPH_SOURCE_DIR "/scenes";
}

const char *sph_app_default_scene(void) {
  static char path[1024];
  snprintf(path, sizeof path, "%s/twisting_column.yaml", sph_app_scenes_dir());
  return path;
}

static char command_line[4096];

/* Joins argv with spaces into command_line (truncated if longer). */
static void remember_command_line(int argc, char **argv) {
  size_t len = 0;
  for (int i = 0; i < argc && len + 1 < sizeof command_line; ++i) {
    int n = snprintf(command_line + len, sizeof command_line - len, "%s%s",
                     i ? " " : "", argv[i]);
    if (n < 0)
      break;
    len += (size_t)n;
  }
}

void sph_app_provenance(sph_provenance *prov) {
  prov->version = SPH_VERSION;
  prov->commit = SPH_GIT_COMMIT;
  prov->command = command_line;
}

int sph_app_scene_path(const char *arg, char *path, size_t size) {
  struct stat st;
  size_t len = strlen(arg);
  int has_ext = len > 5 && !strcmp(arg + len - 5, ".yaml");
  snprintf(path, size, "%s", arg);
  if (stat(arg, &st) == 0 || strchr(arg, '/'))
    return SPH_EXIT_OK; /* a path: the loader reports what is wrong */
  snprintf(path, size, "%s/%s%s", sph_app_scenes_dir(), arg,
           has_ext ? "" : ".yaml");
  if (stat(path, &st) == 0)
    return SPH_EXIT_OK;
  if (has_ext) {
    snprintf(path, size, "%s", arg); /* a missing file.yaml */
    return SPH_EXIT_OK;
  }
  char *names[512];
  size_t n = sph_app_scene_files(names, 512);
  fprintf(stderr,
          "sph: %s: no such file and no shipped scene of that name; "
          "shipped scenes:",
          arg);
  for (size_t i = 0; i < n; ++i) {
    fprintf(stderr, " %.*s", (int)(strlen(names[i]) - 5), names[i]);
    free(names[i]);
  }
  fputc('\n', stderr);
  return SPH_EXIT_USAGE;
}

int sph_app_exit_code(sph_status st) {
  switch (st) {
  case SPH_OK:
    return SPH_EXIT_OK;
  case SPH_ERR_IO:
  case SPH_ERR_NOMEM:
  case SPH_ERR_INTERNAL: /* a failed check of the library's own invariants */
    return SPH_EXIT_IO;
  default:
    return SPH_EXIT_USAGE;
  }
}

void sph_app_print_error(const sph_error *err) {
  if (sph_domain_world_rank() != 0) /* over MPI: rank 0 speaks for all */
    return;
  char buf[2048];
  sph_error_format(err, buf, sizeof buf);
  fprintf(stderr, "sph: %s\n", buf);
}

static int args_option(void *ctx, int id, const char *val) {
  sph_app_args *args = ctx;
  switch (id) {
  case SPH_OPT_SET:
    if (args->nsets >= SPH_MAX_SETS) {
      fprintf(stderr, "sph: more than %d --set options\n", SPH_MAX_SETS);
      return SPH_EXIT_USAGE;
    }
    args->sets[args->nsets++] = val;
    return SPH_EXIT_OK;
  case SPH_OPT_OUT:
    args->out = val;
    return SPH_EXIT_OK;
  case SPH_OPT_RESUME_DIR:
    args->resume = val;
    return SPH_EXIT_OK;
  case SPH_OPT_THREADS:
    return sph_app_count("run", "threads", val, 1024, &args->threads);
  case SPH_OPT_OVERWRITE:
    args->overwrite = 1;
    return SPH_EXIT_OK;
  case SPH_OPT_QUIET:
    args->quiet = 1;
    return SPH_EXIT_OK;
  case SPH_OPT_KEYS:
    args->keys = 1;
    return SPH_EXIT_OK;
  case SPH_OPT_RESOLVED:
    args->resolved = 1;
    return SPH_EXIT_OK;
  case SPH_OPT_MAX_MEMORY:
    return sph_app_bytes(val, &args->max_memory);
  case SPH_OPT_DEVICE:
    /* the scene's `device` key (docs/gpu.md), as --set writes it */
    if (strcmp(val, "cpu") && strcmp(val, "cuda")) {
      fprintf(stderr, "sph: --device is cpu or cuda (got '%s')\n", val);
      return SPH_EXIT_USAGE;
    }
    if (args->nsets >= SPH_MAX_SETS) {
      fprintf(stderr, "sph: more than %d --set options\n", SPH_MAX_SETS);
      return SPH_EXIT_USAGE;
    }
    args->sets[args->nsets++] =
        strcmp(val, "cpu") ? "device=cuda" : "device=cpu";
    return SPH_EXIT_OK;
  default:
    return SPH_EXIT_USAGE;
  }
}

static int args_operand(void *ctx, const char *arg) {
  sph_app_args *args = ctx;
  if (args->scene) {
    fprintf(stderr, "sph: more than one scene given (%s, %s)\n", args->scene,
            arg);
    return SPH_EXIT_USAGE;
  }
  args->scene = arg;
  return SPH_EXIT_OK;
}

int sph_app_parse_args(int argc, char **argv, sph_app_args *args,
                       const sph_app_command *cmd) {
  memset(args, 0, sizeof *args);
  sph_app_command c = *cmd;
  c.option = args_option;
  c.operand = args_operand;
  int rc = sph_app_getopt(&c, argc, argv, args);
  static char path[1024];
  if (rc == SPH_EXIT_OK && args->scene &&
      (rc = sph_app_scene_path(args->scene, path, sizeof path)) == SPH_EXIT_OK)
    args->scene = path;
  if (rc == SPH_EXIT_OK && args->threads > 0)
    omp_set_num_threads(args->threads);
  return rc;
}

/* An error placed in the scene file of a scene that --set changed may follow
 * from a changed key elsewhere (a box's min set past a boundary's plane, a
 * body moved onto another): the note names the overrides (issue 36 item 7). */
void sph_app_print_load_error(const sph_error *err, const char *const *sets,
                              size_t nsets) {
  sph_app_print_error(err);
  if (nsets == 0 || sph_domain_world_rank() != 0 || !err->file[0] ||
      !strcmp(err->file, "<command line>") || err->code == SPH_ERR_NOMEM ||
      err->code == SPH_ERR_SYNTAX || err->code == SPH_ERR_DUPLICATE_KEY)
    return;
  fprintf(stderr, "sph: note: the command line changed this scene (");
  for (size_t i = 0; i < nsets; ++i) {
    const char *eq = strchr(sets[i], '=');
    int len = eq ? (int)(eq - sets[i]) : (int)strlen(sets[i]);
    fprintf(stderr, "%s--set %.*s", i ? ", " : "", len > 200 ? 200 : len,
            sets[i]);
  }
  fprintf(stderr, "); the error may follow from %s\n",
          nsets == 1 ? "it" : "them");
}

int sph_app_load(const sph_app_args *args, const char *path, sph_scene **scene,
                 sph_sim **sim) {
  sph_error err;
  sph_error_clear(&err);
  sph_status st = sph_app_check_scene(path, args->sets, args->nsets,
                                      args->max_memory, scene, sim, &err);
  if (st == SPH_OK)
    return SPH_EXIT_OK;
  sph_app_print_load_error(&err, args->sets, args->nsets);
  return st == SPH_ERR_NOMEM ? SPH_EXIT_IO : SPH_EXIT_USAGE;
}

/* libgomp reads its wait policy once, when it is loaded, before main: a
 * process that must change it starts itself again with it set. Unless the
 * user chose (OMP_WAIT_POLICY or GOMP_SPINCOUNT), threads spin about a
 * microsecond at a barrier, then sleep. libgomp's default spin (300,000
 * turns) made a 2-thread run beside two busy processes 2-25x slower than one
 * thread; sleeping at once (passive) made short steps 20-150 % slower on a
 * quiet machine. README "Threads" has the figures. */
static void short_spin_wait_policy(char **argv) {
  if (getenv("OMP_WAIT_POLICY") || getenv("GOMP_SPINCOUNT"))
    return;
  if (setenv("GOMP_SPINCOUNT", "1000", 1) != 0)
    return;
  execv("/proc/self/exe", argv);
  /* not re-executed: the run goes on with libgomp's default policy */
}

static int dispatch(int argc, char **argv);

/* Under mpirun MPI is started here and ended after the command; only run
 * works over several ranks. */
int main(int argc, char **argv) {
  /* past a file-size limit a write fails with EFBIG, reported like a full
   * disk, instead of the process being killed mid-file */
  signal(SIGXFSZ, SIG_IGN);
  short_spin_wait_policy(argv); /* before MPI: it may start sph again */
  sph_error err;
  sph_error_clear(&err);
  if (sph_domain_init(&argc, &argv, &err) != SPH_OK) {
    sph_app_print_error(&err);
    return SPH_EXIT_USAGE;
  }
  int rc;
  if (sph_domain_world_size() > 1 &&
      (argc < 2 || (strcmp(argv[1], "run") && strcmp(argv[1], "bench")))) {
    if (sph_domain_world_rank() == 0)
      fprintf(stderr,
              "sph: only 'sph run' works over MPI ranks (and 'sph bench "
              "--mpi'; started with %d); run other commands without "
              "mpirun\n",
              sph_domain_world_size());
    rc = SPH_EXIT_USAGE;
  } else {
    rc = dispatch(argc, argv);
  }
  sph_domain_finalize();
  return rc;
}

static int dispatch(int argc, char **argv) {
  remember_command_line(argc, argv);
  if (argc < 2) {
    usage(stdout);
    return SPH_EXIT_OK;
  }
  const char *cmd = argv[1];
  /* sph help CMD: that command's --help */
  char help_flag[] = "--help";
  char *help_argv[] = {argv[0], argc > 2 ? argv[2] : argv[1], help_flag, NULL};
  if (!strcmp(cmd, "help") && argc == 3) {
    argc = 3;
    argv = help_argv;
    cmd = argv[1];
  }
  if (!strcmp(cmd, "run"))
    return sph_cmd_run(argc, argv);
  if (!strcmp(cmd, "check"))
    return sph_cmd_check(argc, argv);
  if (!strcmp(cmd, "list"))
    return sph_cmd_list(argc, argv);
  if (!strcmp(cmd, "study"))
    return sph_cmd_study(argc, argv);
  if (!strcmp(cmd, "imgdiff"))
    return sph_cmd_imgdiff(argc, argv);
  if (!strcmp(cmd, "bench"))
    return sph_cmd_bench(argc, argv);
  if (!strcmp(cmd, "render"))
    return sph_cmd_render(argc, argv);
  if (!strcmp(cmd, "--version") || !strcmp(cmd, "version")) {
    printf("sph %s (commit %s)\n", SPH_VERSION, SPH_GIT_COMMIT);
    return SPH_EXIT_OK;
  }
  if (!strcmp(cmd, "help") || !strcmp(cmd, "--help") || !strcmp(cmd, "-h")) {
    usage(stdout);
    return SPH_EXIT_OK;
  }
  fprintf(stderr, "sph: unknown command '%s'\n\n", cmd);
  usage(stderr);
  return SPH_EXIT_USAGE;
}
