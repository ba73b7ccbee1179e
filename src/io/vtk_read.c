/* Reads back the VTK sink's files (include/sph/vtk_read.h): the .pvd
 * collection and, from a .vtp, the points and one Float64 point array, for
 * `sph render`. The whole file is read into memory; the XML header is
 * scanned for the DataArray tags this writer emits. Appended data may be
 * raw or zlib-compressed (VTK's block header: count, block size, last
 * block size, compressed sizes). */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "io/vtk_read.h"

/* The file's bytes, NUL-terminated (binary data may hold more NULs). */
static sph_status slurp(const char *path, char **data, size_t *size,
                        sph_error *err) {
  FILE *f = fopen(path, "rb");
  if (!f)
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL, "cannot open: %s",
                        strerror(errno));
  char *buf = NULL;
  size_t n = 0, cap = 0;
  for (;;) {
    if (n + 65536 + 1 > cap) {
      cap = 2 * cap + 65536 + 1;
      char *grown = realloc(buf, cap);
      if (!grown) {
        free(buf);
        fclose(f);
        return sph_error_set(err, SPH_ERR_NOMEM, "reading %s", path);
      }
      buf = grown;
    }
    size_t got = fread(buf + n, 1, cap - n - 1, f);
    n += got;
    if (got == 0)
      break;
  }
  int bad = ferror(f);
  fclose(f);
  if (bad) {
    free(buf);
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL, "read error");
  }
  buf[n] = '\0';
  *data = buf;
  *size = n;
  return SPH_OK;
}

/* The value of key="..." inside the tag [tag, end), into out. */
static int attribute(const char *tag, const char *end, const char *key,
                     char *out, size_t size) {
  size_t kl = strlen(key);
  for (const char *p = tag; p + kl + 2 < end; ++p) {
    if (strncmp(p, key, kl) || p[kl] != '=' || p[kl + 1] != '"' ||
        (p > tag && p[-1] != ' '))
      continue;
    const char *v = p + kl + 2, *q = memchr(v, '"', (size_t)(end - v));
    if (!q || (size_t)(q - v) >= size)
      return 0;
    memcpy(out, v, (size_t)(q - v));
    out[q - v] = '\0';
    return 1;
  }
  return 0;
}

static sph_status damaged(const char *path, sph_error *err, const char *what) {
  return sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                      "not a .vtp file sph wrote, or damaged: %s", what);
}

sph_status sph_pvd_read(const char *path, sph_pvd *pvd, sph_error *err) {
  memset(pvd, 0, sizeof *pvd);
  char *data;
  size_t size;
  SPH_TRY(slurp(path, &data, &size, err));
  sph_status st = SPH_OK;
  if (!strstr(data, "<VTKFile type=\"Collection\""))
    st = sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                      "not a VTK collection (.pvd)");
  int count = 0;
  for (const char *p = data; st == SPH_OK && (p = strstr(p, "<DataSet ")); ++p)
    ++count;
  if (st == SPH_OK && count == 0)
    st = sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                      "the collection lists no data set");
  if (st == SPH_OK) {
    pvd->file = calloc((size_t)count, sizeof *pvd->file);
    pvd->time = calloc((size_t)count, sizeof *pvd->time);
    if (!pvd->file || !pvd->time)
      st = sph_error_set(err, SPH_ERR_NOMEM, "reading %s", path);
  }
  const char *p = data;
  for (int i = 0; st == SPH_OK && i < count; ++i) {
    p = strstr(p, "<DataSet ");
    const char *end = strchr(p, '>');
    char t[64];
    if (!end || !attribute(p, end, "timestep", t, sizeof t) ||
        !attribute(p, end, "file", pvd->file[i], sizeof pvd->file[i]))
      st = sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                        "data set %d has no timestep or file", i);
    else
      pvd->time[i] = strtod(t, NULL);
    pvd->count = i + 1;
    p = end ? end : p + 1;
  }
  free(data);
  if (st != SPH_OK)
    sph_pvd_destroy(pvd);
  return st;
}

void sph_pvd_destroy(sph_pvd *pvd) {
  free(pvd->file);
  free(pvd->time);
  memset(pvd, 0, sizeof *pvd);
}

/* A zlib-compressed appended block at p (end: the file's end) into out,
 * which holds want bytes. */
static sph_status inflate_block(const char *path, const unsigned char *p,
                                const unsigned char *end, unsigned char *out,
                                size_t want, sph_error *err) {
  uint64_t head[3];
  if ((size_t)(end - p) < sizeof head)
    return damaged(path, err, "a compressed block's header is cut short");
  memcpy(head, p, sizeof head);
  uint64_t nb = head[0], bs = head[1], last = head[2];
  if (nb > (uint64_t)(end - p) / 8)
    return damaged(path, err, "a compressed block's header is cut short");
  const unsigned char *z = p + 24 + 8 * nb;
  size_t got = 0;
  for (uint64_t b = 0; b < nb; ++b) {
    uint64_t cs;
    memcpy(&cs, p + 24 + 8 * b, 8);
    uLongf len = (uLongf)(b + 1 == nb && last ? last : bs);
    if (cs > (uint64_t)(end - z) || got + len > want ||
        uncompress(out + got, &len, z, (uLong)cs) != Z_OK)
      return damaged(path, err, "a compressed block does not inflate");
    got += len;
    z += cs;
  }
  if (got != want)
    return damaged(path, err, "a compressed array has the wrong length");
  return SPH_OK;
}

/* One DataArray of the header: copies its doubles into out. */
static sph_status read_array(const char *path, const char *data, size_t size,
                             const char *tag, const char *base, int zlib,
                             size_t count, double *out, sph_error *err) {
  const char *end = strchr(tag, '>');
  char type[16], format[16], offset[32];
  if (!end || !attribute(tag, end, "type", type, sizeof type) ||
      !attribute(tag, end, "format", format, sizeof format))
    return damaged(path, err, "a DataArray without type or format");
  if (strcmp(type, "Float64"))
    return damaged(path, err, "an array read as Float64 is not");
  if (!strcmp(format, "ascii")) {
    const char *s = end + 1;
    for (size_t i = 0; i < count; ++i) {
      char *next;
      out[i] = strtod(s, &next);
      if (next == s)
        return damaged(path, err, "an ASCII array ends early");
      s = next;
    }
    return SPH_OK;
  }
  if (strcmp(format, "appended") || !base ||
      !attribute(tag, end, "offset", offset, sizeof offset))
    return damaged(path, err, "an appended array without its data");
  unsigned long long off = strtoull(offset, NULL, 10);
  size_t at = (size_t)(base - data);
  if (zlib)
    return off > size - at
               ? damaged(path, err, "an array's offset lies beyond the file")
               : inflate_block(path, (const unsigned char *)base + off,
                               (const unsigned char *)data + size,
                               (unsigned char *)out, count * sizeof(double),
                               err);
  uint64_t bytes;
  if (off > size || at + off + sizeof bytes > size)
    return damaged(path, err, "an array's offset lies beyond the file");
  memcpy(&bytes, base + off, sizeof bytes);
  if (bytes != count * sizeof(double) || at + off + sizeof bytes + bytes > size)
    return damaged(path, err, "an array's block is cut short");
  memcpy(out, base + off + sizeof bytes, (size_t)bytes);
  return SPH_OK;
}

sph_status sph_vtp_read(const char *path, size_t n, double *points,
                        const char *name, int ncomp, double *values,
                        double *time, sph_error *err) {
  char *data;
  size_t size;
  SPH_TRY(slurp(path, &data, &size, err));
  sph_status st = SPH_OK;
  const char *piece = strstr(data, "<Piece ");
  const char *appended = strstr(data, "<AppendedData");
  const char *base = appended ? strchr(appended, '_') : NULL;
  const char *head_end = appended ? appended : data + strlen(data);
  int zlib = strstr(data, "compressor=\"vtkZLibDataCompressor\"") != NULL &&
             strstr(data, "compressor=") < piece;
  char count[32];
  if (!strstr(data, "<VTKFile type=\"PolyData\"") || !piece ||
      !attribute(piece, strchr(piece, '>'), "NumberOfPoints", count,
                 sizeof count))
    st = damaged(path, err, "no PolyData piece");
  else if (strtoull(count, NULL, 10) != n)
    st = sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                      "%s points, the run's scene builds %zu", count, n);
  if (base)
    ++base;
  *time = NAN;
  const char *tv = strstr(data, "Name=\"TimeValue\"");
  if (st == SPH_OK && tv && tv < piece) {
    const char *gt = strchr(tv, '>');
    if (gt)
      *time = strtod(gt + 1, NULL);
  }
  /* the points, then the named array */
  const char *pts = st == SPH_OK ? strstr(piece, "<Points>") : NULL;
  const char *tag = pts ? strstr(pts, "<DataArray") : NULL;
  if (st == SPH_OK && (!tag || tag > head_end))
    st = damaged(path, err, "no points");
  if (st == SPH_OK)
    st = read_array(path, data, size, tag, base, zlib, 3 * n, points, err);
  if (st == SPH_OK && name) {
    char names[512] = "";
    const char *found = NULL;
    for (const char *p = strstr(piece, "<DataArray"); p && p < head_end;
         p = strstr(p + 1, "<DataArray")) {
      const char *end = strchr(p, '>');
      char an[64];
      if (!end || !attribute(p, end, "Name", an, sizeof an))
        continue;
      if (!strcmp(an, name))
        found = p;
      if (strcmp(an, "Points") && strcmp(an, "connectivity") &&
          strcmp(an, "offsets")) {
        strncat(names, names[0] ? ", " : "", sizeof names - strlen(names) - 1);
        strncat(names, an, sizeof names - strlen(names) - 1);
      }
    }
    char nc[16];
    const char *end = found ? strchr(found, '>') : NULL;
    if (!found)
      st = sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                        "no point array '%s' (it has: %s)", name, names);
    else if (!attribute(found, end, "NumberOfComponents", nc, sizeof nc) ||
             atoi(nc) != ncomp)
      st = sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                        "point array '%s' does not have %d components", name,
                        ncomp);
    else
      st = read_array(path, data, size, found, base, zlib, (size_t)ncomp * n,
                      values, err);
  }
  free(data);
  return st;
}
