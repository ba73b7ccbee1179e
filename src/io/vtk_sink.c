/* VTK sink: one XML PolyData file (.vtp) per output time, one vertex cell
 * per particle, appended raw little-endian binary with UInt64 block headers
 * (or inline ASCII for debugging), Float64 positions in the current
 * configuration, Int64 connectivity and offsets, the point arrays the scene
 * asks for; and a .pvd collection with the physical time of every file,
 * rewritten after each frame so a running or killed simulation always
 * loads in ParaView. Every file is written to a temporary name, fsync'd
 * and renamed. Particles are listed in creation order whatever their
 * storage order (sph_particles_sort_morton). With output.vtk.compress: zlib
 * each appended array is one zlib block behind VTK's compression header
 * (vtkZLibDataCompressor, UInt64 words: 1 block, its size, 0, the
 * compressed size); the blocks are compressed first, since the XML header
 * gives their offsets. Over MPI ranks (sph_domain) each rank writes its
 * owned particles as a piece <scene>_NNNN_pR.vtp and rank 0, once every
 * piece is in place, the <scene>_NNNN.pvtp that lists them (VTK's
 * parallel PolyData) with the time as TimeValue field data, like every
 * .vtp, which the .pvd names. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "io/sink.h"
#include "parallel/domain.h"

typedef struct vtk_sink {
  char dir[1024];
  char name[64];
  int ascii;
  int rank, ranks; /* this process's piece and the pieces of a frame */
  double *times;   /* of the files written so far */
  int nframes, cap;
  int64_t *ids; /* connectivity / offsets work array */
  size_t n;
  /* zlib: one array's bytes in creation order, the compressed blocks of a
   * frame, and each block's place and size in them */
  int zlib;
  unsigned char *raw, *pool;
  size_t pool_cap;
  size_t zat[SPH_FIELD_COUNT + 4];
  uint64_t zsize[SPH_FIELD_COUNT + 4], zraw[SPH_FIELD_COUNT + 4];
} vtk_sink;

typedef struct array_desc {
  const char *name;
  const char *type; /* Float64, Int64, Int32 */
  int ncomp;
  const void *data;
  const int64_t *slot; /* per-particle data in storage order, or NULL */
} array_desc;

/* element i of the listing (component i % ncomp of particle i / ncomp) */
static const char *element(const array_desc *a, size_t i, size_t size) {
  size_t nc = (size_t)a->ncomp, j = i / nc;
  size_t at = a->slot ? (size_t)a->slot[j] * nc + i % nc : i;
  return (const char *)a->data + at * size;
}

static size_t type_size(const char *type) {
  return strcmp(type, "Int32") ? 8 : 4;
}

static sph_status vtk_open(sph_sink *sink, const sph_sim *sim, const char *dir,
                           sph_error *err) {
  vtk_sink *v = calloc(1, sizeof *v);
  if (!v)
    return sph_error_set(err, SPH_ERR_NOMEM, "vtk sink");
  sink->data = v;
  snprintf(v->dir, sizeof v->dir, "%s", dir);
  snprintf(v->name, sizeof v->name, "%s", sim->scene->name);
  v->ascii = sim->scene->output.vtk_ascii;
  v->rank = sph_domain_rank(sim->domain);
  v->ranks = sph_domain_size(sim->domain);
  /* a piece of an updated-Lagrangian run: up to its set's capacity */
  v->n = sim->domain ? sim->ps->capacity : sim->ps->n;
  v->cap = (int)(sim->scene->t_end / sim->scene->output.every) + 4;
  v->times = malloc((size_t)v->cap * sizeof *v->times);
  v->ids = malloc((v->n ? v->n : 1) * sizeof *v->ids);
  if (!v->times || !v->ids)
    return sph_error_set(err, SPH_ERR_NOMEM, "vtk sink");
  v->zlib = sim->scene->output.vtk_zlib;
  if (v->zlib) { /* room for every array of a frame, compressed */
    const sph_output *o = &sim->scene->output;
    size_t nn = v->n ? v->n : 1, total = nn * (3 + 2 + 1) * 8, widest = 3;
    for (int i = 0; i < o->nfields; ++i) {
      int nc = sph_field_components((sph_field)o->fields[i]);
      total += nn * (size_t)nc * 8;
      widest = (size_t)nc > widest ? (size_t)nc : widest;
    }
    v->pool_cap = compressBound((uLong)total) + 64 * (SPH_FIELD_COUNT + 4);
    v->raw = malloc(nn * widest * 8);
    v->pool = malloc(v->pool_cap);
    if (!v->raw || !v->pool)
      return sph_error_set(err, SPH_ERR_NOMEM, "vtk sink (zlib)");
  }
  /* resuming: the frames before the checkpoint are on disk */
  for (int i = 0; i < sink->resume_frames && i < v->cap; ++i)
    v->times[v->nframes++] = sph_output_time(sim->scene, i);
  return SPH_OK;
}

/* the arrays of a frame: the scene's output fields and integer ids */
static int frame_arrays(const sph_frame *fr, array_desc *out, int max) {
  const sph_output *o = &fr->sim->scene->output;
  int k = 0;
  for (int i = 0; i < o->nfields && k < max; ++i) {
    sph_field f = (sph_field)o->fields[i];
    if (!fr->ps->field[f])
      continue; /* the method does not provide it */
    out[k++] =
        (array_desc){sph_field_name(f), "Float64", sph_field_components(f),
                     fr->ps->field[f], fr->ps->slot};
  }
  if (o->body_id && k < max)
    out[k++] = (array_desc){"body_id", "Int32", 1, fr->ps->body, fr->ps->slot};
  if (o->particle_id && k < max)
    out[k++] =
        (array_desc){"particle_id", "Int64", 1, fr->ps->id, fr->ps->slot};
  return k;
}

static void write_ascii(FILE *f, const array_desc *a, size_t n) {
  size_t count = n * (size_t)a->ncomp;
  size_t size = type_size(a->type);
  for (size_t i = 0; i < count; ++i) {
    const void *e = element(a, i, size);
    if (!strcmp(a->type, "Float64"))
      fprintf(f, "%.17g", *(const double *)e);
    else if (!strcmp(a->type, "Int64"))
      fprintf(f, "%lld", (long long)*(const int64_t *)e);
    else
      fprintf(f, "%d", (int)*(const int32_t *)e);
    fputc(i + 1 < count ? ' ' : '\n', f);
  }
}

/* the appended bytes of block k: its header words and data */
static uint64_t block_bytes(const vtk_sink *v, int k, const array_desc *a,
                            size_t n) {
  if (!v->zlib)
    return 8 + n * (size_t)a->ncomp * type_size(a->type);
  return v->zraw[k] ? 4 * 8 + v->zsize[k] : 3 * 8;
}

static void data_array(FILE *f, const vtk_sink *v, const array_desc *a,
                       uint64_t *offset, size_t n, int k) {
  fprintf(f,
          "        <DataArray type=\"%s\" Name=\"%s\" "
          "NumberOfComponents=\"%d\" format=\"%s\"",
          a->type, a->name, a->ncomp, v->ascii ? "ascii" : "appended");
  if (v->ascii) {
    fputs(">\n", f);
    write_ascii(f, a, n);
    fputs("        </DataArray>\n", f);
  } else {
    fprintf(f, " offset=\"%llu\"/>\n", (unsigned long long)*offset);
    *offset += block_bytes(v, k, a, n);
  }
}

static void append_block(FILE *f, const array_desc *a, size_t n) {
  size_t size = type_size(a->type), count = n * (size_t)a->ncomp;
  uint64_t bytes = count * size;
  fwrite(&bytes, sizeof bytes, 1, f); /* x86-64 and arm64: little endian */
  if (!a->slot) {
    fwrite(a->data, 1, bytes, f);
    return;
  }
  char buf[8192];
  for (size_t i = 0, used = 0; i < count; ++i) {
    memcpy(buf + used, element(a, i, size), size);
    if ((used += size) == sizeof buf || i + 1 == count) {
      fwrite(buf, 1, used, f);
      used = 0;
    }
  }
}

/* zlib: array a (creation order) compressed as block k into the pool */
static sph_status zblock(vtk_sink *v, int k, const array_desc *a, size_t n,
                         size_t *used, sph_error *err) {
  size_t size = type_size(a->type), count = n * (size_t)a->ncomp;
  for (size_t i = 0; i < count; ++i)
    memcpy(v->raw + i * size, element(a, i, size), size);
  uLongf len = (uLongf)(v->pool_cap - *used);
  v->zraw[k] = count * size;
  v->zat[k] = *used;
  v->zsize[k] = 0;
  if (!count)
    return SPH_OK;
  if (compress2(v->pool + *used, &len, v->raw, (uLong)(count * size), 1) !=
      Z_OK)
    return sph_error_set(err, SPH_ERR_NOMEM, "vtk sink: zlib failed");
  v->zsize[k] = len;
  *used += len;
  return SPH_OK;
}

static void append_zblock(FILE *f, const vtk_sink *v, int k) {
  uint64_t head[4] = {v->zraw[k] ? 1 : 0, v->zraw[k], 0, v->zsize[k]};
  fwrite(head, 8, v->zraw[k] ? 4 : 3, f);
  fwrite(v->pool + v->zat[k], 1, v->zsize[k], f);
}

static sph_status write_pvd(vtk_sink *v, sph_error *err) {
  char path[1200];
  snprintf(path, sizeof path, "%s/%s.pvd", v->dir, v->name);
  sph_atomic_file af;
  SPH_TRY(sph_atomic_open(&af, path, err));
  fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" "
        "version=\"1.0\" byte_order=\"LittleEndian\" "
        "header_type=\"UInt64\">\n  <Collection>\n",
        af.f);
  for (int i = 0; i < v->nframes; ++i)
    fprintf(af.f,
            "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" "
            "file=\"%s_%04d.%s\"/>\n",
            v->times[i], v->name, i, v->ranks > 1 ? "pvtp" : "vtp");
  fputs("  </Collection>\n</VTKFile>\n", af.f);
  sph_status st = sph_atomic_commit(&af, err);
  if (st != SPH_OK)
    sph_atomic_abort(&af);
  return st;
}

/* the .pvtp of a distributed frame: the arrays of the pieces, their files */
static sph_status write_pvtp(const vtk_sink *v, const sph_frame *fr,
                             sph_error *err) {
  char path[1200];
  snprintf(path, sizeof path, "%s/%s_%04d.pvtp", v->dir, v->name, fr->index);
  array_desc arrays[SPH_FIELD_COUNT + 2];
  int na = frame_arrays(fr, arrays, SPH_FIELD_COUNT + 2);
  sph_atomic_file af;
  SPH_TRY(sph_atomic_open(&af, path, err));
  fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"PPolyData\" "
        "version=\"1.0\" byte_order=\"LittleEndian\" "
        "header_type=\"UInt64\">\n  <PPolyData GhostLevel=\"0\">\n",
        af.f);
  /* the time as in the pieces: VTK's parallel reader gives it to ParaView
   * when the .pvtp series is opened without the .pvd */
  fprintf(af.f,
          "    <FieldData>\n"
          "      <DataArray type=\"Float64\" Name=\"TimeValue\" "
          "NumberOfTuples=\"1\" format=\"ascii\">%.17g</DataArray>\n"
          "    </FieldData>\n    <PPointData>\n",
          fr->time);
  for (int i = 0; i < na; ++i)
    fprintf(af.f,
            "      <PDataArray type=\"%s\" Name=\"%s\" "
            "NumberOfComponents=\"%d\"/>\n",
            arrays[i].type, arrays[i].name, arrays[i].ncomp);
  fputs("    </PPointData>\n    <PPoints>\n      <PDataArray "
        "type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n"
        "    </PPoints>\n",
        af.f);
  for (int r = 0; r < v->ranks; ++r)
    fprintf(af.f, "    <Piece Source=\"%s_%04d_p%d.vtp\"/>\n", v->name,
            fr->index, r);
  fputs("  </PPolyData>\n</VTKFile>\n", af.f);
  sph_status st = sph_atomic_commit(&af, err);
  if (st != SPH_OK)
    sph_atomic_abort(&af);
  return st;
}

/* the .vtp of a frame (a piece of it over MPI ranks) */
static sph_status write_vtp(vtk_sink *v, const sph_frame *fr, const char *path,
                            sph_error *err) {
  size_t n = fr->ps->n;
  array_desc arrays[SPH_FIELD_COUNT + 2];
  int na = frame_arrays(fr, arrays, SPH_FIELD_COUNT + 2);
  const double *x = fr->ps->field[SPH_FIELD_POSITION]
                        ? fr->ps->field[SPH_FIELD_POSITION]
                        : fr->ps->field[SPH_FIELD_POSITION0];
  array_desc points = {"Points", "Float64", 3, x, fr->ps->slot};
  for (size_t i = 0; i < n; ++i)
    v->ids[i] = (int64_t)i; /* connectivity i, offsets i + 1 */
  array_desc conn = {"connectivity", "Int64", 1, v->ids, NULL};
  /* zlib: blocks 0..na-1 the arrays, then points, connectivity, offsets */
  if (v->zlib) {
    size_t used = 0;
    for (int i = 0; i < na; ++i)
      SPH_TRY(zblock(v, i, &arrays[i], n, &used, err));
    SPH_TRY(zblock(v, na, &points, n, &used, err));
    SPH_TRY(zblock(v, na + 1, &conn, n, &used, err));
    for (size_t i = 0; i < n; ++i)
      v->ids[i] = (int64_t)i + 1;
    SPH_TRY(zblock(v, na + 2, &conn, n, &used, err));
    for (size_t i = 0; i < n; ++i)
      v->ids[i] = (int64_t)i;
  }
  sph_atomic_file af;
  SPH_TRY(sph_atomic_open(&af, path, err));
  FILE *f = af.f;
  /* the time as the data set's field data, where VTK's reader finds it */
  fprintf(f,
          "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" "
          "version=\"1.0\" byte_order=\"LittleEndian\" "
          "header_type=\"UInt64\"%s>\n  <PolyData>\n    <FieldData>\n"
          "      <DataArray type=\"Float64\" Name=\"TimeValue\" "
          "NumberOfTuples=\"1\" format=\"ascii\">%.17g</DataArray>\n"
          "    </FieldData>\n",
          v->zlib ? " compressor=\"vtkZLibDataCompressor\"" : "", fr->time);
  fprintf(f,
          "    <Piece "
          "NumberOfPoints=\"%zu\" NumberOfVerts=\"%zu\" NumberOfLines=\"0\" "
          "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
          n, n);
  uint64_t offset = 0;
  fputs("      <PointData>\n", f);
  for (int i = 0; i < na; ++i)
    data_array(f, v, &arrays[i], &offset, n, i);
  fputs("      </PointData>\n      <Points>\n", f);
  data_array(f, v, &points, &offset, n, na);
  fputs("      </Points>\n      <Verts>\n", f);
  data_array(f, v, &conn, &offset, n, na + 1);
  /* offsets: 1..n, written from the same work array shifted by one */
  uint64_t offsets_at = offset;
  if (v->ascii) {
    fputs("        <DataArray type=\"Int64\" Name=\"offsets\" "
          "NumberOfComponents=\"1\" format=\"ascii\">\n",
          f);
    for (size_t i = 0; i < n; ++i)
      fprintf(f, "%zu%c", i + 1, i + 1 < n ? ' ' : '\n');
    fputs("        </DataArray>\n", f);
  } else {
    fprintf(f,
            "        <DataArray type=\"Int64\" Name=\"offsets\" "
            "NumberOfComponents=\"1\" format=\"appended\" offset=\"%llu\"/>\n",
            (unsigned long long)offsets_at);
  }
  fputs("      </Verts>\n    </Piece>\n  </PolyData>\n", f);
  if (v->zlib) {
    fputs("  <AppendedData encoding=\"raw\">\n   _", f);
    for (int k = 0; k < na + 3; ++k)
      append_zblock(f, v, k);
    fputs("\n  </AppendedData>\n", f);
  } else if (!v->ascii) {
    fputs("  <AppendedData encoding=\"raw\">\n   _", f);
    for (int i = 0; i < na; ++i)
      append_block(f, &arrays[i], n);
    append_block(f, &points, n);
    append_block(f, &conn, n);
    for (size_t i = 0; i < n; ++i)
      v->ids[i] = (int64_t)i + 1;
    append_block(f, &conn, n);
    fputs("\n  </AppendedData>\n", f);
  }
  fputs("</VTKFile>\n", f);
  sph_status st = sph_atomic_commit(&af, err);
  if (st != SPH_OK)
    sph_atomic_abort(&af);
  return st;
}

static sph_status vtk_write(sph_sink *sink, const sph_frame *fr,
                            sph_error *err) {
  vtk_sink *v = sink->data;
  if (fr->index >= 10000)
    return sph_error_set(err, SPH_ERR_ARG, "more than 9999 VTK frames");
  char path[1200];
  if (v->ranks > 1)
    snprintf(path, sizeof path, "%s/%s_%04d_p%d.vtp", v->dir, v->name,
             fr->index, v->rank);
  else
    snprintf(path, sizeof path, "%s/%s_%04d.vtp", v->dir, v->name, fr->index);
  sph_status st = write_vtp(v, fr, path, err);
  /* every piece in place before the .pvtp names them */
  if (v->ranks > 1) {
    st = sph_domain_agree(fr->sim->domain, st, err);
    if (st == SPH_OK && v->rank == 0)
      st = write_pvtp(v, fr, err);
  }
  if (st != SPH_OK)
    return st;
  if (v->nframes == v->cap) {
    double *t = realloc(v->times, 2 * (size_t)v->cap * sizeof *t);
    if (!t)
      return sph_error_set(err, SPH_ERR_NOMEM, "vtk sink");
    v->times = t;
    v->cap *= 2;
  }
  v->times[v->nframes++] = fr->time;
  return v->rank == 0 ? write_pvd(v, err) : SPH_OK;
}

static sph_status vtk_close(sph_sink *sink, sph_error *err) { return SPH_OK; }

static void vtk_destroy(sph_sink *sink) {
  vtk_sink *v = sink->data;
  if (!v)
    return;
  free(v->times);
  free(v->ids);
  free(v->raw);
  free(v->pool);
  free(v);
  sink->data = NULL;
}

static int vtk_enabled(const sph_scene *scene) { return scene->output.vtk; }

const sph_sink_ops sph_vtk_sink_ops = {
    .name = "vtk",
    .enabled = vtk_enabled,
    .distributed = 1,
    .open = vtk_open,
    .write = vtk_write,
    .close = vtk_close,
    .destroy = vtk_destroy,
};
