/* sph: a headless simulator for large-strain elastic solid dynamics with
 * SPH. Dispatches to the sub-commands (DESIGN.md sec. 1). */
#include <errno.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/app_impl.h"
#include "sph/render.h"
#include "sph/scene.h"
#include "sph/sim.h"
#include "sph/stability.h"

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
          "  bench [--quick] [--json FILE] [--threads N]\n"
          "                       throughput, split and memory of a fixed "
          "suite\n"
          "  help                 this text\n");
}

const char *sph_app_scenes_dir(void) {
  const char *env = getenv("SPH_SCENES_DIR");
  return env && *env ? env : SPH_SOURCE_DIR "/scenes";
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

void sph_app_print_error(const sph_error *err) {
  char buf[2048];
  sph_error_format(err, buf, sizeof buf);
  fprintf(stderr, "sph: %s\n", buf);
}

int sph_app_mkdir_p(const char *path) {
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

int sph_app_parse_args(int argc, char **argv, int first, sph_app_args *args,
                       const char *command) {
  memset(args, 0, sizeof *args);
  for (int i = first; i < argc; ++i) {
    const char *a = argv[i];
    const char *val = NULL;
    int takes = !strcmp(a, "--set") || !strcmp(a, "--out") ||
                !strcmp(a, "--threads") || !strcmp(a, "--resume");
    if (takes) {
      if (i + 1 >= argc) {
        fprintf(stderr, "sph %s: %s needs a value\n", command, a);
        return SPH_EXIT_USAGE;
      }
      val = argv[++i];
    }
    if (!strcmp(a, "--set")) {
      if (args->nsets >= SPH_MAX_SETS) {
        fprintf(stderr, "sph %s: more than %d --set options\n", command,
                SPH_MAX_SETS);
        return SPH_EXIT_USAGE;
      }
      args->sets[args->nsets++] = val;
    } else if (!strcmp(a, "--out")) {
      args->out = val;
    } else if (!strcmp(a, "--resume")) {
      args->resume = val;
    } else if (!strcmp(a, "--threads")) {
      char *end;
      long n = strtol(val, &end, 10);
      if (*end || n < 1 || n > 1024) {
        fprintf(stderr, "sph %s: --threads takes a count from 1 to 1024\n",
                command);
        return SPH_EXIT_USAGE;
      }
      args->threads = (int)n;
    } else if (!strcmp(a, "--overwrite")) {
      args->overwrite = 1;
    } else if (!strcmp(a, "--quiet")) {
      args->quiet = 1;
    } else if (a[0] == '-' && a[1] == '-') {
      fprintf(stderr, "sph %s: unknown option %s\n", command, a);
      return SPH_EXIT_USAGE;
    } else if (!args->scene) {
      args->scene = a;
    } else {
      fprintf(stderr, "sph %s: more than one scene given (%s, %s)\n", command,
              args->scene, a);
      return SPH_EXIT_USAGE;
    }
  }
  if (args->threads > 0)
    omp_set_num_threads(args->threads);
  return SPH_EXIT_OK;
}

int sph_app_load(const sph_app_args *args, const char *path, sph_scene **scene,
                 sph_sim **sim) {
  sph_error err;
  sph_error_clear(&err);
  *scene = NULL;
  *sim = NULL;
  sph_status st = sph_scene_load(scene, path, args->sets, args->nsets, &err);
  if (st == SPH_OK)
    st = sph_sim_create(sim, *scene, &err);
  if (st == SPH_OK)
    st = sph_png_check(*sim, &err);
  if (st == SPH_OK)
    return SPH_EXIT_OK;
  sph_sim_destroy(*sim);
  *sim = NULL;
  sph_app_print_error(&err);
  sph_scene_destroy(*scene);
  *scene = NULL;
  return SPH_EXIT_USAGE;
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

int main(int argc, char **argv) {
  short_spin_wait_policy(argv);
  remember_command_line(argc, argv);
  if (argc < 2)
    return sph_cmd_run(argc, argv);
  const char *cmd = argv[1];
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
