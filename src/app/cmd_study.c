/* sph study: runs a scene over the Cartesian product of --vary values, each
 * case a separate `sph run` process (outputs off but summary.json and
 * energy.csv), and collects results.csv, report.md and gnuplot figures.
 * Every case is validated before any run starts. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "app/app_impl.h"
#include "app/study_impl.h"
#include "io/sink.h"
#include "scene/node.h"
#include "scene/scene.h"
#include "solver/sim.h"

typedef struct study_args {
  const char *sets[SPH_MAX_SETS];
  size_t nsets;
  char *vary_values[STUDY_MAX_KEYS][STUDY_MAX_VALUES];
  int nvalues[STUDY_MAX_KEYS];
  const char *resolution;
  const char *out;
  int resume;
  int dry_run; /* validate and list the cases, run nothing */
} study_args;

static const char study_usage[] =
    "usage: sph study SCENE --vary key=v1,v2,... [--vary ...] [--set k=v]...\n"
    "       [--repeat N] [--threads N] [--resolution KEY] [--out DIR]\n"
    "       [--resume] [--dry-run]\n"
    "  run every combination of the --vary values, each case its own sph\n"
    "  run; write results.csv, report.md and plots (default DIR\n"
    "  outputs/<scene>_study)\n";

/* Splits "key=v1,v2" on the commas outside brackets and quotes. */
static int split_vary(study *s, study_args *a, const char *arg) {
  const char *eq = strchr(arg, '=');
  if (!eq || eq == arg || !eq[1]) {
    fprintf(stderr, "sph study: --vary expects key=v1,v2,..., got '%s'\n", arg);
    return SPH_EXIT_USAGE;
  }
  if (s->nkeys >= STUDY_MAX_KEYS) {
    fprintf(stderr, "sph study: more than %d --vary options\n", STUDY_MAX_KEYS);
    return SPH_EXIT_USAGE;
  }
  int k = s->nkeys++;
  s->keys[k] = strndup(arg, (size_t)(eq - arg));
  for (int j = 0; j < k; ++j)
    if (!strcmp(s->keys[j], s->keys[k])) {
      fprintf(stderr, "sph study: --vary %s given twice\n", s->keys[k]);
      return SPH_EXIT_USAGE;
    }
  const char *p = eq + 1, *start = p;
  int depth = 0;
  char quote = 0;
  for (;; ++p) {
    if (quote) {
      if (*p == quote)
        quote = 0;
      else if (!*p)
        break;
      continue;
    }
    if (*p == '"' || *p == '\'')
      quote = *p;
    else if (*p == '[' || *p == '{')
      ++depth;
    else if ((*p == ']' || *p == '}') && depth > 0)
      --depth;
    else if ((*p == ',' && depth == 0) || !*p) {
      if (p == start) {
        fprintf(stderr, "sph study: --vary %s has an empty value\n",
                s->keys[k]);
        return SPH_EXIT_USAGE;
      }
      if (a->nvalues[k] >= STUDY_MAX_VALUES) {
        fprintf(stderr, "sph study: --vary %s has more than %d values\n",
                s->keys[k], STUDY_MAX_VALUES);
        return SPH_EXIT_USAGE;
      }
      a->vary_values[k][a->nvalues[k]++] = strndup(start, (size_t)(p - start));
      start = p + 1;
      if (!*p)
        break;
    }
  }
  if (quote || depth) {
    fprintf(stderr, "sph study: --vary %s: unbalanced brackets or quotes\n",
            s->keys[k]);
    return SPH_EXIT_USAGE;
  }
  return SPH_EXIT_OK;
}

typedef struct study_parse {
  study *s;
  study_args *a;
} study_parse;

static int study_option(void *ctx, int id, const char *val) {
  study *s = ((study_parse *)ctx)->s;
  study_args *a = ((study_parse *)ctx)->a;
  switch (id) {
  case SPH_OPT_VARY:
    return split_vary(s, a, val);
  case SPH_OPT_SET:
    if (a->nsets >= SPH_MAX_SETS - STUDY_MAX_KEYS - 4) {
      fprintf(stderr, "sph study: too many --set options\n");
      return SPH_EXIT_USAGE;
    }
    a->sets[a->nsets++] = val;
    return SPH_EXIT_OK;
  case SPH_OPT_REPEAT:
    return sph_app_count("study", "repeat", val, 100, &s->repeat);
  case SPH_OPT_THREADS:
    return sph_app_count("study", "threads", val, 1024, &s->threads);
  case SPH_OPT_OUT:
    a->out = val;
    return SPH_EXIT_OK;
  case SPH_OPT_RESOLUTION:
    a->resolution = val;
    return SPH_EXIT_OK;
  case SPH_OPT_RESUME:
    a->resume = 1;
    return SPH_EXIT_OK;
  case SPH_OPT_DRY_RUN:
    a->dry_run = 1;
    return SPH_EXIT_OK;
  default:
    return SPH_EXIT_USAGE;
  }
}

static int study_operand(void *ctx, const char *arg) {
  study *s = ((study_parse *)ctx)->s;
  if (s->scene_path) {
    fprintf(stderr, "sph study: more than one scene given (%s, %s)\n",
            s->scene_path, arg);
    return SPH_EXIT_USAGE;
  }
  s->scene_path = arg;
  return SPH_EXIT_OK;
}

static const int study_allowed[] = {
    SPH_OPT_VARY,    SPH_OPT_SET,     SPH_OPT_REPEAT,
    SPH_OPT_THREADS, SPH_OPT_OUT,     SPH_OPT_RESOLUTION,
    SPH_OPT_RESUME,  SPH_OPT_DRY_RUN, 0};
static const sph_app_command study_command = {
    "study", study_usage, study_allowed, study_option, study_operand};

static int parse_args(int argc, char **argv, study *s, study_args *a) {
  study_parse p = {s, a};
  int rc = sph_app_getopt(&study_command, argc, argv, &p);
  if (rc != SPH_EXIT_OK)
    return rc;
  if (!s->scene_path || !s->nkeys) {
    fputs(study_usage, stderr);
    return SPH_EXIT_USAGE;
  }
  static char path[1024];
  if ((rc = sph_app_scene_path(s->scene_path, path, sizeof path)) !=
      SPH_EXIT_OK)
    return rc;
  s->scene_path = path;
  s->resolution = s->nkeys - 1;
  if (a->resolution) {
    s->resolution = -1;
    for (int k = 0; k < s->nkeys; ++k)
      if (!strcmp(s->keys[k], a->resolution))
        s->resolution = k;
    if (s->resolution < 0) {
      fprintf(stderr,
              "sph study: --resolution %s is not one of the --vary "
              "keys\n",
              a->resolution);
      return SPH_EXIT_USAGE;
    }
  }
  return SPH_EXIT_OK;
}

/* The overrides of case c: --set, then the varied values, then outputs
 * off. Strings are allocated into bufs. */
static size_t case_sets(const study *s, const study_args *a,
                        const study_case *c, int checkpoint_off,
                        const char **sets, char bufs[][1024]) {
  size_t n = 0;
  for (size_t i = 0; i < a->nsets; ++i)
    sets[n++] = a->sets[i];
  for (int k = 0; k < s->nkeys; ++k) {
    snprintf(bufs[k], 1024, "%s=%s", s->keys[k], c->values[k]);
    sets[n++] = bufs[k];
  }
  sets[n++] = "output.vtk=false";
  sets[n++] = "output.png=false";
  sets[n++] = "output.probes=[]";
  if (checkpoint_off)
    sets[n++] = "output.checkpoint_every=1e300";
  return n;
}

static void case_label(const study *s, const study_case *c, char *buf,
                       size_t len) {
  buf[0] = '\0';
  for (int k = 0; k < s->nkeys; ++k) {
    size_t used = strlen(buf);
    snprintf(buf + used, len - used, "%s%s=%s", k ? " " : "", s->keys[k],
             c->values[k]);
  }
}

/* Loads every case as sph run would; prints the first error. */
static int validate(study *s, const study_args *a, int *checkpoint_off) {
  *checkpoint_off = 0;
  for (int i = 0; i < s->ncases; ++i) {
    study_case *c = &s->cases[i];
    const char *sets[SPH_MAX_SETS];
    char bufs[STUDY_MAX_KEYS][1024];
    size_t n = case_sets(s, a, c, *checkpoint_off, sets, bufs);
    sph_error err;
    sph_error_clear(&err);
    sph_scene *scene = NULL;
    sph_sim *sim = NULL;
    sph_status st = sph_scene_load(&scene, s->scene_path, sets, n, &err);
    if (st == SPH_OK && scene->output.checkpoint_every > 0.0 &&
        !*checkpoint_off) {
      /* checkpoints off in every case (set before the first is loaded) */
      *checkpoint_off = 1;
      sph_scene_destroy(scene);
      --i;
      continue;
    }
    if (st == SPH_OK)
      st = sph_sim_create(&sim, scene, &err);
    if (st != SPH_OK) {
      char label[2048];
      case_label(s, c, label, sizeof label);
      sph_app_print_error(&err);
      fprintf(stderr, "sph study: case %d (%s) is refused; nothing was run\n",
              i + 1, label);
      sph_sim_destroy(sim);
      sph_scene_destroy(scene);
      return SPH_EXIT_USAGE;
    }
    c->dp = sim->dp;
    c->particles = (long)sim->ps->n;
    if (i == 0)
      snprintf(s->scene_name, sizeof s->scene_name, "%s", scene->name);
    sph_sim_destroy(sim);
    sph_scene_destroy(scene);
  }
  return SPH_EXIT_OK;
}

static double number(const sph_node *map, const char *key) {
  const sph_node *n = map ? sph_node_child(map, key) : NULL;
  double x;
  sph_error err;
  if (!n || n->kind != SPH_NODE_SCALAR || sph_node_as_double(n, &x, &err))
    return NAN;
  return x;
}

/* Fills row from DIR/summary.json (JSON read as YAML). */
static int read_summary(const char *path, study_row *r) {
  sph_node *root = NULL;
  sph_error err;
  if (sph_node_load_file(&root, path, &err) != SPH_OK)
    return -1;
  r->particles = (long)number(root, "particles");
  r->steps = (unsigned long)number(root, "steps");
  r->wall = number(root, "wall_seconds");
  const sph_node *e = sph_node_child(root, "error");
  for (int k = 0; k < STUDY_NORMS; ++k)
    r->l2[k] = number(e, study_norm_names[k]);
  r->period = number(e, "period");
  const sph_node *en = sph_node_child(root, "energy");
  double e0 = number(en, "initial"), e1 = number(en, "final");
  r->energy_drift = e0 != 0.0 ? (e1 - e0) / fabs(e0) : NAN;
  r->lin_drift = number(root, "linear_momentum_drift");
  r->ang_drift = number(root, "angular_momentum_drift");
  const sph_node *st = sph_node_child(root, "stable");
  int stable = 0;
  if (st)
    sph_node_as_bool(st, &stable, &err);
  r->stable = stable;
  const sph_node *why = sph_node_child(root, "reason");
  snprintf(r->reason, sizeof r->reason, "%s",
           why && why->value ? why->value : "");
  sph_node_destroy(root);
  return 0;
}

/* Runs one repeat of case c in rundir; fills row (reason names a crash). */
static void run_case(const study *s, const study_args *a, const study_case *c,
                     int checkpoint_off, const char *rundir, study_row *row) {
  const char *sets[SPH_MAX_SETS];
  char bufs[STUDY_MAX_KEYS][1024];
  size_t n = case_sets(s, a, c, checkpoint_off, sets, bufs);
  char threads[16];
  snprintf(threads, sizeof threads, "%d", s->threads);
  const char *argv[2 * SPH_MAX_SETS + 16];
  int k = 0;
  argv[k++] = "sph";
  argv[k++] = "run";
  argv[k++] = s->scene_path;
  for (size_t i = 0; i < n; ++i) {
    argv[k++] = "--set";
    argv[k++] = sets[i];
  }
  argv[k++] = "--out";
  argv[k++] = rundir;
  argv[k++] = "--overwrite";
  argv[k++] = "--quiet";
  if (s->threads > 0) {
    argv[k++] = "--threads";
    argv[k++] = threads;
  }
  argv[k] = NULL;
  char log[1300], summary[1300];
  snprintf(log, sizeof log, "%s/run.log", rundir);
  snprintf(summary, sizeof summary, "%s/summary.json", rundir);
  remove(summary);
  memset(row, 0, sizeof *row);
  row->wall = NAN;
  fflush(stdout);
  fflush(stderr);
  pid_t pid = fork();
  if (pid == 0) {
    int fd = sph_open_nofollow(log, O_WRONLY | O_CREAT | O_TRUNC, 0666, NULL);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
      close(fd);
    }
    execv("/proc/self/exe", (char *const *)argv);
    _exit(127);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) < 0) {
    snprintf(row->reason, sizeof row->reason, "cannot start sph run: %s",
             strerror(errno));
    return;
  }
  if (read_summary(summary, row) == 0)
    return;
  for (int j = 0; j < STUDY_NORMS; ++j)
    row->l2[j] = NAN;
  row->period = NAN;
  row->energy_drift = row->lin_drift = row->ang_drift = NAN;
  row->particles = c->particles;
  if (WIFSIGNALED(status))
    snprintf(row->reason, sizeof row->reason,
             "sph run killed by signal %d, no summary.json", WTERMSIG(status));
  else
    snprintf(row->reason, sizeof row->reason,
             "sph run exited with %d, no summary.json", WEXITSTATUS(status));
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Appends the row to results.csv and makes it durable. */
static int append_row(const study *s, const study_case *c, const char *csv) {
  FILE *f = sph_fopen_nofollow(csv, "a", NULL); /* no link (issue 36) */
  if (!f)
    return -1;
  study_csv_row(s, c, f);
  int bad = fflush(f) != 0 || fsync(fileno(f)) != 0;
  return fclose(f) != 0 || bad ? -1 : 0;
}

/* Writes results.csv afresh (temp + rename) with the rows already done. */
static int start_csv(const study *s, const char *csv) {
  char tmp[1200];
  snprintf(tmp, sizeof tmp, "%s.part", csv);
  FILE *f = sph_fopen_nofollow(tmp, "w", NULL); /* no link (issue 36) */
  if (!f)
    return -1;
  study_csv_header(s, f);
  fputc('\n', f);
  for (int i = 0; i < s->ncases; ++i)
    if (s->cases[i].done)
      study_csv_row(s, &s->cases[i], f);
  int bad = fflush(f) != 0 || fsync(fileno(f)) != 0;
  if (fclose(f) != 0 || bad || rename(tmp, csv) != 0) {
    remove(tmp);
    return -1;
  }
  return 0;
}

static void progress(const study *s, const study_case *c, int done, int total,
                     double left) {
  char label[2048];
  case_label(s, c, label, sizeof label);
  const study_row *r = &c->row;
  printf("[%d/%d] %s: %.3g s, %s", done, total, label, r->wall,
         r->stable ? "stable" : "UNSTABLE");
  if (!r->stable && r->reason[0])
    printf(" (%s)", r->reason);
  for (int k = 0; k < STUDY_NORMS; ++k)
    if (isfinite(r->l2[k])) {
      printf(", %s %.2g", study_norm_names[k], r->l2[k]);
      break;
    }
  if (done < total)
    printf(" \xe2\x80\x94 about %.0f s left", left);
  printf("\n");
  fflush(stdout);
}

static int run_study(study *s, study_args *a) {
  int checkpoint_off;
  int rc = validate(s, a, &checkpoint_off);
  if (rc != SPH_EXIT_OK)
    return rc;
  if (a->dry_run) {
    for (int i = 0; i < s->ncases; ++i) {
      char label[2048];
      case_label(s, &s->cases[i], label, sizeof label);
      printf("[%d/%d] %s: %ld particles, dp = %.4g\n", i + 1, s->ncases, label,
             s->cases[i].particles, s->cases[i].dp);
    }
    printf("sph study: %d case%s valid, nothing run (--dry-run)\n", s->ncases,
           s->ncases == 1 ? "" : "s");
    return SPH_EXIT_OK;
  }
  if (a->out)
    snprintf(s->dir, sizeof s->dir, "%s", a->out);
  else
    snprintf(s->dir, sizeof s->dir, "outputs/%s_study", s->scene_name);
  char csv[1100];
  snprintf(csv, sizeof csv, "%s/results.csv", s->dir);
  struct stat sb;
  if (!a->resume && stat(csv, &sb) == 0) {
    fprintf(stderr,
            "sph study: %s holds an earlier study; pass --resume to finish "
            "it or --out DIR to write elsewhere\n",
            s->dir);
    return SPH_EXIT_USAGE;
  }
  if (a->resume) {
    sph_error err;
    sph_error_clear(&err);
    sph_status st = study_csv_read(s, csv, &err);
    if (st == SPH_ERR_ARG) {
      sph_app_print_error(&err);
      return SPH_EXIT_USAGE;
    }
  }
  sph_error derr;
  if (sph_run_output_dir(s->dir, &derr) != SPH_OK) {
    sph_app_print_error(&derr);
    return SPH_EXIT_USAGE;
  }
  char runs[1100];
  snprintf(runs, sizeof runs, "%s/runs", s->dir);
  if (sph_mkdir_p(runs) != 0 || start_csv(s, csv) != 0) {
    fprintf(stderr, "sph study: cannot write %s: %s\n", s->dir,
            strerror(errno));
    return SPH_EXIT_IO;
  }
  int todo = 0, done = 0;
  for (int i = 0; i < s->ncases; ++i)
    todo += !s->cases[i].done;
  printf("sph study: %s, %d case%s (%d to run, %d repeat%s) in %s/\n",
         s->scene_name, s->ncases, s->ncases == 1 ? "" : "s", todo, s->repeat,
         s->repeat == 1 ? "" : "s", s->dir);
  fflush(stdout);
  double t0 = sph_wtime();
  int finished = s->ncases - todo;
  for (int i = 0; i < s->ncases; ++i) {
    study_case *c = &s->cases[i];
    if (c->done)
      continue;
    char rundir[1200];
    snprintf(rundir, sizeof rundir, "%s/%03d", runs, c->index);
    if (sph_mkdir_p(rundir) != 0) {
      fprintf(stderr, "sph study: cannot create %s: %s\n", rundir,
              strerror(errno));
      return SPH_EXIT_IO;
    }
    double walls[100];
    for (int r = 0; r < s->repeat; ++r) {
      run_case(s, a, c, checkpoint_off, rundir, &c->row);
      walls[r] = c->row.wall;
    }
    qsort(walls, (size_t)s->repeat, sizeof *walls, cmp_double);
    study_row *row = &c->row;
    row->wall = s->repeat % 2
                    ? walls[s->repeat / 2]
                    : 0.5 * (walls[s->repeat / 2 - 1] + walls[s->repeat / 2]);
    row->dp = c->dp;
    row->rate = row->wall > 0.0
                    ? (double)row->steps * (double)row->particles / row->wall
                    : NAN;
    c->done = 1;
    ++done;
    ++finished;
    if (append_row(s, c, csv) != 0) {
      fprintf(stderr, "sph study: cannot append to %s: %s\n", csv,
              strerror(errno));
      return SPH_EXIT_IO;
    }
    double elapsed = sph_wtime() - t0;
    progress(s, c, finished, s->ncases, elapsed / done * (todo - done));
  }
  sph_error err;
  sph_error_clear(&err);
  sph_status rst = study_report_write(s, &err);
  if (rst != SPH_OK) {
    sph_app_print_error(&err);
    return sph_app_exit_code(rst);
  }
  printf("report: %s/report.md, results: %s\n", s->dir, csv);
  sph_status st = study_plots_write(s, &err);
  if (st == SPH_ERR_UNSUPPORTED)
    printf("plots skipped: gnuplot not found\n");
  else if (st == SPH_ERR_ARG)
    printf("plots skipped: %s\n", err.message);
  else if (st != SPH_OK) {
    char msg[1024];
    sph_error_format(&err, msg, sizeof msg);
    fprintf(stderr, "sph study: warning: no plots: %s\n", msg);
  } else
    printf("plots: %s/error_vs_time.png, %s/convergence.png\n", s->dir, s->dir);
  return SPH_EXIT_OK;
}

int sph_cmd_study(int argc, char **argv) {
  study s;
  study_args a;
  memset(&s, 0, sizeof s);
  memset(&a, 0, sizeof a);
  s.repeat = 1;
  int rc = parse_args(argc, argv, &s, &a);
  if (rc == SPH_EXIT_OK) {
    long n = 1;
    for (int k = 0; k < s.nkeys && n <= 4096; ++k)
      n *= a.nvalues[k];
    if (n > 4096) {
      fprintf(stderr, "sph study: more than 4096 cases\n");
      rc = SPH_EXIT_USAGE;
    } else {
      s.ncases = (int)n;
      s.cases = calloc((size_t)n, sizeof *s.cases);
      /* the last key varies fastest */
      for (int i = 0; s.cases && i < s.ncases; ++i) {
        s.cases[i].index = i + 1;
        for (int k = s.nkeys - 1, rest = i; k >= 0; --k) {
          s.cases[i].values[k] = a.vary_values[k][rest % a.nvalues[k]];
          rest /= a.nvalues[k];
        }
      }
      rc = s.cases ? run_study(&s, &a) : SPH_EXIT_IO;
    }
  }
  free(s.cases);
  for (int k = 0; k < s.nkeys; ++k) {
    free((char *)s.keys[k]);
    for (int j = 0; j < a.nvalues[k]; ++j)
      free(a.vary_values[k][j]);
  }
  return rc == SPH_APP_HELP ? SPH_EXIT_OK : rc;
}
