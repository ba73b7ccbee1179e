/* sph run: load and validate a scene, then simulate it to time.end,
 * writing every output through the sinks (DESIGN.md sec. 1-2). Nothing is
 * written until the scene, its particles and its method have all been
 * validated. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/app_impl.h"
#include "app/progress_impl.h"
#include "io/checkpoint.h"
#include "io/sink.h"
#include "render/render.h"
#include "scene/scene.h"
#include "solver/reference.h"
#include "solver/sim.h"
#include "solver/stability.h"

static int file_exists(const char *dir, const char *name) {
  char path[1200];
  struct stat st;
  snprintf(path, sizeof path, "%s/%s", dir, name);
  return stat(path, &st) == 0;
}

/* name is <scene>_NNNN<suffix> (four digits) or <scene><suffix> with
 * numbered = 0 */
static int run_file(const char *name, const char *scene, const char *suffix,
                    int numbered) {
  size_t p = strlen(scene);
  if (strncmp(name, scene, p))
    return 0;
  const char *rest = name + p;
  if (numbered) {
    if (rest[0] != '_' || strspn(rest + 1, "0123456789") != 4)
      return 0;
    rest += 5;
  }
  return !strcmp(rest, suffix);
}

/* name is a VTK piece of a run over MPI ranks, <scene>_NNNN_pR.vtp[.part] */
static int piece_file(const char *name, const char *scene) {
  size_t p = strlen(scene);
  if (strncmp(name, scene, p) || name[p] != '_' ||
      strspn(name + p + 1, "0123456789") != 4 || strncmp(name + p + 5, "_p", 2))
    return 0;
  const char *rest = name + p + 7;
  size_t digits = strspn(rest, "0123456789");
  return digits > 0 && (!strcmp(rest + digits, ".vtp") ||
                        !strcmp(rest + digits, ".vtp.part"));
}

/* name is a checkpoint piece or manifest of a run over MPI ranks,
 * checkpoint_S_pR.sphc or checkpoint_S.sphm (slot S a or b), or .part */
static int checkpoint_piece(const char *name) {
  if (strncmp(name, "checkpoint_", 11) || (name[11] != 'a' && name[11] != 'b'))
    return 0;
  const char *rest = name + 12;
  if (!strcmp(rest, ".sphm") || !strcmp(rest, ".sphm.part"))
    return 1;
  size_t digits = strncmp(rest, "_p", 2) ? 0 : strspn(rest + 2, "0123456789");
  rest += 2 + digits;
  return digits > 0 && (!strcmp(rest, ".sphc") || !strcmp(rest, ".sphc.part"));
}

/* Removes the files in dir that the run named `scene` writes, and its
 * temporary (.part) ones. */
static void remove_run_files(const char *dir, const char *scene) {
  static const char *const names[] = {"summary.json",
                                      "energy.csv",
                                      "probes.csv",
                                      "scene_used.yaml",
                                      SPH_CHECKPOINT_FILE,
                                      SPH_CHECKPOINT_PREVIOUS,
                                      NULL};
  static const char *const numbered[] = {
      ".vtp", ".vtp.part", ".pvtp", ".pvtp.part", ".png", ".png.part", NULL};
  static const char *const single[] = {".pvd", ".pvd.part", ".mp4", ".mp4.part",
                                       NULL};
  char path[2400];
  for (const char *const *n = names; *n; ++n)
    for (int part = 0; part < 2; ++part) {
      snprintf(path, sizeof path, "%s/%s%s", dir, *n, part ? ".part" : "");
      remove(path);
    }
  char sub[2][1100];
  snprintf(sub[0], sizeof sub[0], "%s", dir);
  snprintf(sub[1], sizeof sub[1], "%s/frames", dir);
  for (int k = 0; k < 2; ++k) {
    DIR *d = opendir(sub[k]);
    struct dirent *e;
    while (d && (e = readdir(d))) {
      int ours = 0;
      for (const char *const *x = numbered; *x && !ours; ++x)
        ours = run_file(e->d_name, scene, *x, 1);
      for (const char *const *x = single; *x && !ours && k == 0; ++x)
        ours = run_file(e->d_name, scene, *x, 0);
      ours = ours || (k == 0 && (piece_file(e->d_name, scene) ||
                                 checkpoint_piece(e->d_name)));
      /* a cut path would name another file */
      if (ours && snprintf(path, sizeof path, "%s/%s", sub[k], e->d_name) <
                      (int)sizeof path)
        remove(path);
    }
    if (d)
      closedir(d);
  }
}

/* --overwrite: removes only the files an earlier run of ours wrote, named
 * after the scene its scene_used.yaml records (and this run's), never
 * other files of the folder. */
static void remove_previous(const char *dir, const char *scene) {
  char path[1200], line[256], previous[256] = "";
  snprintf(path, sizeof path, "%s/scene_used.yaml", dir);
  FILE *f = fopen(path, "r");
  while (f && fgets(line, sizeof line, f))
    if (!strncmp(line, "name: ", 6)) {
      line[strcspn(line, "\r\n")] = '\0';
      snprintf(previous, sizeof previous, "%s", line + 6);
      break;
    }
  if (f)
    fclose(f);
  if (previous[0] && strcmp(previous, scene) && !strchr(previous, '/'))
    remove_run_files(dir, previous);
  remove_run_files(dir, scene);
}

static void banner(const sph_sim *sim, const char *dir, const sph_halo *h) {
  const sph_scene *s = sim->scene;
  printf("sph: %s (%s)\n", s->name, s->path);
  printf("  method     %s: %s\n             [%s]\n", sim->method->name,
         sim->method->title, sim->method->reference);
  printf("  particles  %zu in %zu bod%s, dp = %.4g m, kernel %s h = %.4g m\n",
         sph_domain_particles(sim->domain, sim->ps), s->nbodies,
         s->nbodies == 1 ? "y" : "ies", sim->dp,
         sph_kernel_type_name(s->kernel_type), sim->kernel.h);
  printf("  terms     ");
  if (!sim->nterms)
    printf(" (none)");
  for (int i = 0; i < sim->nterms; ++i)
    printf(" %s", sim->terms[i].ops->name);
  printf("\n  time       0 .. %.6g s, output every %.6g s, %d thread%s\n",
         s->t_end, s->output.every, sim->threads, sim->threads == 1 ? "" : "s");
  if (sim->domain)
    printf("  ranks      %d (MPI, recursive coordinate bisection): at most "
           "%.0f owned and %.0f ghost particles a rank; halo %.0f particles "
           "in %.0f messages per exchange\n",
           sph_domain_size(sim->domain), h->max_owned, h->max_ghosts, h->values,
           h->messages);
  printf("  output     %s/\n", dir);
  fflush(stdout);
}

static sph_status write_scene_used(const sph_scene *s, const char *dir,
                                   sph_error *err) {
  char path[1200];
  snprintf(path, sizeof path, "%s/scene_used.yaml", dir);
  sph_atomic_file af;
  sph_status st = sph_atomic_open(&af, path, err);
  if (st != SPH_OK)
    return st;
  sph_provenance prov;
  sph_app_provenance(&prov);
  fprintf(af.f, "# %s as run by sph %s (commit %s), every default filled in\n",
          s->path, prov.version, prov.commit);
  fprintf(af.f, "# command: %s\n", prov.command);
  st = sph_node_write(s->root, af.f, err);
  if (st == SPH_OK)
    st = sph_atomic_commit(&af, err);
  if (st != SPH_OK)
    sph_atomic_abort(&af);
  return st;
}

/* One line: the wall time of each sink and its share of the run's, and
 * the busy time of a sink's own thread (png: the render thread). */
static void print_sink_times(const sph_sink *sinks, int nsinks, double wall) {
  printf("outputs:");
  for (int i = 0; i < nsinks; ++i) {
    printf("%s %s %.2f s (%.1f %%)", i ? "," : "", sinks[i].ops->name,
           sinks[i].seconds,
           wall > 0.0 ? 100.0 * sinks[i].seconds / wall : 0.0);
    if (sinks[i].thread_seconds > 0.0)
      printf(" + render thread %.2f s", sinks[i].thread_seconds);
  }
  printf(" of %.2f s wall\n", wall);
}

/* Over MPI ranks every rank writes its VTK piece and draws its particles
 * into the frames (composited onto rank 0); the other sinks run on rank 0
 * only. */
static int piece_sink(const sph_sim *sim, const sph_sink *sink) {
  return sim->domain &&
         (sink->ops == &sph_vtk_sink_ops || sink->ops == &sph_png_sink_ops ||
          sink->ops == &sph_png_sink_sync_ops);
}

/* Over MPI ranks rank 0's probes read a set of their
 * particles only: the nearest to each probe in the reference configuration
 * (ties: the first created, as the probe sink picks them), by particle id,
 * their fields taken from their owners at every frame. */
typedef struct probe_view {
  sph_particles *ps;    /* the probes' distinct particles by id */
  double *rows, *got;   /* a flag then the fields, per particle */
  unsigned long fields; /* the probes' (bit 1ul << f) */
  int w;                /* doubles a row */
} probe_view;

static int cmp_id(const void *pa, const void *pb) {
  int64_t a = *(const int64_t *)pa, b = *(const int64_t *)pb;
  return (a > b) - (a < b);
}

/* the rows of the probes' particles this rank owns: fields (the position
 * only with X) or the reference positions, to rank 0's set (collective) */
static sph_status probe_view_fill(probe_view *pv, sph_sim *sim, int X,
                                  sph_error *err) {
  const sph_particles *ps = sim->ps;
  sph_particles *v = pv->ps;
  size_t m = v->n, w = (size_t)pv->w;
  memset(pv->rows, 0, m * w * sizeof *pv->rows);
  for (size_t a = 0; a < ps->n; ++a) {
    const int64_t *k = bsearch(&ps->id[a], v->id, m, sizeof *v->id, cmp_id);
    if (!k)
      continue;
    double *r = pv->rows + w * (size_t)(k - v->id);
    r[0] = 1.0;
    size_t c = 1;
    for (int f = 0; f < SPH_FIELD_COUNT; ++f) {
      if (X ? f != SPH_FIELD_POSITION0 : !(pv->fields & 1ul << f))
        continue;
      size_t nc = (size_t)sph_field_components((sph_field)f);
      memcpy(r + c, ps->field[f] + nc * a, nc * sizeof *r);
      c += nc;
    }
  }
  SPH_TRY(sph_domain_pick(sim->domain, pv->rows, m, pv->w, pv->got, err));
  for (size_t k = 0; k < m && sph_domain_rank(sim->domain) == 0; ++k) {
    size_t c = 1;
    for (int f = 0; f < SPH_FIELD_COUNT; ++f) {
      if (X ? f != SPH_FIELD_POSITION0 : !(pv->fields & 1ul << f))
        continue;
      size_t nc = (size_t)sph_field_components((sph_field)f);
      memcpy(v->field[f] + nc * k, pv->got + w * k + c, nc * sizeof *pv->got);
      c += nc;
    }
  }
  return SPH_OK;
}

static void probe_view_destroy(probe_view *pv) {
  sph_particles_destroy(pv->ps);
  free(pv->rows);
  free(pv->got);
}

/* the probes' particles: the nearest owned one of each rank, then the
 * nearest of those, ties to the smallest id (collective) */
static sph_status probe_view_create(probe_view *pv, sph_sim *sim,
                                    sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_particles *ps = sim->ps;
  size_t np = s->output.nprobes, m = 0;
  int64_t *ids = malloc((np + 1) * sizeof *ids);
  sph_status st = ids ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "probes");
  SPH_TRY(sph_domain_agree(sim->domain, st, err));
  for (size_t k = 0; k < np; ++k) {
    double best = INFINITY, id = INFINITY;
    for (size_t a = 0; a < ps->n; ++a) {
      const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * a;
      double d = 0.0;
      for (int c = 0; c < 3; ++c)
        d += pow(X[c] - s->output.probes[k].at[c], 2);
      if (d < best || (d == best && (double)ps->id[a] < id)) {
        best = d;
        id = (double)ps->id[a];
      }
    }
    double dmin = sph_domain_min(sim->domain, best);
    ids[k] = (int64_t)sph_domain_min(sim->domain, best == dmin ? id : INFINITY);
  }
  qsort(ids, np, sizeof *ids, cmp_id);
  for (size_t k = 0; k < np; ++k)
    if (m == 0 || ids[k] != ids[m - 1])
      ids[m++] = ids[k];
  st = sph_particles_create(&pv->ps, m ? m : 1, ps->dim, err);
  int w = 4; /* the flag, then the reference position or the fields */
  for (size_t k = 0; st == SPH_OK && k < np; ++k)
    for (int i = 0; st == SPH_OK && i < s->output.probes[k].nfields; ++i) {
      int f = s->output.probes[k].fields[i];
      if (ps->field[f] && f != SPH_FIELD_POSITION0 &&
          !(pv->fields & 1ul << f)) {
        st = sph_particles_require(pv->ps, (sph_field)f, err);
        pv->fields |= 1ul << f;
        w += sph_field_components((sph_field)f);
      }
    }
  if (st == SPH_OK) {
    pv->w = w;
    pv->ps->n = m;
    memcpy(pv->ps->id, ids, m * sizeof *ids);
    pv->rows = malloc((m * (size_t)w + 1) * sizeof *pv->rows);
    pv->got = calloc(m * (size_t)w + 1, sizeof *pv->got);
    if (!pv->rows || !pv->got)
      st = sph_error_set(err, SPH_ERR_NOMEM, "probes");
  }
  free(ids);
  SPH_TRY(sph_domain_agree(sim->domain, st, err));
  return probe_view_fill(pv, sim, 1, err);
}

/* derive, then every sink and the verdict see the same frame; over MPI
 * ranks the energies and momenta are summed over them, every rank judges
 * its particles for the verdict and draws its part of the PNG frame, and
 * rank 0's sinks see `view`, the run with its probes' particles */
static sph_status output_frame(sph_sim *sim, sph_sim *view, probe_view *pv,
                               sph_sink *sinks, int nsinks, sph_verdict *v,
                               int index, sph_error *err) {
  sph_status st = sim->method->derive(sim, err);
  if ((st = sph_domain_agree(sim->domain, st, err)) != SPH_OK)
    return st;
  double momentum[6];
  sph_frame fr = {.time = sim->t,
                  .step = sim->steps,
                  .index = index,
                  .sim = sim,
                  .ps = sim->ps,
                  .momentum = momentum};
  sim->method->energy(sim, &fr.kinetic, &fr.strain);
  sph_momentum(sim->ps, momentum, momentum + 3);
  sph_frame whole = fr;
  int root = sph_domain_rank(sim->domain) == 0;
  if (sim->domain) {
    double e[2] = {fr.kinetic, fr.strain};
    sph_domain_sum(sim->domain, e, 2);
    sph_domain_sum(sim->domain, momentum, 6);
    fr.kinetic = whole.kinetic = e[0];
    fr.strain = whole.strain = e[1];
    if (pv->ps)
      SPH_TRY(probe_view_fill(pv, sim, 0, err));
    if (root) {
      sph_particles *all = view->ps;
      *view = *sim;
      view->ps = all;
      whole.sim = view;
      whole.ps = all;
    }
  }
  for (int i = 0; i < nsinks; ++i) {
    int piece = piece_sink(sim, &sinks[i]);
    if ((st != SPH_OK && !piece) || (!root && !piece))
      continue; /* pieces are collective: every rank writes its own */
    double t0 = sph_wtime();
    sph_status sst = sinks[i].ops->write(&sinks[i], piece ? &fr : &whole, err);
    st = st == SPH_OK ? sst : st;
    sinks[i].seconds += sph_wtime() - t0;
  }
  /* the verdict is collective: every rank observes once the sinks agree */
  st = sph_domain_agree(sim->domain, st, err);
  if (st == SPH_OK)
    st = sph_verdict_observe(v, &fr, err);
  if (st == SPH_OK && sim->reference) /* collective: from its owner */
    sph_reference_observe(sim->reference, &fr);
  return sph_domain_agree(sim->domain, st, err);
}

static const int run_allowed[] = {
    SPH_OPT_SET,       SPH_OPT_OUT,   SPH_OPT_THREADS,    SPH_OPT_RESUME_DIR,
    SPH_OPT_OVERWRITE, SPH_OPT_QUIET, SPH_OPT_MAX_MEMORY, 0};
static const sph_app_command run_command = {
    "run",
    "usage: sph run [SCENE] [--set key=value]... [--out DIR] [--threads N]\n"
    "               [--overwrite] [--quiet] [--resume DIR] [--max-memory "
    "SIZE]\n"
    "  simulate SCENE (a file, or a shipped scene's name: sph list; default\n"
    "  twisting_column) to its end time; exit 0 stable, 1 unstable, 2 bad\n"
    "  input or usage, 3 I/O failure; a run estimated to need more than\n"
    "  SIZE (4G, 512M; default 90 % of the memory available) is refused\n",
    run_allowed, NULL, NULL};

/* SIGINT, SIGTERM, SIGHUP, SIGUSR1 (which mpirun forwards to the ranks
 * without ending them): the first asks the run to stop at the next step
 * boundary (outputs finished, a checkpoint, summary.json with stopped_by);
 * a second one ends the process at once. */
static volatile sig_atomic_t stop_signal;

static void on_stop_signal(int signo) {
  if (stop_signal) {
    signal(signo, SIG_DFL);
    raise(signo);
    return;
  }
  stop_signal = signo;
}

static void catch_stop_signals(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  sigaction(SIGHUP, &sa, NULL);
  sigaction(SIGUSR1, &sa, NULL);
}

static const char *signal_name(int signo) {
  return signo == SIGINT    ? "SIGINT"
         : signo == SIGTERM ? "SIGTERM"
         : signo == SIGHUP  ? "SIGHUP"
         : signo == SIGUSR1 ? "SIGUSR1"
                            : "a signal";
}

/* One run per output folder: an exclusive lock on DIR/.sph.lock, held until
 * the process ends, with the holder's pid in the file. Returns the open
 * descriptor, or -1 with *holder the running pid (0: the lock file could
 * not be made). */
static int lock_output(const char *dir, long *holder) {
  char path[1100];
  snprintf(path, sizeof path, "%s/.sph.lock", dir);
  *holder = 0;
  int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0)
    return -1;
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    char buf[32] = "";
    ssize_t k = pread(fd, buf, sizeof buf - 1, 0);
    buf[k > 0 ? k : 0] = '\0';
    *holder = strtol(buf, NULL, 10);
    *holder = *holder > 0 ? *holder : 1;
    close(fd);
    return -1;
  }
  char pid[32];
  int len = snprintf(pid, sizeof pid, "%ld\n", (long)getpid());
  if (ftruncate(fd, 0) != 0 || pwrite(fd, pid, (size_t)len, 0) != len) {
    close(fd);
    return -1;
  }
  return fd;
}

int sph_cmd_run(int argc, char **argv) {
  sph_app_args args;
  int rc = sph_app_parse_args(argc, argv, &args, &run_command);
  if (rc != SPH_EXIT_OK)
    return rc == SPH_APP_HELP ? SPH_EXIT_OK : rc;
  const char *path = args.scene ? args.scene : sph_app_default_scene();
  /* over MPI ranks rank 0 prints for all */
  int root = sph_domain_world_rank() == 0;
  if (!root && !freopen("/dev/null", "w", stdout))
    return SPH_EXIT_IO;
  sph_scene *scene;
  sph_sim *sim;
  if ((rc = sph_app_load(&args, path, &scene, &sim)) != SPH_EXIT_OK)
    return rc;
  sph_error err;
  sph_error_clear(&err);
  sph_status st = SPH_OK;
  char dir[1024];
  /* rank 0's view of a distributed run: its probes' particles (below) */
  sph_sim view = *sim;
  probe_view pv = {0};
  const sph_sim *whole = sim->domain ? &view : sim;
  if (args.resume && args.out && strcmp(args.resume, args.out)) {
    fprintf(stderr, "sph: --resume continues in its own folder; drop --out "
                    "or give the same folder\n");
    sph_sim_destroy(sim);
    sph_scene_destroy(scene);
    return SPH_EXIT_USAGE;
  }
  const char *given = args.resume ? args.resume : args.out;
  if (given && strlen(given) > 900) { /* room for the files' own names */
    fprintf(stderr,
            "sph: the output folder's path is %zu bytes long; at "
            "most 900\n",
            strlen(given));
    sph_sim_destroy(sim);
    sph_scene_destroy(scene);
    return SPH_EXIT_USAGE;
  }
  if (args.resume)
    snprintf(dir, sizeof dir, "%s", args.resume);
  else if (args.out)
    snprintf(dir, sizeof dir, "%s", args.out);
  else
    snprintf(dir, sizeof dir, "outputs/%s", scene->name);
  /* a folder that cannot be made or written in: exit 2 either way */
  long holder = 0;
  int lock_fd = -1;
  struct stat rst;
  if (!root)
    ; /* rank 0 makes, locks and checks the folder for every rank */
  else if (args.resume && stat(dir, &rst) != 0) /* not made for a resume */
    st = sph_error_set(&err, SPH_ERR_ARG, "nothing to resume in %s: %s", dir,
                       strerror(errno));
  else
    st = sph_app_output_dir(dir, &err);
  if (st == SPH_OK && root && (lock_fd = lock_output(dir, &holder)) < 0) {
    if (holder > 0)
      st = sph_error_set(&err, SPH_ERR_ARG,
                         "%s is in use by another sph run (pid %ld); wait for "
                         "it or write elsewhere with --out DIR",
                         dir, holder);
    else
      st = sph_error_set(&err, SPH_ERR_ARG,
                         "cannot write in the output folder %s: %s", dir,
                         strerror(errno));
  }
  /* after the lock: a folder in use says so, whatever it holds */
  if (st == SPH_OK && root && !args.overwrite && !args.resume &&
      (file_exists(dir, "summary.json") || file_exists(dir, "scene_used.yaml")))
    st = sph_error_set(&err, SPH_ERR_ARG,
                       "%s holds the results of an earlier run; pass "
                       "--overwrite to replace them or --out DIR to write "
                       "elsewhere",
                       dir);
  st = sph_domain_agree(sim->domain, st, &err);
  if (st != SPH_OK) {
    sph_app_print_error(&err);
    if (lock_fd >= 0)
      close(lock_fd);
    sph_sim_destroy(sim);
    sph_scene_destroy(scene);
    return SPH_EXIT_USAGE;
  }
  if (args.overwrite && !args.resume && root)
    remove_previous(dir, scene->name);
  sph_halo halo = sph_domain_halo(sim->domain); /* collective */
  /* rank 0's probes' particles, from their owners */
  if (st == SPH_OK && sim->domain && scene->output.nprobes) {
    st = probe_view_create(&pv, sim, &err);
    if (st == SPH_OK && root)
      view.ps = pv.ps;
  }
  if (!args.quiet)
    banner(whole, dir, &halo);

  sph_sink sinks[4];
  int nsinks = 0;
  sinks[nsinks++] = (sph_sink){.ops = &sph_energy_sink_ops};
  if (scene->output.vtk)
    sinks[nsinks++] = (sph_sink){.ops = &sph_vtk_sink_ops};
  if (scene->output.nprobes)
    sinks[nsinks++] = (sph_sink){.ops = &sph_probe_sink_ops};
  if (scene->output.png.enabled) {
    /* a render thread only where a core is left for it */
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    sinks[nsinks++] =
        (sph_sink){.ops = sim->threads < cores ? &sph_png_sink_ops
                                               : &sph_png_sink_sync_ops};
  }
  sph_verdict *verdict = NULL;
  int index = 0;
  if (st == SPH_OK)
    st = sph_verdict_create(&verdict, sim, &err); /* collective */
  if (st == SPH_OK && args.resume) {
    char used[1200];
    st = sph_checkpoint_resume(dir, sim, verdict, &index, used, sizeof used,
                               &err);
    if (st != SPH_OK) {
      sph_app_print_error(&err);
      sph_verdict_destroy(verdict);
      probe_view_destroy(&pv);
      sph_sim_destroy(sim);
      sph_scene_destroy(scene);
      return SPH_EXIT_USAGE; /* the checkpoint is the run's input */
    }
    if (!args.quiet)
      printf("  resume     %s: t = %.6g s, step %lu, next output %d\n", used,
             sim->t, sim->steps, index);
  }
  if (st == SPH_OK && root)
    st = write_scene_used(scene, dir, &err);
  for (int i = 0; i < nsinks && st == SPH_OK; ++i) {
    int piece = piece_sink(sim, &sinks[i]);
    if (!root && !piece)
      continue;
    double t0 = sph_wtime();
    sinks[i].resume_frames = index;
    st = sinks[i].ops->open(&sinks[i], piece ? sim : whole, dir, &err);
    sinks[i].seconds += sph_wtime() - t0;
  }
  st = sph_domain_agree(sim->domain, st, &err);

  /* over MPI ranks every rank catches them; they agree on stopping */
  catch_stop_signals();
  sph_progress prog;
  sph_progress_start(&prog, scene->t_end, args.quiet || !root);
  double wall0 = sph_wtime();
  double comm0 = sph_domain_seconds(sim->domain);
  int completed = 0;
  if (st == SPH_OK && index == 0)
    st = output_frame(sim, &view, &pv, sinks, nsinks, verdict, index++, &err);
  double t_end = scene->t_end, ckpt = scene->output.checkpoint_every;
  double eps = 1e-12 * t_end;
  double next_ckpt =
      ckpt > 0.0 ? ckpt * (floor(sim->t / ckpt + 1e-9) + 1.0) : INFINITY;
  while (st == SPH_OK && verdict->stable && sim->t < t_end - eps &&
         !sph_domain_max(sim->domain, stop_signal)) {
    double next = sph_output_time(scene, index);
    st = sph_sim_step(sim, next - sim->t, &err);
    if (st != SPH_OK)
      break;
    sph_progress_step(&prog, sim->t, sim->steps);
    if (sim->t >= next - eps) {
      sim->t = next; /* land exactly on the output time */
      st = output_frame(sim, &view, &pv, sinks, nsinks, verdict, index++, &err);
      sph_progress_output(&prog, sim->t, sim->steps);
    }
    if (st == SPH_OK && sim->t >= next_ckpt - eps && sim->t < t_end - eps) {
      /* rows before the checkpoint reach the disk first */
      for (int i = 0; i < nsinks && st == SPH_OK; ++i)
        if (sinks[i].ops->flush && (root || piece_sink(sim, &sinks[i]))) {
          double t0 = sph_wtime();
          st = sinks[i].ops->flush(&sinks[i], &err);
          sinks[i].seconds += sph_wtime() - t0;
        }
      st = sph_domain_agree(sim->domain, st, &err);
      if (st == SPH_OK)
        st = sph_checkpoint_write(dir, sim, verdict, index, &err);
      next_ckpt += ckpt * floor((sim->t - next_ckpt) / ckpt + 1.0);
    }
  }
  sph_progress_finish(&prog);
  int stopped = (int)sph_domain_max(sim->domain, stop_signal);
  if (stopped && st == SPH_OK && sim->t < t_end - eps) {
    /* stopped between steps: what was written reaches the disk, then a
     * checkpoint to --resume from */
    for (int i = 0; i < nsinks && st == SPH_OK; ++i)
      if (sinks[i].ops->flush && (root || piece_sink(sim, &sinks[i])))
        st = sinks[i].ops->flush(&sinks[i], &err);
    st = sph_domain_agree(sim->domain, st, &err);
    if (st == SPH_OK)
      st = sph_checkpoint_write(dir, sim, verdict, index, &err);
  } else {
    stopped = 0;
  }
  int failed_step = st != SPH_OK && st != SPH_ERR_IO;
  if (st == SPH_OK && verdict->stable && !stopped)
    completed = 1;
  if (failed_step && verdict)
    sph_verdict_fail_step(verdict, sim->t, &err);
  /* close the sinks (files renamed into place) and write the summary */
  sph_error cerr;
  int io_failed = st == SPH_ERR_IO;
  for (int i = 0; i < nsinks; ++i) {
    double t0 = sph_wtime();
    if (sinks[i].data && !io_failed &&
        sinks[i].ops->close(&sinks[i], &cerr) != SPH_OK) {
      io_failed = 1;
      err = cerr;
    }
    if (sinks[i].ops->destroy)
      sinks[i].ops->destroy(&sinks[i]);
    sinks[i].seconds += sph_wtime() - t0;
  }
  /* the run's wall time includes waiting for the last frames */
  double wall = sph_wtime() - wall0;
  /* over MPI ranks: the most a rank spent in exchanges and reductions
   * (waits included) and outside them (collective) */
  double comm = sph_domain_seconds(sim->domain) - comm0;
  double work = sph_domain_max(sim->domain, wall - comm);
  comm = sph_domain_max(sim->domain, comm);
  /* the errors against the reference, in the serial order (collective) */
  sph_reference_error ref_err;
  if (verdict && sim->reference &&
      sph_reference_errors(sim->reference, sim, &ref_err, &cerr) != SPH_OK &&
      !io_failed) {
    io_failed = 1;
    err = cerr;
  }
  /* the animation of the frames, once the run has ended */
  sph_mp4_info mp4 = {0};
  sph_error merr;
  sph_status mst = SPH_OK;
  int mp4_tried = scene->output.png.enabled && scene->output.png.mp4 &&
                  !io_failed && index > 0 && root;
  if (mp4_tried)
    mst = sph_mp4_assemble(dir, scene->name, index, scene->output.png.fps, &mp4,
                           &merr);
  if (verdict && !io_failed && root) {
    char spath[1200];
    snprintf(spath, sizeof spath, "%s/summary.json", dir);
    sph_provenance prov;
    sph_app_provenance(&prov);
    sph_particles *all = view.ps;
    view = *sim; /* the counts and timers of the end of the run */
    view.ps = all;
    if (sph_summary_write(spath, whole, &prov, verdict,
                          sim->reference ? &ref_err : NULL, wall, sinks, nsinks,
                          mp4_tried && mst == SPH_OK ? mp4.seconds : -1.0,
                          completed, stopped ? signal_name(stopped) : NULL,
                          &cerr) != SPH_OK) {
      io_failed = 1;
      err = cerr;
    }
  }
  if (io_failed) {
    sph_app_print_error(&err);
    rc = sph_app_exit_code(err.code);
  } else if (stopped) {
    printf("stopped by %s at t = %.6g s (%lu steps, %.2f s wall): outputs "
           "and a checkpoint written; continue with --resume %s\n",
           signal_name(stopped), sim->t, sim->steps, wall, dir);
    rc = 128 + stopped;
  } else if (verdict && !verdict->stable) {
    printf("verdict: UNSTABLE - %s tripped at t = %.6g s: %s (%lu steps, "
           "%.2f s wall)\n",
           sph_indicator_key(verdict->first), verdict->t_tripped,
           verdict->reason, sim->steps, wall);
    rc = SPH_EXIT_FAIL;
  } else {
    printf("verdict: stable (%lu steps, %.2f s wall, %.3g particle-steps/s)\n",
           sim->steps, wall,
           wall > 0
               ? (double)sim->steps *
                     (double)sph_domain_particles(sim->domain, sim->ps) / wall
               : 0.0);
    rc = SPH_EXIT_OK;
  }
  if (!io_failed && !args.quiet)
    print_sink_times(sinks, nsinks, wall);
  if (sim->domain && !args.quiet)
    printf("mpi: %d ranks; exchanges and reductions at most %.2f s of a "
           "rank's wall (waits included), the rest at most %.2f s\n",
           sph_domain_size(sim->domain), comm, work);
  sph_domain_moves mv = sph_domain_moves_of(sim->domain);
  if (mv.rebuilds > 0.0 && !args.quiet)
    printf("mpi: %.0f halo rebuilds, %.0f particles migrated, %.0f "
           "re-balances (over %.0f %% imbalance); at most %.0f ghost "
           "particles a rank, %.0f particles a halo exchange\n",
           mv.rebuilds, mv.migrated, mv.rebalances,
           100.0 * SPH_DOMAIN_IMBALANCE, mv.ghosts_max, mv.halo_max);
  if (mp4_tried && mst == SPH_OK)
    printf("mp4: %s (%d frames, %s, %.1f s)\n", mp4.path, mp4.frames, mp4.codec,
           mp4.seconds);
  else if (mp4_tried && mst == SPH_ERR_UNSUPPORTED)
    printf("mp4 skipped: ffmpeg not found\n");
  else if (mp4_tried) {
    char msg[1024];
    sph_error_format(&merr, msg, sizeof msg);
    fprintf(stderr, "sph: warning: no mp4: %s\n", msg);
  }
  rc = sph_domain_bcast_int(sim->domain, rc); /* rank 0's verdict */
  sph_verdict_destroy(verdict);
  probe_view_destroy(&pv);
  sph_sim_destroy(sim);
  sph_scene_destroy(scene);
  if (lock_fd >= 0)
    close(lock_fd); /* the folder is free for the next run */
  return rc;
}
