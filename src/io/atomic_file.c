/* Atomic output files: write to "<path>.part", fsync, rename over <path>,
 * so a killed run never leaves a truncated file under the final name.
 * Streams (the CSV tables): written under the final name and flushed row by
 * row, so they can be read while the run goes and keep every row written
 * when it stops; a resume keeps the complete lines its checkpoint counts
 * (a torn last line is dropped there).
 * Nothing is written through a symbolic link (issue 36): every output is
 * opened with O_NOFOLLOW, a .part file is made new (O_EXCL), and a link,
 * a non-regular file or a file with other hard links under an output's
 * name is refused naming it; inputs are opened without blocking and
 * refused unless they are regular files (a FIFO would hang the read). */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/sink.h"

/* what is under path, when it is not something sph writes into (an
 * output: SPH_ERR_IO, a write that cannot be done) or reads (SPH_ERR_ARG,
 * bad input) */
static sph_status refuse_kind(const char *path, const struct stat *sb,
                              int writing, sph_error *err) {
  sph_status code = writing ? SPH_ERR_IO : SPH_ERR_ARG;
  if (S_ISLNK(sb->st_mode))
    return sph_error_at(err, code, path, 0, 0, NULL,
                        "is a symbolic link; sph does not write through "
                        "links (remove it, or write elsewhere with --out)");
  if (!S_ISREG(sb->st_mode))
    return sph_error_at(err, code, path, 0, 0, NULL,
                        "not a regular file (a folder, FIFO or device); "
                        "sph %s only regular files",
                        writing ? "writes" : "reads");
  if (writing && sb->st_nlink > 1)
    return sph_error_at(err, code, path, 0, 0, NULL,
                        "has %lu hard links; sph does not write into a file "
                        "shared with another name (remove it)",
                        (unsigned long)sb->st_nlink);
  return SPH_OK;
}

/* open(2) of an output (or an input read back in place) that follows no
 * link and refuses what refuse_kind refuses; *fd, or -1 */
static sph_status open_checked(const char *path, int flags, mode_t mode,
                               int *fd, sph_error *err) {
  int writing = (flags & O_ACCMODE) != O_RDONLY, trunc = flags & O_TRUNC;
  /* O_NONBLOCK: a FIFO planted under the name must not block the open */
  *fd = open(path, (flags & ~O_TRUNC) | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC,
             mode);
  struct stat sb;
  if (*fd < 0) {
    int e = errno;
    sph_status st =
        lstat(path, &sb) == 0 && (e == ELOOP || e == ENXIO || e == EISDIR)
            ? refuse_kind(path, &sb, writing, err)
            : sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                           "cannot %s the file: %s",
                           writing ? "create" : "open", strerror(e));
    errno = e;
    return st;
  }
  sph_status st = SPH_OK;
  if (fstat(*fd, &sb) != 0)
    st = sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                      "cannot open the file: %s", strerror(errno));
  else if ((st = refuse_kind(path, &sb, writing, err)) != SPH_OK)
    errno = EINVAL;
  else if (fcntl(*fd, F_SETFL, fcntl(*fd, F_GETFL) & ~O_NONBLOCK) != 0 ||
           (trunc && ftruncate(*fd, 0) != 0))
    st = sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                      "cannot open the file: %s", strerror(errno));
  if (st != SPH_OK) {
    int e = errno;
    close(*fd);
    *fd = -1;
    errno = e;
  }
  return st;
}

int sph_open_nofollow(const char *path, int flags, mode_t mode,
                      sph_error *err) {
  int fd;
  open_checked(path, flags, mode, &fd, err);
  return fd;
}

/* fopen(3) modes "r", "w", "a", with "+" and "x" (O_EXCL) */
static sph_status fopen_checked(const char *path, const char *mode, FILE **f,
                                sph_error *err) {
  int flags = mode[0] == 'w'   ? O_WRONLY | O_CREAT | O_TRUNC
              : mode[0] == 'a' ? O_WRONLY | O_CREAT | O_APPEND
                               : O_RDONLY;
  if (strchr(mode, '+'))
    flags = (flags & ~O_ACCMODE) | O_RDWR;
  if (strchr(mode, 'x'))
    flags |= O_EXCL;
  char fmode[4];
  snprintf(fmode, sizeof fmode, "%c%s", mode[0], strchr(mode, '+') ? "+" : "");
  int fd;
  *f = NULL;
  SPH_TRY(open_checked(path, flags, 0666, &fd, err));
  if (!(*f = fdopen(fd, fmode))) {
    int e = errno;
    close(fd);
    errno = e;
    return sph_error_at(err, SPH_ERR_NOMEM, path, 0, 0, NULL, "cannot open: %s",
                        strerror(e));
  }
  return SPH_OK;
}

FILE *sph_fopen_nofollow(const char *path, const char *mode, sph_error *err) {
  FILE *f;
  fopen_checked(path, mode, &f, err);
  return f;
}

sph_status sph_fopen_input(const char *path, FILE **f, long long *size,
                           sph_error *err) {
  *f = NULL;
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL, "cannot open: %s",
                        strerror(errno));
  struct stat sb;
  sph_status st = SPH_OK;
  if (fstat(fd, &sb) != 0)
    st = sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL, "cannot open: %s",
                      strerror(errno));
  else if ((st = refuse_kind(path, &sb, 0, err)) == SPH_OK &&
           (fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK) != 0 ||
            !(*f = fdopen(fd, "rb"))))
    st = sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL, "cannot open: %s",
                      strerror(errno));
  if (st != SPH_OK) {
    close(fd);
    return st;
  }
  if (size)
    *size = (long long)sb.st_size;
  return SPH_OK;
}

sph_status sph_atomic_open(sph_atomic_file *af, const char *path,
                           sph_error *err) {
  memset(af, 0, sizeof *af);
  snprintf(af->path, sizeof af->path, "%s", path);
  snprintf(af->tmp, sizeof af->tmp, "%s.part", path);
  /* the final name is replaced by rename, which never follows a link; a
   * link there is refused all the same, as is one under the .part name */
  struct stat sb;
  if (lstat(path, &sb) == 0 && (S_ISLNK(sb.st_mode) || S_ISFIFO(sb.st_mode)))
    return refuse_kind(path, &sb, 1, err);
  if (lstat(af->tmp, &sb) == 0) {
    if (S_ISLNK(sb.st_mode) || !S_ISREG(sb.st_mode))
      return refuse_kind(af->tmp, &sb, 1, err);
    unlink(af->tmp); /* left by a killed run */
  }
  sph_status st = fopen_checked(af->tmp, "wx", &af->f, err);
  if (st != SPH_OK && errno != EINVAL && errno != ELOOP) /* not a refusal */
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "cannot create the file: %s", strerror(errno));
  return st;
}

sph_status sph_atomic_commit(sph_atomic_file *af, sph_error *err) {
  if (!af->f)
    return sph_error_at(err, SPH_ERR_IO, af->path, 0, 0, NULL,
                        "file is not open");
  int bad = fflush(af->f) != 0 || ferror(af->f) || fsync(fileno(af->f)) != 0;
  int saved = errno;
  bad |= fclose(af->f) != 0;
  af->f = NULL;
  if (!af->tmp[0]) /* a stream: already under its name */
    return bad ? sph_error_at(err, SPH_ERR_IO, af->path, 0, 0, NULL,
                              "cannot write the file: %s", strerror(saved))
               : SPH_OK;
  if (bad || rename(af->tmp, af->path) != 0) {
    if (!bad)
      saved = errno;
    remove(af->tmp);
    return sph_error_at(err, SPH_ERR_IO, af->path, 0, 0, NULL,
                        "cannot write the file: %s", strerror(saved));
  }
  return SPH_OK;
}

void sph_atomic_abort(sph_atomic_file *af) {
  if (af->f)
    fclose(af->f);
  af->f = NULL;
  if (af->tmp[0])
    remove(af->tmp);
}

sph_status sph_stream_open(sph_atomic_file *af, const char *path, size_t lines,
                           sph_error *err) {
  memset(af, 0, sizeof *af);
  snprintf(af->path, sizeof af->path, "%s", path);
  char tmp[1040];
  snprintf(tmp, sizeof tmp, "%s.part", path);
  char *buf = NULL;
  size_t len = 0;
  FILE *f = NULL, *old = NULL; /* resume: the file itself, cut in place */
  sph_status st = SPH_OK;
  if (lines > 0) { /* resume: the lines the checkpoint counts */
    st = fopen_checked(path, "r+", &f, err);
    if (st != SPH_OK && errno == ENOENT) /* written by an earlier version */
      st = fopen_checked(tmp, "r", &old, err);
    if (st != SPH_OK)
      return errno == ENOENT ? sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                                            "cannot resume: the file does "
                                            "not exist")
                             : st;
    FILE *in = f ? f : old;
    size_t cap = 0, have = 0;
    for (int ch; have < lines && (ch = fgetc(in)) != EOF;) {
      if (len + 1 >= cap) {
        cap = cap ? 2 * cap : 65536;
        char *nb = realloc(buf, cap);
        if (!nb) {
          free(buf);
          fclose(in);
          return sph_error_set(err, SPH_ERR_NOMEM, "resume %s", path);
        }
        buf = nb;
      }
      buf[len++] = (char)ch;
      have += ch == '\n';
    }
    if (old)
      fclose(old);
    if (have < lines) {
      free(buf);
      if (f)
        fclose(f);
      return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                          "cannot resume: %zu complete lines, the checkpoint "
                          "needs %zu",
                          have, lines);
    }
  }
  /* a resume cuts the file after the lines it keeps, in place: killed at
   * any moment, the file still holds them (rewriting it would lose every
   * row until the first flush) */
  if (f) {
    if (fflush(f) != 0 || ftruncate(fileno(f), (off_t)len) != 0 ||
        fseeko(f, (off_t)len, SEEK_SET) != 0) {
      st = sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "cannot resume the file: %s", strerror(errno));
      fclose(f);
      f = NULL;
    }
  } else if ((st = fopen_checked(path, "w", &f, err)) == SPH_OK && len)
    fwrite(buf, 1, len, f); /* the lines of an earlier version's .part */
  free(buf);
  if (st != SPH_OK)
    return st;
  af->f = f;
  remove(tmp);
  return SPH_OK;
}

sph_status sph_stream_row_end(sph_atomic_file *af, sph_error *err) {
  if (fflush(af->f) != 0 || ferror(af->f)) /* the row is readable now */
    return sph_error_at(err, SPH_ERR_IO, af->path, 0, 0, NULL,
                        "cannot write the file: %s",
                        strerror(errno ? errno : EIO));
  return SPH_OK;
}

sph_status sph_atomic_flush(sph_atomic_file *af, sph_error *err) {
  if (!af->f || fflush(af->f) != 0 || ferror(af->f) ||
      fsync(fileno(af->f)) != 0)
    return sph_error_at(err, SPH_ERR_IO, af->path, 0, 0, NULL,
                        "cannot write the file: %s", strerror(errno));
  return SPH_OK;
}
