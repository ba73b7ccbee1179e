/* Reads back the VTK sink's files (src/io/vtk_read.h): the .pvd
 * collection and, from a .vtp (or a .pvtp and its pieces, a run over MPI
 * ranks), the points and one Float64 point array, for `sph render`. The
 * XML is parsed with libexpat into a small element tree (names, attributes,
 * the byte range of each element's text, its line), which is then checked
 * against the subset this writer emits; parsing stops at <AppendedData>,
 * whose raw bytes follow '_'. Appended data may be raw or zlib-compressed
 * (VTK's block header: count, block size, last block size, compressed
 * sizes). Every error names the file, and the line where it has one. */
#include <errno.h>
#include <expat.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "io/sink.h"
#include "io/vtk_read.h"

/* bounds on what a file of ours holds (a .pvd lists one data set a frame,
 * at most 9999) */
#define XML_MAX_DEPTH 16
#define XML_MAX_NODES 100000
#define XML_MAX_ATTRS 16

typedef struct xnode {
  char name[32];
  int parent, nattr;
  char *key[XML_MAX_ATTRS], *val[XML_MAX_ATTRS];
  size_t begin, end; /* the bytes between its start and end tags */
  unsigned long line, col;
} xnode;

typedef struct xdoc {
  const char *path;
  char *data; /* the file's bytes, NUL-terminated */
  size_t size;
  xnode *node;
  int n, cap;
  int stack[XML_MAX_DEPTH], depth;
  size_t base; /* the appended data's first byte; 0: none */
  int appended;
  XML_Parser p;
  sph_status st;
  sph_error *err;
} xdoc;

static sph_status node_error(xdoc *d, const xnode *x, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static sph_status node_error(xdoc *d, const xnode *x, const char *fmt, ...) {
  char msg[400];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return sph_error_at(d->err, SPH_ERR_SYNTAX, d->path, x ? (int)x->line : 0,
                      x ? (int)x->col + 1 : 0, NULL,
                      "not a VTK file sph wrote, or damaged: %s", msg);
}

/* stops the parse with an error at the parser's place */
static void parse_error(xdoc *d, const char *what) {
  if (d->st == SPH_OK)
    d->st = sph_error_at(d->err, SPH_ERR_SYNTAX, d->path,
                         (int)XML_GetCurrentLineNumber(d->p),
                         (int)XML_GetCurrentColumnNumber(d->p) + 1, NULL,
                         "not a VTK file sph wrote, or damaged: %s", what);
  XML_StopParser(d->p, XML_FALSE);
}

static void XMLCALL on_start(void *ud, const XML_Char *name,
                             const XML_Char **atts) {
  xdoc *d = ud;
  if (d->depth == XML_MAX_DEPTH || d->n == XML_MAX_NODES) {
    parse_error(d, "elements nested or repeated beyond a VTK file's");
    return;
  }
  if (d->n == d->cap) {
    int cap = d->cap ? 2 * d->cap : 64;
    xnode *grown = realloc(d->node, (size_t)cap * sizeof *grown);
    if (!grown) {
      d->st = sph_error_set(d->err, SPH_ERR_NOMEM, "reading %s", d->path);
      XML_StopParser(d->p, XML_FALSE);
      return;
    }
    d->node = grown;
    d->cap = cap;
  }
  xnode *x = &d->node[d->n];
  memset(x, 0, sizeof *x);
  snprintf(x->name, sizeof x->name, "%s", name);
  x->parent = d->depth ? d->stack[d->depth - 1] : -1;
  x->line = (unsigned long)XML_GetCurrentLineNumber(d->p);
  x->col = (unsigned long)XML_GetCurrentColumnNumber(d->p);
  x->begin =
      (size_t)(XML_GetCurrentByteIndex(d->p) + XML_GetCurrentByteCount(d->p));
  x->end = x->begin;
  d->stack[d->depth++] = d->n++;
  for (int i = 0; atts[i] && atts[i + 1]; i += 2) {
    if (x->nattr == XML_MAX_ATTRS) {
      parse_error(d, "an element with too many attributes");
      return;
    }
    x->key[x->nattr] = strdup(atts[i]);
    x->val[x->nattr] = strdup(atts[i + 1]);
    if (!x->key[x->nattr] || !x->val[x->nattr]) {
      free(x->key[x->nattr]);
      free(x->val[x->nattr]);
      d->st = sph_error_set(d->err, SPH_ERR_NOMEM, "reading %s", d->path);
      XML_StopParser(d->p, XML_FALSE);
      return;
    }
    x->nattr++;
  }
  /* raw bytes follow: the XML ends here for this reader */
  if (!strcmp(name, "AppendedData")) {
    d->appended = 1;
    XML_StopParser(d->p, XML_FALSE);
  }
}

static void XMLCALL on_end(void *ud, const XML_Char *name) {
  xdoc *d = ud;
  (void)name;
  xnode *x = &d->node[d->stack[--d->depth]];
  size_t at = (size_t)XML_GetCurrentByteIndex(d->p);
  x->end = at > x->begin ? at : x->begin; /* <a/>: no text */
}

/* sph writes no DOCTYPE: none is read (no entity declarations) */
static void XMLCALL on_doctype(void *ud, const XML_Char *name,
                               const XML_Char *sysid, const XML_Char *pubid,
                               int internal) {
  (void)name, (void)sysid, (void)pubid, (void)internal;
  parse_error(ud, "a DOCTYPE declaration (sph writes none)");
}

static void xdoc_destroy(xdoc *d) {
  for (int i = 0; i < d->n; ++i)
    for (int k = 0; k < d->node[i].nattr; ++k) {
      free(d->node[i].key[k]);
      free(d->node[i].val[k]);
    }
  free(d->node);
  free(d->data);
  memset(d, 0, sizeof *d);
}

/* Reads path whole (a regular file) and parses its XML up to the appended
 * data. */
static sph_status xdoc_load(xdoc *d, const char *path, sph_error *err) {
  memset(d, 0, sizeof *d);
  d->path = path;
  d->err = err;
  FILE *f;
  long long size;
  SPH_TRY(sph_fopen_input(path, &f, &size, err));
  d->size = size > 0 ? (size_t)size : 0;
  d->data = malloc(d->size + 1);
  if (!d->data) {
    fclose(f);
    return sph_error_set(err, SPH_ERR_NOMEM, "reading %s", path);
  }
  int bad = fread(d->data, 1, d->size, f) != d->size;
  fclose(f);
  if (bad) {
    xdoc_destroy(d);
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "read error (it changed while read)");
  }
  d->data[d->size] = '\0';
  d->p = XML_ParserCreate(NULL);
  if (!d->p) {
    xdoc_destroy(d);
    return sph_error_set(err, SPH_ERR_NOMEM, "reading %s", path);
  }
  XML_SetUserData(d->p, d);
  XML_SetElementHandler(d->p, on_start, on_end);
  XML_SetStartDoctypeDeclHandler(d->p, on_doctype);
  /* fed in pieces: an int holds a piece's length */
  const size_t chunk = 1 << 20;
  for (size_t at = 0; d->st == SPH_OK && !d->appended;) {
    size_t len = d->size - at < chunk ? d->size - at : chunk;
    int last = at + len == d->size;
    if (XML_Parse(d->p, d->data + at, (int)len, last) == XML_STATUS_ERROR &&
        !d->appended)
      parse_error(d, XML_ErrorString(XML_GetErrorCode(d->p)));
    at += len;
    if (last)
      break;
  }
  XML_ParserFree(d->p);
  d->p = NULL;
  if (d->st == SPH_OK && d->n == 0)
    d->st = node_error(d, NULL, "no XML element");
  if (d->st == SPH_OK && d->appended) { /* whitespace, then '_' */
    size_t at = d->node[d->n - 1].begin;
    while (at < d->size && strchr(" \t\r\n", d->data[at]) && d->data[at])
      ++at;
    if (at >= d->size || d->data[at] != '_')
      d->st = node_error(d, &d->node[d->n - 1],
                         "<AppendedData> without its '_' marker");
    d->base = at + 1;
  }
  sph_status st = d->st;
  if (st != SPH_OK)
    xdoc_destroy(d);
  return st;
}

static const char *attr(const xnode *x, const char *key) {
  for (int i = 0; i < x->nattr; ++i)
    if (!strcmp(x->key[i], key))
      return x->val[i];
  return NULL;
}

/* the next child of parent named name after node index after (-1: the
 * first), or -1 */
static int child(const xdoc *d, int parent, const char *name, int after) {
  for (int i = after + 1; i < d->n; ++i)
    if (d->node[i].parent == parent && !strcmp(d->node[i].name, name))
      return i;
  return -1;
}

/* a whole unsigned decimal number */
static int parse_count(const char *s, unsigned long long *out) {
  char *end;
  if (!s || !*s || *s == '-' || *s == '+')
    return 0;
  errno = 0;
  *out = strtoull(s, &end, 10);
  return !*end && errno == 0;
}

/* the root VTKFile of the given type, with this writer's byte order and
 * header type (when given) */
static sph_status check_root(xdoc *d, const char *type) {
  const xnode *r = &d->node[0];
  const char *t = attr(r, "type"), *bo = attr(r, "byte_order"),
             *ht = attr(r, "header_type");
  if (strcmp(r->name, "VTKFile") || !t || strcmp(t, type))
    return node_error(d, r, "not a <VTKFile type=\"%s\">", type);
  if (bo && strcmp(bo, "LittleEndian"))
    return node_error(d, r, "byte_order %s, sph writes LittleEndian", bo);
  if (ht && strcmp(ht, "UInt64"))
    return node_error(d, r, "header_type %s, sph writes UInt64", ht);
  return SPH_OK;
}

sph_status sph_pvd_read(const char *path, sph_pvd *pvd, sph_error *err) {
  memset(pvd, 0, sizeof *pvd);
  xdoc d;
  SPH_TRY(xdoc_load(&d, path, err));
  sph_status st = check_root(&d, "Collection");
  int coll = st == SPH_OK ? child(&d, 0, "Collection", -1) : -1;
  if (st == SPH_OK && coll < 0)
    st = node_error(&d, &d.node[0], "no <Collection>");
  int count = 0;
  for (int i = coll; st == SPH_OK && (i = child(&d, coll, "DataSet", i)) >= 0;)
    ++count;
  if (st == SPH_OK && count == 0)
    st = node_error(&d, &d.node[coll], "the collection lists no data set");
  if (st == SPH_OK) {
    pvd->file = calloc((size_t)count, sizeof *pvd->file);
    pvd->time = calloc((size_t)count, sizeof *pvd->time);
    if (!pvd->file || !pvd->time)
      st = sph_error_set(err, SPH_ERR_NOMEM, "reading %s", path);
  }
  for (int i = coll, k = 0; st == SPH_OK && k < count; ++k) {
    i = child(&d, coll, "DataSet", i);
    const xnode *x = &d.node[i];
    const char *t = attr(x, "timestep"), *file = attr(x, "file");
    char *end = NULL;
    double time = t ? strtod(t, &end) : NAN;
    if (!t || end == t || *end || !isfinite(time))
      st = node_error(&d, x, "data set %d has no timestep (a number)", k);
    else if (!file || !*file || strlen(file) >= sizeof pvd->file[k])
      st = node_error(&d, x, "data set %d has no file (under %zu bytes)", k,
                      sizeof pvd->file[k]);
    else {
      snprintf(pvd->file[k], sizeof pvd->file[k], "%s", file);
      pvd->time[k] = time;
      pvd->count = k + 1;
    }
  }
  xdoc_destroy(&d);
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
static sph_status inflate_block(xdoc *d, const xnode *x, const unsigned char *p,
                                const unsigned char *end, unsigned char *out,
                                size_t want) {
  uint64_t head[3];
  if ((size_t)(end - p) < sizeof head)
    return node_error(d, x, "a compressed block's header is cut short");
  memcpy(head, p, sizeof head);
  uint64_t nb = head[0], bs = head[1], last = head[2];
  if (nb > ((uint64_t)(end - p) - 24) / 8)
    return node_error(d, x, "a compressed block's header is cut short");
  const unsigned char *z = p + 24 + 8 * nb;
  size_t got = 0;
  for (uint64_t b = 0; b < nb; ++b) {
    uint64_t cs;
    memcpy(&cs, p + 24 + 8 * b, 8);
    uint64_t len64 = b + 1 == nb && last ? last : bs;
    uLongf len = (uLongf)len64;
    if (cs > (uint64_t)(end - z) || len64 > want - got ||
        uncompress(out + got, &len, z, (uLong)cs) != Z_OK)
      return node_error(d, x, "a compressed block does not inflate");
    got += len;
    z += cs;
  }
  if (got != want)
    return node_error(d, x, "a compressed array has the wrong length");
  return SPH_OK;
}

/* The DataArray node x, of count values of type Float64 or Int64 (as
 * given), into out (count 8-byte values). */
static sph_status read_array(xdoc *d, int zlib, int i, const char *want,
                             size_t count, void *out) {
  const xnode *x = &d->node[i];
  const char *type = attr(x, "type"), *format = attr(x, "format");
  if (!type || !format)
    return node_error(d, x, "a DataArray without type or format");
  if (strcmp(type, want))
    return node_error(d, x, "array %s is %s, not %s",
                      attr(x, "Name") ? attr(x, "Name") : "(no name)", type,
                      want);
  int is_int = !strcmp(want, "Int64");
  if (!strcmp(format, "ascii")) {
    const char *s = d->data + x->begin, *stop = d->data + x->end;
    for (size_t k = 0; k < count; ++k) {
      char *next;
      if (is_int)
        ((int64_t *)out)[k] = strtoll(s, &next, 10);
      else
        ((double *)out)[k] = strtod(s, &next);
      if (next == s || next > stop)
        return node_error(d, x, "an ASCII array ends early");
      s = next;
    }
    return SPH_OK;
  }
  unsigned long long off;
  if (strcmp(format, "appended") || !d->base ||
      !parse_count(attr(x, "offset"), &off))
    return node_error(d, x, "an appended array without its data");
  size_t room = d->size - d->base, want_bytes = count * 8;
  if (off > room)
    return node_error(d, x, "an array's offset lies beyond the file");
  const unsigned char *p = (const unsigned char *)d->data + d->base + off;
  if (zlib)
    return inflate_block(d, x, p, (const unsigned char *)d->data + d->size, out,
                         want_bytes);
  uint64_t bytes;
  if (room - off < sizeof bytes)
    return node_error(d, x, "an array's offset lies beyond the file");
  memcpy(&bytes, p, sizeof bytes);
  if (bytes != want_bytes || bytes > room - off - sizeof bytes)
    return node_error(d, x, "an array's block is cut short");
  memcpy(out, p + sizeof bytes, want_bytes);
  return SPH_OK;
}

/* One PolyData file's points: the piece, its point count (at most n, or
 * exactly n when exact), time, points, the array `name` and, when ids is
 * not NULL, particle_id where the file has it (*has_ids). */
typedef struct piece_out {
  size_t count;
  double *points, *values, time;
  int64_t *ids;
  int has_ids;
} piece_out;

/* The names of a piece's point arrays, for the message of a missing one. */
static void array_names(const xdoc *d, int pdata, char *names, size_t size) {
  names[0] = '\0';
  for (int i = pdata; pdata >= 0 && (i = child(d, pdata, "DataArray", i)) >= 0;)
    if (attr(&d->node[i], "Name")) {
      strncat(names, names[0] ? ", " : "", size - strlen(names) - 1);
      strncat(names, attr(&d->node[i], "Name"), size - strlen(names) - 1);
    }
}

static sph_status read_polydata(xdoc *d, size_t n, int exact, const char *name,
                                int ncomp, piece_out *o) {
  SPH_TRY(check_root(d, "PolyData"));
  const char *comp = attr(&d->node[0], "compressor");
  if (comp && strcmp(comp, "vtkZLibDataCompressor"))
    return node_error(d, &d->node[0], "compressor %s, sph writes zlib", comp);
  int zlib = comp != NULL;
  int poly = child(d, 0, "PolyData", -1);
  int piece = poly >= 0 ? child(d, poly, "Piece", -1) : -1;
  unsigned long long count;
  if (piece < 0)
    return node_error(d, &d->node[0], "no PolyData piece");
  if (!parse_count(attr(&d->node[piece], "NumberOfPoints"), &count))
    return node_error(d, &d->node[piece], "a Piece without NumberOfPoints");
  if (exact ? count != n : count > n)
    return sph_error_at(d->err, SPH_ERR_SYNTAX, d->path,
                        (int)d->node[piece].line, 0, NULL,
                        "%llu points, the run's scene builds %s%zu", count,
                        exact ? "" : "at most ", n);
  o->count = (size_t)count;
  o->time = NAN;
  int fd = child(d, poly, "FieldData", -1);
  for (int i = fd; fd >= 0 && (i = child(d, fd, "DataArray", i)) >= 0;)
    if (attr(&d->node[i], "Name") &&
        !strcmp(attr(&d->node[i], "Name"), "TimeValue"))
      SPH_TRY(read_array(d, 0, i, "Float64", 1, &o->time));
  int pts = child(d, piece, "Points", -1);
  int tag = pts >= 0 ? child(d, pts, "DataArray", -1) : -1;
  if (tag < 0)
    return node_error(d, &d->node[piece], "no points");
  SPH_TRY(read_array(d, zlib, tag, "Float64", 3 * o->count, o->points));
  int pdata = child(d, piece, "PointData", -1), found = -1, idn = -1;
  for (int i = pdata;
       pdata >= 0 && (i = child(d, pdata, "DataArray", i)) >= 0;) {
    const char *an = attr(&d->node[i], "Name");
    if (an && name && !strcmp(an, name))
      found = i;
    if (an && !strcmp(an, "particle_id"))
      idn = i;
  }
  o->has_ids = o->ids && idn >= 0;
  if (o->has_ids)
    SPH_TRY(read_array(d, zlib, idn, "Int64", o->count, o->ids));
  if (!name)
    return SPH_OK;
  unsigned long long nc;
  if (found < 0) {
    char names[512];
    array_names(d, pdata, names, sizeof names);
    return sph_error_at(d->err, SPH_ERR_SYNTAX, d->path, 0, 0, NULL,
                        "no point array '%s' (it has: %s)", name, names);
  }
  if (!parse_count(attr(&d->node[found], "NumberOfComponents"), &nc) ||
      nc != (unsigned long long)ncomp)
    return sph_error_at(
        d->err, SPH_ERR_SYNTAX, d->path, (int)d->node[found].line, 0, NULL,
        "point array '%s' does not have %d components", name, ncomp);
  return read_array(d, zlib, found, "Float64", (size_t)ncomp * o->count,
                    o->values);
}

/* The pieces of a .pvtp one after the other into the outputs; placed by
 * their particle_id when every piece has it (the particles' creation
 * order), in rank order otherwise. */
static sph_status read_pieces(xdoc *d, size_t n, double *points,
                              const char *name, int ncomp, double *values,
                              double *time, sph_error *err) {
  int pp = child(d, 0, "PPolyData", -1), npieces = 0, all_ids = 1;
  if (pp < 0)
    return node_error(d, &d->node[0], "no <PPolyData>");
  double *x = malloc(3 * (n ? n : 1) * sizeof *x);
  double *v = malloc((size_t)ncomp * (n ? n : 1) * sizeof *v);
  int64_t *ids = malloc((n ? n : 1) * sizeof *ids);
  char *seen = calloc(n ? n : 1, 1);
  sph_status st = x && v && ids && seen ? SPH_OK
                                        : sph_error_set(err, SPH_ERR_NOMEM,
                                                        "reading %s", d->path);
  size_t filled = 0;
  const char *slash = strrchr(d->path, '/');
  int dirlen = slash ? (int)(slash - d->path) : 0;
  *time = NAN;
  for (int i = pp; st == SPH_OK && (i = child(d, pp, "Piece", i)) >= 0;) {
    const char *src = attr(&d->node[i], "Source");
    char path[1400];
    if (!src || !*src)
      st = node_error(d, &d->node[i], "a Piece without Source");
    else if ((size_t)snprintf(path, sizeof path, "%.*s%s%s", dirlen, d->path,
                              slash && src[0] != '/' ? "/" : "",
                              src) >= sizeof path)
      st = node_error(d, &d->node[i], "a piece's path is too long");
    if (st != SPH_OK)
      break;
    xdoc pd;
    piece_out o = {0,   x + 3 * filled, v + (size_t)ncomp * filled,
                   NAN, ids + filled,   0};
    st = xdoc_load(&pd, slash && src[0] != '/' ? path : src, err);
    if (st == SPH_OK) {
      st = read_polydata(&pd, n - filled, 0, name, ncomp, &o);
      xdoc_destroy(&pd);
    }
    filled += o.count;
    all_ids = all_ids && o.has_ids;
    if (npieces++ == 0)
      *time = o.time;
  }
  if (st == SPH_OK && filled != n)
    st = node_error(d, &d->node[pp],
                    "%zu points in its %d pieces, the run's "
                    "scene builds %zu",
                    filled, npieces, n);
  for (size_t k = 0; st == SPH_OK && k < n; ++k) {
    size_t at = all_ids ? (size_t)ids[k] : k;
    if (all_ids && (ids[k] < 0 || (uint64_t)ids[k] >= n || seen[at]))
      st = node_error(d, &d->node[pp],
                      "the pieces' particle_id are not "
                      "0 .. %zu, each once",
                      n - 1);
    else {
      seen[at] = 1;
      memcpy(points + 3 * at, x + 3 * k, 3 * sizeof *x);
      if (name)
        memcpy(values + (size_t)ncomp * at, v + (size_t)ncomp * k,
               (size_t)ncomp * sizeof *v);
    }
  }
  free(x);
  free(v);
  free(ids);
  free(seen);
  return st;
}

sph_status sph_vtp_read(const char *path, size_t n, double *points,
                        const char *name, int ncomp, double *values,
                        double *time, sph_error *err) {
  xdoc d;
  *time = NAN;
  SPH_TRY(xdoc_load(&d, path, err));
  sph_status st;
  const char *type = attr(&d.node[0], "type");
  if (!strcmp(d.node[0].name, "VTKFile") && type && !strcmp(type, "PPolyData"))
    st = read_pieces(&d, n, points, name, ncomp, values, time, err);
  else {
    piece_out o = {0, points, values, NAN, NULL, 0};
    st = read_polydata(&d, n, 1, name, ncomp, &o);
    *time = o.time;
  }
  xdoc_destroy(&d);
  return st;
}

/* A PolyData file's point count and whether it has point array `name`. */
static sph_status polydata_count(xdoc *d, const char *name, size_t *n,
                                 int *has) {
  SPH_TRY(check_root(d, "PolyData"));
  int poly = child(d, 0, "PolyData", -1);
  int piece = poly >= 0 ? child(d, poly, "Piece", -1) : -1;
  unsigned long long count;
  if (piece < 0)
    return node_error(d, &d->node[0], "no PolyData piece");
  if (!parse_count(attr(&d->node[piece], "NumberOfPoints"), &count))
    return node_error(d, &d->node[piece], "a Piece without NumberOfPoints");
  *n = (size_t)count;
  *has = 0;
  int pdata = child(d, piece, "PointData", -1);
  for (int i = pdata;
       name && pdata >= 0 && (i = child(d, pdata, "DataArray", i)) >= 0;)
    if (attr(&d->node[i], "Name") && !strcmp(attr(&d->node[i], "Name"), name))
      *has = 1;
  return SPH_OK;
}

sph_status sph_vtp_count(const char *path, const char *name, size_t *n,
                         int *has, sph_error *err) {
  xdoc d;
  *n = 0;
  *has = 0;
  SPH_TRY(xdoc_load(&d, path, err));
  const char *type = attr(&d.node[0], "type");
  sph_status st = SPH_OK;
  if (!strcmp(d.node[0].name, "VTKFile") && type &&
      !strcmp(type, "PPolyData")) {
    int pp = child(&d, 0, "PPolyData", -1), all = 1;
    if (pp < 0)
      st = node_error(&d, &d.node[0], "no <PPolyData>");
    const char *slash = strrchr(path, '/');
    int dirlen = slash ? (int)(slash - path) : 0;
    for (int i = pp; st == SPH_OK && (i = child(&d, pp, "Piece", i)) >= 0;) {
      const char *src = attr(&d.node[i], "Source");
      char piece[1400];
      if (!src || !*src) {
        st = node_error(&d, &d.node[i], "a Piece without Source");
        break;
      }
      snprintf(piece, sizeof piece, "%.*s%s%s", dirlen, path,
               slash && src[0] != '/' ? "/" : "", src);
      xdoc pd;
      size_t k = 0;
      int h = 0;
      st = xdoc_load(&pd, slash && src[0] != '/' ? piece : src, err);
      if (st == SPH_OK) {
        st = polydata_count(&pd, name, &k, &h);
        xdoc_destroy(&pd);
      }
      *n += k;
      all = all && h;
    }
    *has = all && *n > 0;
  } else {
    st = polydata_count(&d, name, n, has);
  }
  xdoc_destroy(&d);
  return st;
}
