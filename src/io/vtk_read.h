/* Reading back what the VTK sink writes (src/io/vtk_sink.c): the .pvd
 * collection's files and times, and a .vtp file's (or a .pvtp's pieces')
 * points and one Float64 point array, appended raw (UInt64 block headers),
 * zlib-compressed or ASCII. Only this writer's layout is read (parsed with
 * libexpat); anything else is refused naming the file and line. */
#ifndef SPH_VTK_READ_H
#define SPH_VTK_READ_H

#include <stddef.h>

#include "sph/status.h"

/* The data sets of a .pvd: count files (paths relative to the .pvd's
 * folder) with their times, in the collection's order. */
typedef struct sph_pvd {
  int count;
  char (*file)[256];
  double *time;
} sph_pvd;

/* SPH_ERR_IO when the file cannot be read, SPH_ERR_SYNTAX when it is not a
 * collection this writer made; the error names the file. */
sph_status sph_pvd_read(const char *path, sph_pvd *pvd, sph_error *err);
void sph_pvd_destroy(sph_pvd *pvd);

/* Reads n points (3 n doubles) and, when name is not NULL, the point array
 * `name` of ncomp components (n ncomp doubles) from a .vtp file, and its
 * TimeValue (NaN without one). A .pvtp (a run over MPI ranks) gives its
 * pieces' points one after the other, placed by particle_id when every
 * piece has it (else in rank order; sph render places them by the first
 * frame's positions). A missing file is SPH_ERR_IO; a different
 * point count, a missing array (the message lists the file's arrays) or a
 * damaged file SPH_ERR_SYNTAX, naming the file. */
sph_status sph_vtp_read(const char *path, size_t n, double *points,
                        const char *name, int ncomp, double *values,
                        double *time, sph_error *err);

/* The number of points of a .vtp (or a .pvtp's pieces together) and
 * whether it (every piece) has the point array `name`; errors as above. */
sph_status sph_vtp_count(const char *path, const char *name, size_t *n,
                         int *has, sph_error *err);

#endif
