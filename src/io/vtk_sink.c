/* VTK sink: one XML PolyData file (.vtp) per output time, one vertex cell
 * per particle, appended raw little-endian binary with UInt64 block headers
 * (or inline ASCII for debugging), Float64 positions in the current
 * configuration, Int64 connectivity and offsets, the point arrays the scene
 * asks for; and a .pvd collection with the physical time of every file,
 * rewritten after each frame so a running or killed simulation always
 * loads in ParaView. Every file is written to a temporary name, fsync'd
 * and renamed. Particles are listed in creation order whatever their
 * storage order (sph_particles_sort_morton). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sph/sink.h"

typedef struct vtk_sink {
  char dir[1024];
  char name[64];
  int ascii;
  double *times; /* of the files written so far */
  int nframes, cap;
  int64_t *ids; /* connectivity / offsets work array */
  size_t n;
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
  v->n = sim->ps->n;
  v->cap = (int)(sim->scene->t_end / sim->scene->output.every) + 4;
  v->times = malloc((size_t)v->cap * sizeof *v->times);
  v->ids = malloc((v->n ? v->n : 1) * sizeof *v->ids);
  if (!v->times || !v->ids)
    return sph_error_set(err, SPH_ERR_NOMEM, "vtk sink");
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

static void data_array(FILE *f, const vtk_sink *v, const array_desc *a,
                       uint64_t *offset, size_t n) {
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
    *offset += 8 + n * (size_t)a->ncomp * type_size(a->type);
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
            "file=\"%s_%04d.vtp\"/>\n",
            v->times[i], v->name, i);
  fputs("  </Collection>\n</VTKFile>\n", af.f);
  sph_status st = sph_atomic_commit(&af, err);
  if (st != SPH_OK)
    sph_atomic_abort(&af);
  return st;
}

static sph_status vtk_write(sph_sink *sink, const sph_frame *fr,
                            sph_error *err) {
  vtk_sink *v = sink->data;
  size_t n = fr->ps->n;
  if (fr->index >= 10000)
    return sph_error_set(err, SPH_ERR_ARG, "more than 9999 VTK frames");
  char path[1200];
  snprintf(path, sizeof path, "%s/%s_%04d.vtp", v->dir, v->name, fr->index);
  array_desc arrays[SPH_FIELD_COUNT + 2];
  int na = frame_arrays(fr, arrays, SPH_FIELD_COUNT + 2);
  const double *x = fr->ps->field[SPH_FIELD_POSITION]
                        ? fr->ps->field[SPH_FIELD_POSITION]
                        : fr->ps->field[SPH_FIELD_POSITION0];
  array_desc points = {"Points", "Float64", 3, x, fr->ps->slot};
  for (size_t i = 0; i < n; ++i)
    v->ids[i] = (int64_t)i; /* connectivity i, offsets i + 1 */
  array_desc conn = {"connectivity", "Int64", 1, v->ids, NULL};
  sph_atomic_file af;
  SPH_TRY(sph_atomic_open(&af, path, err));
  FILE *f = af.f;
  /* the time as the data set's field data, where VTK's reader finds it */
  fprintf(f,
          "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" "
          "version=\"1.0\" byte_order=\"LittleEndian\" "
          "header_type=\"UInt64\">\n  <PolyData>\n    <FieldData>\n"
          "      <DataArray type=\"Float64\" Name=\"TimeValue\" "
          "NumberOfTuples=\"1\" format=\"ascii\">%.17g</DataArray>\n"
          "    </FieldData>\n",
          fr->time);
  fprintf(f,
          "    <Piece "
          "NumberOfPoints=\"%zu\" NumberOfVerts=\"%zu\" NumberOfLines=\"0\" "
          "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
          n, n);
  uint64_t offset = 0;
  fputs("      <PointData>\n", f);
  for (int i = 0; i < na; ++i)
    data_array(f, v, &arrays[i], &offset, n);
  fputs("      </PointData>\n      <Points>\n", f);
  data_array(f, v, &points, &offset, n);
  fputs("      </Points>\n      <Verts>\n", f);
  data_array(f, v, &conn, &offset, n);
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
  if (!v->ascii) {
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
  if (st != SPH_OK) {
    sph_atomic_abort(&af);
    return st;
  }
  if (v->nframes == v->cap) {
    double *t = realloc(v->times, 2 * (size_t)v->cap * sizeof *t);
    if (!t)
      return sph_error_set(err, SPH_ERR_NOMEM, "vtk sink");
    v->times = t;
    v->cap *= 2;
  }
  v->times[v->nframes++] = fr->time;
  return write_pvd(v, err);
}

static sph_status vtk_close(sph_sink *sink, sph_error *err) { return SPH_OK; }

static void vtk_destroy(sph_sink *sink) {
  vtk_sink *v = sink->data;
  if (!v)
    return;
  free(v->times);
  free(v->ids);
  free(v);
  sink->data = NULL;
}

const sph_sink_ops sph_vtk_sink_ops = {
    .name = "vtk",
    .open = vtk_open,
    .write = vtk_write,
    .close = vtk_close,
    .destroy = vtk_destroy,
};
