/* The one option parser of every sub-command: getopt_long over a shared
 * option table, each command allowing its own subset; --help and -h print
 * the command's usage. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/app_impl.h"

/* Every option of every command; a command names the ids it allows. */
static const struct option all_options[] = {
    {"help", no_argument, NULL, SPH_OPT_HELP},
    {"set", required_argument, NULL, SPH_OPT_SET},
    {"out", required_argument, NULL, SPH_OPT_OUT},
    {"threads", required_argument, NULL, SPH_OPT_THREADS},
    {"resume", required_argument, NULL, SPH_OPT_RESUME_DIR},
    {"resume", no_argument, NULL, SPH_OPT_RESUME},
    {"overwrite", no_argument, NULL, SPH_OPT_OVERWRITE},
    {"quiet", no_argument, NULL, SPH_OPT_QUIET},
    {"vary", required_argument, NULL, SPH_OPT_VARY},
    {"repeat", required_argument, NULL, SPH_OPT_REPEAT},
    {"resolution", required_argument, NULL, SPH_OPT_RESOLUTION},
    {"dry-run", no_argument, NULL, SPH_OPT_DRY_RUN},
    {"quick", no_argument, NULL, SPH_OPT_QUICK},
    {"json", required_argument, NULL, SPH_OPT_JSON},
    {"tolerance", required_argument, NULL, SPH_OPT_TOLERANCE},
    {"shift", required_argument, NULL, SPH_OPT_SHIFT},
    {"max-fraction", required_argument, NULL, SPH_OPT_MAX_FRACTION},
    {"max-cluster", required_argument, NULL, SPH_OPT_MAX_CLUSTER},
    {"diff", required_argument, NULL, SPH_OPT_DIFF},
    {"field", required_argument, NULL, SPH_OPT_FIELD},
    {"range", required_argument, NULL, SPH_OPT_RANGE},
    {"width", required_argument, NULL, SPH_OPT_WIDTH},
    {"height", required_argument, NULL, SPH_OPT_HEIGHT},
    {"mp4", no_argument, NULL, SPH_OPT_MP4},
    {"keys", no_argument, NULL, SPH_OPT_KEYS},
    {"max-memory", required_argument, NULL, SPH_OPT_MAX_MEMORY},
    {"resolved", no_argument, NULL, SPH_OPT_RESOLVED},
    {"case", required_argument, NULL, SPH_OPT_CASE},
    {"mpi", no_argument, NULL, SPH_OPT_MPI},
    {"device", required_argument, NULL, SPH_OPT_DEVICE},
};
#define NALL (sizeof all_options / sizeof *all_options)

int sph_app_getopt(const sph_app_command *cmd, int argc, char **argv,
                   void *ctx) {
  /* this command's table: --help, then its allowed options */
  struct option table[NALL + 1];
  size_t n = 0;
  table[n++] = all_options[0];
  for (const int *id = cmd->allowed; id && *id; ++id)
    for (size_t k = 1; k < NALL; ++k)
      if (all_options[k].val == *id)
        table[n++] = all_options[k];
  table[n] = (struct option){NULL, 0, NULL, 0};
  /* argv[1] (the command) plays getopt's argv[0]; "-" hands operands over
   * in order, ":" reports a missing value */
  optind = 1;
  opterr = 0;
  int c, rc = SPH_EXIT_OK;
  while (rc == SPH_EXIT_OK &&
         (c = getopt_long(argc - 1, argv + 1, "-:h", table, NULL)) != -1) {
    if (c == 'h' || c == SPH_OPT_HELP) {
      fputs(cmd->usage, stdout);
      return SPH_APP_HELP;
    } else if (c == 1) {
      rc = cmd->operand ? cmd->operand(ctx, optarg) : SPH_EXIT_USAGE;
      if (!cmd->operand)
        fprintf(stderr, "sph %s: takes no operand (%s)\n", cmd->name, optarg);
    } else if (c == ':') {
      fprintf(stderr, "sph %s: %s needs a value\n", cmd->name,
              argv[optind]); /* argv + 1 shifted: the option just read */
      rc = SPH_EXIT_USAGE;
    } else if (c == '?') {
      fprintf(stderr, "sph %s: unknown option %s\n", cmd->name, argv[optind]);
      rc = SPH_EXIT_USAGE;
    } else {
      rc = cmd->option(ctx, c, optarg);
    }
  }
  if (rc == SPH_EXIT_USAGE)
    fprintf(stderr, "%s", cmd->usage);
  return rc;
}

int sph_app_count(const char *command, const char *opt, const char *val,
                  int max, int *out) {
  char *end;
  long n = strtol(val, &end, 10);
  if (end == val || *end || n < 1 || n > max) {
    fprintf(stderr, "sph %s: --%s takes a count from 1 to %d\n", command, opt,
            max);
    return SPH_EXIT_USAGE;
  }
  *out = (int)n;
  return SPH_EXIT_OK;
}

int sph_app_bytes(const char *val, double *out) {
  char *end;
  double x = strtod(val, &end);
  static const char suffixes[] = "kMGT";
  const char *s = *end ? strchr(suffixes, *end) : NULL;
  if (s && *end) {
    x *= s == suffixes       ? 1e3
         : s == suffixes + 1 ? 1e6
         : s == suffixes + 2 ? 1e9
                             : 1e12;
    ++end;
    end += *end == 'B';
  }
  if (end == val || *end || !(x >= 1e6 && x <= 1e18)) {
    fprintf(stderr,
            "sph: --max-memory takes a size from 1M to 1000000T, e.g. 4G, "
            "512M or bytes (got '%s')\n",
            val);
    return SPH_EXIT_USAGE;
  }
  *out = x;
  return SPH_EXIT_OK;
}
