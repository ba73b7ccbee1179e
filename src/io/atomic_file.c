/* Atomic output files: write to "<path>.part", fsync, rename over <path>,
 * so a killed run never leaves a truncated file under the final name. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "sph/sink.h"

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
