/* Checkpoint files (layout in include/sph/checkpoint.h): written through
 * an atomic temporary file with a zlib CRC-32 over every byte, read whole
 * and checked before anything of the simulation is touched. */
#include <errno.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "sph/checkpoint.h"
#include "sph/node.h"
#include "sph/reference.h"
#include "sph/sink.h"

static const char magic[8] = "SPHCKPT";
static const uint32_t endian_tag = 0x01020304u;

/* The verdict's scalars, in file order. */
#define VERDICT_FIELD(f)                                                       \
  { offsetof(sph_verdict, f), sizeof(((sph_verdict *)0)->f) }
static const struct {
  size_t off, size;
} verdict_fields[] = {
    VERDICT_FIELD(stable),
    VERDICT_FIELD(nan),
    VERDICT_FIELD(reason),
    VERDICT_FIELD(t_tripped),
    VERDICT_FIELD(energy_tracked),
    VERDICT_FIELD(frames),
    VERDICT_FIELD(energy0),
    VERDICT_FIELD(energy_max),
    VERDICT_FIELD(energy_final),
    VERDICT_FIELD(J_min),
    VERDICT_FIELD(J_max),
    VERDICT_FIELD(checkerboard),
    VERDICT_FIELD(checkerboard_max),
    VERDICT_FIELD(lin0),
    VERDICT_FIELD(ang0),
    VERDICT_FIELD(lin_scale),
    VERDICT_FIELD(ang_scale),
    VERDICT_FIELD(lin_drift),
    VERDICT_FIELD(ang_drift),
    VERDICT_FIELD(fracture_max_stretch),
    VERDICT_FIELD(fracture_pairs_over),
    VERDICT_FIELD(fracture_peak_stretch),
    VERDICT_FIELD(fracture_peak_over),
    VERDICT_FIELD(zigzag),
    VERDICT_FIELD(zigzag_max),
};
#define NVERDICT (sizeof verdict_fields / sizeof *verdict_fields)

typedef struct header {
  uint64_t particles;
  char method[32];
  char scene[64];
  uint32_t scene_crc;
  double t;
  uint64_t steps;
  double dt_min, dt_max, dt_last;
  int32_t next_output;
} header;

/* The header's fields after magic, version and byte-order tag, in file
 * order: one list for writing and reading. */
#define HEADER_FIELD(f)                                                        \
  { offsetof(header, f), sizeof(((header *)0)->f) }
static const struct {
  size_t off, size;
} header_fields[] = {
    HEADER_FIELD(particles),   HEADER_FIELD(method), HEADER_FIELD(scene),
    HEADER_FIELD(scene_crc),   HEADER_FIELD(t),      HEADER_FIELD(steps),
    HEADER_FIELD(dt_min),      HEADER_FIELD(dt_max), HEADER_FIELD(dt_last),
    HEADER_FIELD(next_output),
};
#define NHEADER (sizeof header_fields / sizeof *header_fields)

sph_status sph_checkpoint_scene_crc(const sph_scene *s, unsigned *crc,
                                    sph_error *err) {
  char *buf = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&buf, &len);
  if (!f)
    return sph_error_set(err, SPH_ERR_NOMEM, "scene checksum");
  sph_status st = sph_node_write(s->root, f, err);
  fclose(f);
  if (st == SPH_OK)
    *crc = (unsigned)crc32(0L, (const Bytef *)buf, (uInt)len);
  free(buf);
  return st;
}

/* ---- writing
 * ----------------------------------------------------------------- */

typedef struct writer {
  FILE *f;
  uLong crc;
} writer;

static void put(writer *w, const void *p, size_t len) {
  const unsigned char *b = p;
  w->crc = crc32(w->crc, b, (uInt)len);
  fwrite(b, 1, len, w->f);
}

static void make_header(const sph_sim *sim, int next_output, unsigned crc,
                        header *h) {
  memset(h, 0, sizeof *h);
  h->particles = sim->ps->n;
  snprintf(h->method, sizeof h->method, "%s", sim->method->name);
  snprintf(h->scene, sizeof h->scene, "%s", sim->scene->name);
  h->scene_crc = crc;
  h->t = sim->t;
  h->steps = sim->steps;
  h->dt_min = sim->dt_min;
  h->dt_max = sim->dt_max;
  h->dt_last = sim->dt_last;
  h->next_output = next_output;
}

static void put_header(writer *w, const header *h) {
  uint32_t version = SPH_CHECKPOINT_VERSION;
  put(w, magic, sizeof magic);
  put(w, &version, 4);
  put(w, &endian_tag, 4);
  for (size_t i = 0; i < NHEADER; ++i)
    put(w, (const char *)h + header_fields[i].off, header_fields[i].size);
}

/* How often each timer's part and each term ran (summary.json "calls"), so
 * a resumed run reports the counts of an uninterrupted one: u32 count, then
 * that many u64, the timers' then the terms'. */
static void put_calls(writer *w, const sph_sim *sim) {
  uint32_t n = (uint32_t)(sim->ntimers + sim->nterms);
  put(w, &n, 4);
  for (int i = 0; i < sim->ntimers; ++i) {
    uint64_t c = sim->timers[i].calls;
    put(w, &c, 8);
  }
  for (int i = 0; i < sim->nterms; ++i) {
    uint64_t c = sim->terms[i].calls;
    put(w, &c, 8);
  }
}

sph_status sph_checkpoint_write(const char *dir, const sph_sim *sim,
                                const sph_verdict *v, int next_output,
                                sph_error *err) {
  unsigned crc = 0;
  SPH_TRY(sph_checkpoint_scene_crc(sim->scene, &crc, err));
  sph_state_array arr[SPH_MAX_STATE + 1];
  int na = sim->method->state((sph_sim *)sim, arr);
  na += sph_reference_state(sim->reference, arr + na);
  char path[1024], prev[1100];
  snprintf(path, sizeof path, "%s/%s", dir, SPH_CHECKPOINT_FILE);
  snprintf(prev, sizeof prev, "%s/%s", dir, SPH_CHECKPOINT_PREVIOUS);
  sph_atomic_file af;
  SPH_TRY(sph_atomic_open(&af, path, err));
  writer w = {af.f, crc32(0L, Z_NULL, 0)};
  header h;
  make_header(sim, next_output, crc, &h);
  put_header(&w, &h);
  for (size_t i = 0; i < NVERDICT; ++i)
    put(&w, (const char *)v + verdict_fields[i].off, verdict_fields[i].size);
  put_calls(&w, sim);
  uint32_t n32 = (uint32_t)na;
  put(&w, &n32, 4);
  for (int i = 0; i < na; ++i) {
    char name[16] = {0};
    uint64_t len = arr[i].len;
    snprintf(name, sizeof name, "%s", arr[i].name);
    put(&w, name, sizeof name);
    put(&w, &len, 8);
  }
  for (int i = 0; i < na; ++i)
    put(&w, arr[i].data, arr[i].len * sizeof(double));
  uint32_t sum = (uint32_t)w.crc;
  fwrite(&sum, 4, 1, af.f);
  /* keep the last good one until the new one is in place */
  if (rename(path, prev) != 0 && errno != ENOENT) {
    sph_atomic_abort(&af);
    return sph_error_at(err, SPH_ERR_IO, prev, 0, 0, NULL,
                        "cannot keep the previous checkpoint: %s",
                        strerror(errno));
  }
  sph_status st = sph_atomic_commit(&af, err);
  if (st != SPH_OK)
    sph_atomic_abort(&af);
  return st;
}

/* ---- reading
 * ----------------------------------------------------------------- */

typedef struct reader {
  const unsigned char *b;
  size_t len, at;
} reader;

static int get(reader *r, void *out, size_t len) {
  if (r->len - r->at < len)
    return 0;
  memcpy(out, r->b + r->at, len);
  r->at += len;
  return 1;
}

/* Checks one file against the simulation; on success copies it in. */
static sph_status load(const char *path, sph_sim *sim, sph_verdict *v,
                       int *next_output, sph_error *err) {
  FILE *f = fopen(path, "rb");
  if (!f)
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL, "cannot open: %s",
                        strerror(errno));
  unsigned char *buf = NULL;
  size_t len = 0, cap = 0;
  for (;;) {
    if (len == cap) {
      cap = cap ? 2 * cap : 1 << 20;
      unsigned char *nb = realloc(buf, cap);
      if (!nb) {
        free(buf);
        fclose(f);
        return sph_error_set(err, SPH_ERR_NOMEM, "checkpoint");
      }
      buf = nb;
    }
    size_t got = fread(buf + len, 1, cap - len, f);
    len += got;
    if (got == 0)
      break;
  }
  int bad_read = ferror(f);
  fclose(f);
  sph_status st = SPH_OK;
#define FAIL(...)                                                              \
  do {                                                                         \
    st = sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL, __VA_ARGS__);         \
    goto done;                                                                 \
  } while (0)
  if (bad_read)
    FAIL("cannot read");
  if (len < 12 || memcmp(buf, magic, sizeof magic))
    FAIL("not an sph checkpoint");
  uint32_t sum;
  memcpy(&sum, buf + len - 4, 4);
  if ((uint32_t)crc32(crc32(0L, Z_NULL, 0), buf, (uInt)(len - 4)) != sum)
    FAIL("checksum mismatch: the file is damaged or truncated");
  reader r = {buf, len - 4, sizeof magic};
  uint32_t version = 0, tag = 0, na = 0;
  header h;
  memset(&h, 0, sizeof h);
  if (!get(&r, &version, 4) || !get(&r, &tag, 4))
    FAIL("truncated header");
  if (version != SPH_CHECKPOINT_VERSION)
    FAIL("version %u, this sph reads version %u", version,
         SPH_CHECKPOINT_VERSION);
  if (tag != endian_tag)
    FAIL("written on a machine of the other byte order");
  for (size_t i = 0; i < NHEADER; ++i)
    if (!get(&r, (char *)&h + header_fields[i].off, header_fields[i].size))
      FAIL("truncated header");
  h.method[sizeof h.method - 1] = h.scene[sizeof h.scene - 1] = '\0';
  unsigned crc = 0;
  if ((st = sph_checkpoint_scene_crc(sim->scene, &crc, err)) != SPH_OK)
    goto done;
  if (strcmp(h.scene, sim->scene->name))
    FAIL("written by scene '%s', not '%s'", h.scene, sim->scene->name);
  if (strcmp(h.method, sim->method->name))
    FAIL("written by method %s, not %s", h.method, sim->method->name);
  if (h.particles != sim->ps->n)
    FAIL("holds %llu particles, the scene makes %zu",
         (unsigned long long)h.particles, sim->ps->n);
  if (h.scene_crc != crc)
    FAIL("written for a different configuration of scene '%s' (its "
         "resolved settings differ; resume with the same scene and --set "
         "options)",
         h.scene);
  if (!(h.t >= 0.0 && h.t <= sim->scene->t_end) || h.next_output < 1)
    FAIL("time %g or output index %d out of range", h.t, h.next_output);
  sph_verdict vv = *v;
  for (size_t i = 0; i < NVERDICT; ++i)
    if (!get(&r, (char *)&vv + verdict_fields[i].off, verdict_fields[i].size))
      FAIL("truncated verdict");
  vv.reason[sizeof vv.reason - 1] = '\0';
  uint32_t ncalls = 0;
  uint64_t calls[SPH_MAX_TIMERS + SPH_MAX_TERMS];
  if (!get(&r, &ncalls, 4))
    FAIL("truncated call counts");
  if (ncalls != (uint32_t)(sim->ntimers + sim->nterms))
    FAIL("holds %u call counts, the run has %d timers and terms", ncalls,
         sim->ntimers + sim->nterms);
  if (!get(&r, calls, ncalls * sizeof *calls))
    FAIL("truncated call counts");
  sph_state_array arr[SPH_MAX_STATE + 1];
  int nm = sim->method->state(sim, arr);
  nm += sph_reference_state(sim->reference, arr + nm);
  if (!get(&r, &na, 4) || na != (uint32_t)nm)
    FAIL("holds %u state arrays, method %s has %d", na, h.method, nm);
  for (int i = 0; i < nm; ++i) {
    char name[16];
    uint64_t n;
    if (!get(&r, name, sizeof name) || !get(&r, &n, 8))
      FAIL("truncated array table");
    name[sizeof name - 1] = '\0';
    if (strcmp(name, arr[i].name) || n != arr[i].len)
      FAIL("array %d is %s[%llu], expected %s[%zu]", i, name,
           (unsigned long long)n, arr[i].name, arr[i].len);
  }
  size_t data_at = r.at, need = 0;
  for (int i = 0; i < nm; ++i)
    need += arr[i].len * sizeof(double);
  if (r.len - data_at != need)
    FAIL("holds %zu bytes of state, expected %zu", r.len - data_at, need);
  /* everything checked: copy in */
  for (int i = 0; i < nm; ++i)
    get(&r, arr[i].data, arr[i].len * sizeof(double));
  if (sim->method->restore && (st = sim->method->restore(sim, err)) != SPH_OK)
    goto done;
  /* after restore, which may count a rebuild of its own */
  for (int i = 0; i < sim->ntimers; ++i)
    sim->timers[i].calls = (unsigned long)calls[i];
  for (int i = 0; i < sim->nterms; ++i)
    sim->terms[i].calls = (unsigned long)calls[sim->ntimers + i];
  sim->t = h.t;
  sim->steps = (unsigned long)h.steps;
  sim->dt_min = h.dt_min;
  sim->dt_max = h.dt_max;
  sim->dt_last = h.dt_last;
  *next_output = h.next_output;
  *v = vv;
#undef FAIL
done:
  free(buf);
  return st;
}

sph_status sph_checkpoint_resume(const char *dir, sph_sim *sim, sph_verdict *v,
                                 int *next_output, char *used, size_t used_len,
                                 sph_error *err) {
  static const char *const names[] = {SPH_CHECKPOINT_FILE,
                                      SPH_CHECKPOINT_PREVIOUS};
  char why[2][900];
  for (int i = 0; i < 2; ++i) {
    char path[1100];
    snprintf(path, sizeof path, "%s/%s", dir, names[i]);
    sph_error e;
    sph_error_clear(&e);
    if (load(path, sim, v, next_output, &e) == SPH_OK) {
      snprintf(used, used_len, "%s", path);
      return SPH_OK;
    }
    snprintf(why[i], sizeof why[i], "%s: %.800s", names[i], e.message);
  }
  return sph_error_at(err, SPH_ERR_IO, dir, 0, 0, NULL,
                      "no valid checkpoint to resume from (%.360s; %.360s)",
                      why[0], why[1]);
}
