/* Atomic output files: write to "<path>.part", fsync, rename over <path>,
 * so a killed run never leaves a truncated file under the final name.
 * Streams (the CSV tables): written under the final name and flushed row by
 * row, so they can be read while the run goes and keep every row written
 * when it stops; a resume keeps the complete lines its checkpoint counts
 * (a torn last line is dropped there). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/sink.h"

sph_status sph_atomic_open(sph_atomic_file *af, const char *path,
                           sph_error *err) {
  memset(af, 0, sizeof *af);
  snprintf(af->path, sizeof af->path, "%s", path);
  snprintf(af->tmp, sizeof af->tmp, "%s.part", path);
  af->f = fopen(af->tmp, "w");
  if (!af->f)
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "cannot create the file: %s", strerror(errno));
  return SPH_OK;
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
  int in_place = 0; /* the lines kept are the start of <path> */
  if (lines > 0) {  /* resume: the lines the checkpoint counts */
    FILE *f = fopen(path, "r");
    in_place = f != NULL;
    if (!f)
      f = fopen(tmp, "r"); /* written by an earlier version */
    if (!f)
      return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                          "cannot resume: the file does not exist");
    size_t cap = 0, have = 0;
    for (int ch; have < lines && (ch = fgetc(f)) != EOF;) {
      if (len + 1 >= cap) {
        cap = cap ? 2 * cap : 65536;
        char *nb = realloc(buf, cap);
        if (!nb) {
          free(buf);
          fclose(f);
          return sph_error_set(err, SPH_ERR_NOMEM, "resume %s", path);
        }
        buf = nb;
      }
      buf[len++] = (char)ch;
      have += ch == '\n';
    }
    fclose(f);
    if (have < lines) {
      free(buf);
      return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                          "cannot resume: %zu complete lines, the checkpoint "
                          "needs %zu",
                          have, lines);
    }
  }
  /* a resume cuts the file after the lines it keeps, in place: killed at
   * any moment, the file still holds them (rewriting it would lose every
   * row until the first flush) */
  if (in_place)
    af->f = truncate(path, (off_t)len) == 0 ? fopen(path, "a") : NULL;
  else
    af->f = fopen(path, "w");
  if (!af->f) {
    free(buf);
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "cannot create the file: %s", strerror(errno));
  }
  remove(tmp);
  if (len && !in_place)
    fwrite(buf, 1, len, af->f);
  free(buf);
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
