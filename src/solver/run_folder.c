/* The run's output folder (docs/design.md sec. 2): one run per folder (a lock),
 * --overwrite removing only the files an earlier run of ours wrote, and
 * scene_used.yaml. */
#include <dirent.h>
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
  struct stat fst; /* a frames folder that is a link is not ours */
  int frames_linked = lstat(sub[1], &fst) == 0 && S_ISLNK(fst.st_mode);
  for (int k = 0; k < 2 - frames_linked; ++k) {
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
void sph_run_remove_previous(const char *dir, const char *scene) {
  char path[1200], line[256], previous[256] = "";
  snprintf(path, sizeof path, "%s/scene_used.yaml", dir);
  FILE *f = NULL; /* never a FIFO or a link's target */
  if (sph_fopen_input(path, &f, NULL, NULL) != SPH_OK)
    f = NULL;
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
