/* The run's output folder (docs/design.md sec. 2; docs/outputs.md, the
 * output folder): one run per folder (a lock), a manifest of the files runs
 * wrote there, --overwrite removing only those, and scene_used.yaml. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/checkpoint.h"
#include "solver/run_impl.h"

int sph_run_file_exists(const char *dir, const char *name) {
  char path[1200];
  struct stat st;
  snprintf(path, sizeof path, "%s/%s", dir, name);
  return stat(path, &st) == 0;
}

/* ---- the manifest, DIR/.sph.manifest (issue 36 item 4) ----
 * One line a file, "SIZE NAME": every file a run of sph may write in the
 * folder (SIZE -1: planned, written before the run writes anything) and,
 * once the run is closed, the files it wrote with their sizes. --overwrite
 * removes only these; a file under one of the names a run would write that
 * is not in it (or whose size changed) is refused, named. */
#define MANIFEST ".sph.manifest"

typedef struct entry {
  char name[96];
  long long size;
} entry;

typedef struct names {
  entry *e;
  size_t n, cap;
} names;

static int entry_cmp(const void *a, const void *b) {
  return strcmp(((const entry *)a)->name, ((const entry *)b)->name);
}

/* a name sph writes: letters, digits, '_', '-', '.', not leading '.', in
 * the folder or its frames/ (a crafted manifest names nothing else) */
static int name_ok(const char *name) {
  const char *base = strncmp(name, "frames/", 7) ? name : name + 7;
  return *base && *base != '.' &&
         strspn(base, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                      "0123456789_-.") == strlen(base) &&
         strlen(name) < sizeof((entry *)0)->name;
}

static int add(names *m, const char *name, long long size) {
  if (!name_ok(name))
    return 0;
  if (m->n == m->cap) {
    size_t cap = m->cap ? 2 * m->cap : 64;
    entry *e = realloc(m->e, cap * sizeof *e);
    if (!e)
      return -1;
    m->e = e;
    m->cap = cap;
  }
  snprintf(m->e[m->n].name, sizeof m->e[m->n].name, "%s", name);
  m->e[m->n++].size = size;
  return 0;
}

/* a name and its temporary (.part) */
static int add_both(names *m, const char *name) {
  char part[200];
  snprintf(part, sizeof part, "%s.part", name);
  return add(m, name, -1) || add(m, part, -1);
}

/* sorted, each name once (-1 if any of its entries is planned) */
static void sort_unique(names *m) {
  if (m->n)
    qsort(m->e, m->n, sizeof *m->e, entry_cmp);
  size_t k = 0;
  for (size_t i = 0; i < m->n; ++i)
    if (!k || strcmp(m->e[k - 1].name, m->e[i].name))
      m->e[k++] = m->e[i];
    else if (m->e[i].size < 0) /* planned: to be written again */
      m->e[k - 1].size = -1;
  m->n = k;
}

static const entry *find(const names *m, const char *name) {
  entry key;
  snprintf(key.name, sizeof key.name, "%s", name);
  return m->n ? bsearch(&key, m->e, m->n, sizeof *m->e, entry_cmp) : NULL;
}

/* every file a run of `scene` with `frames` output frames over `ranks`
 * MPI ranks may write here (frames: VTK files with vtk, PNG with png) */
static int planned(names *m, const char *scene, int frames, int ranks, int vtk,
                   int png) {
  static const char *const fixed[] = {"summary.json",
                                      "energy.csv",
                                      "probes.csv",
                                      "scene_used.yaml",
                                      SPH_CHECKPOINT_FILE,
                                      SPH_CHECKPOINT_PREVIOUS,
                                      NULL};
  char name[160];
  int bad = 0;
  for (const char *const *n = fixed; *n; ++n)
    bad |= add_both(m, *n);
  static const char *const single[] = {".pvd", ".mp4", NULL};
  for (const char *const *x = single; *x; ++x) {
    snprintf(name, sizeof name, "%s%s", scene, *x);
    bad |= add_both(m, name);
  }
  for (int i = 0; i < frames && !bad; ++i) {
    snprintf(name, sizeof name, "%s_%04d.vtp", scene, i);
    bad |= vtk && ranks == 1 && add_both(m, name);
    snprintf(name, sizeof name, "frames/%s_%04d.png", scene, i);
    bad |= png && add_both(m, name);
    for (int r = 0; vtk && ranks > 1 && r < ranks && !bad; ++r) {
      snprintf(name, sizeof name, "%s_%04d_p%d.vtp", scene, i, r);
      bad |= add_both(m, name);
    }
    if (vtk && ranks > 1) {
      snprintf(name, sizeof name, "%s_%04d.pvtp", scene, i);
      bad |= add_both(m, name);
    }
  }
  for (int s = 0; s < 2 && ranks > 1; ++s) {
    snprintf(name, sizeof name, "checkpoint_%c.sphm", "ab"[s]);
    bad |= add_both(m, name);
    for (int r = 0; r < ranks; ++r) {
      snprintf(name, sizeof name, "checkpoint_%c_p%d.sphc", "ab"[s], r);
      bad |= add_both(m, name);
    }
  }
  return bad;
}

/* the manifest in the folder (none: empty) */
static void manifest_read(const char *dir, names *m) {
  char path[1200], line[256];
  snprintf(path, sizeof path, "%s/" MANIFEST, dir);
  FILE *f = NULL; /* never a FIFO or a link's target */
  if (sph_fopen_input(path, &f, NULL, NULL) != SPH_OK)
    return;
  while (fgets(line, sizeof line, f)) {
    long long size;
    char name[128];
    if (line[0] != '#' && sscanf(line, "%lld %127s", &size, name) == 2 &&
        add(m, name, size < 0 ? -1 : size))
      break;
  }
  fclose(f);
  sort_unique(m);
}

static sph_status manifest_write(const char *dir, const names *m,
                                 sph_error *err) {
  char path[1200];
  snprintf(path, sizeof path, "%s/" MANIFEST, dir);
  sph_atomic_file af;
  SPH_TRY(sph_atomic_open(&af, path, err));
  fprintf(af.f, "# the files sph writes in this folder (size, name; -1: "
                "planned); --overwrite removes only these\n");
  for (size_t i = 0; i < m->n; ++i)
    fprintf(af.f, "%lld %s\n", m->e[i].size, m->e[i].name);
  sph_status st = sph_atomic_commit(&af, err);
  if (st != SPH_OK)
    sph_atomic_abort(&af);
  return st;
}

/* the size of DIR/name if it is there (-2: not there, -3: not a regular
 * file, or under a frames/ that is a link: never ours) */
static long long size_of(const char *dir, const char *name, int frames_link) {
  char path[1200];
  struct stat st;
  snprintf(path, sizeof path, "%s/%s", dir, name);
  if (lstat(path, &st) != 0)
    return -2;
  if (!S_ISREG(st.st_mode) || (frames_link && !strncmp(name, "frames/", 7)))
    return -3;
  return (long long)st.st_size;
}

static int frames_linked(const char *dir) {
  char path[1200];
  struct stat st;
  snprintf(path, sizeof path, "%s/frames", dir);
  return lstat(path, &st) == 0 && S_ISLNK(st.st_mode);
}

sph_status sph_run_manifest_start(const char *dir, const sph_scene *scene,
                                  int frames, int ranks, int overwrite,
                                  sph_error *err) {
  names old = {0}, plan = {0};
  sph_status st = SPH_OK;
  manifest_read(dir, &old);
  if (planned(&plan, scene->name, frames, ranks, scene->output.vtk,
              scene->output.png.enabled))
    st = sph_error_set(err, SPH_ERR_NOMEM, "output manifest");
  sort_unique(&plan);
  int link = frames_linked(dir);
  /* nothing of the user's is written over, and nothing changed removed */
  for (size_t i = 0; i < plan.n && st == SPH_OK; ++i) {
    const char *n = plan.e[i].name;
    long long size = size_of(dir, n, link);
    const entry *e = find(&old, n);
    if (size == -3)
      st = sph_error_set(err, SPH_ERR_ARG,
                         "%s/%s is not a regular file (a link, a FIFO or a "
                         "folder) and sph never writes through one; move it "
                         "away or write elsewhere with --out DIR",
                         dir, n);
    else if (size != -2 && !e)
      st = sph_error_set(err, SPH_ERR_ARG,
                         "%s/%s is not a file an earlier sph run wrote "
                         "here (not in %s/" MANIFEST "); move it away or "
                         "write elsewhere with --out DIR",
                         dir, n, dir);
  }
  for (size_t i = 0; i < old.n && st == SPH_OK && overwrite; ++i) {
    long long size = size_of(dir, old.e[i].name, link);
    if (size >= 0 && old.e[i].size >= 0 && size != old.e[i].size)
      st = sph_error_set(err, SPH_ERR_ARG,
                         "%s/%s changed since sph wrote it (%lld bytes, %lld "
                         "in %s/" MANIFEST "); move it away or write "
                         "elsewhere with --out DIR",
                         dir, old.e[i].name, size, old.e[i].size, dir);
  }
  /* --overwrite: the earlier runs' files go, then the plan is the manifest */
  names *keep = overwrite ? &plan : &old;
  for (size_t i = 0; i < old.n && st == SPH_OK && overwrite; ++i) {
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, old.e[i].name);
    if (size_of(dir, old.e[i].name, link) >= 0)
      remove(path);
  }
  for (size_t i = 0; i < plan.n && st == SPH_OK && !overwrite; ++i)
    if (add(keep, plan.e[i].name, -1))
      st = sph_error_set(err, SPH_ERR_NOMEM, "output manifest");
  if (st == SPH_OK) {
    sort_unique(keep);
    st = manifest_write(dir, keep, err);
  }
  free(old.e);
  free(plan.e);
  return st;
}

sph_status sph_run_manifest_close(const char *dir, sph_error *err) {
  names m = {0}, done = {0};
  manifest_read(dir, &m);
  int link = frames_linked(dir);
  sph_status st = SPH_OK;
  for (size_t i = 0; i < m.n && st == SPH_OK; ++i) {
    long long size = size_of(dir, m.e[i].name, link);
    if (size >= 0 && add(&done, m.e[i].name, size))
      st = sph_error_set(err, SPH_ERR_NOMEM, "output manifest");
  }
  if (st == SPH_OK)
    st = manifest_write(dir, &done, err);
  free(m.e);
  free(done.e);
  return st;
}

sph_status sph_run_write_scene_used(const sph_run *run, sph_error *err) {
  const sph_scene *s = run->scene;
  const char *dir = run->dir;
  char path[1200];
  snprintf(path, sizeof path, "%s/scene_used.yaml", dir);
  sph_atomic_file af;
  sph_status st = sph_atomic_open(&af, path, err);
  if (st != SPH_OK)
    return st;
  sph_provenance prov;
  sph_run_provenance(run, &prov);
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

/* One run per output folder: an exclusive lock on DIR/.sph.lock, held until
 * the process ends, with the holder's pid in the file. Returns the open
 * descriptor, or -1 with *holder the running pid (0: the lock file could
 * not be made). */
static int lock_output(const char *dir, long *holder) {
  char path[1100];
  snprintf(path, sizeof path, "%s/.sph.lock", dir);
  *holder = 0;
  /* a link or another hard link under the name is refused (issue 36) */
  int fd = sph_open_nofollow(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644, NULL);
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

sph_status sph_run_lock(sph_run *run, sph_error *err) {
  long holder = 0;
  if ((run->lock_fd = lock_output(run->dir, &holder)) >= 0)
    return SPH_OK;
  if (holder > 0)
    return sph_error_set(err, SPH_ERR_ARG,
                         "%s is in use by another sph run (pid %ld); wait for "
                         "it or write elsewhere with --out DIR",
                         run->dir, holder);
  return sph_error_set(err, SPH_ERR_ARG,
                       "cannot write in the output folder %s: %s", run->dir,
                       strerror(errno));
}
