/* Checkpoint files (layout in include/sph/checkpoint.h): written through
 * an atomic temporary file with a zlib CRC-32 over every byte, read whole
 * and checked before anything of the simulation is touched. Over MPI ranks
 * every rank writes its owned particles' state as a piece in that layout
 * and rank 0 then a text manifest naming the pieces with their sizes and
 * checksums, alternating between two slots so the newest complete
 * checkpoint is never overwritten. */
#include <errno.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>

#include "io/checkpoint.h"
#include "io/sink.h"
#include "parallel/domain.h"
#include "scene/node.h"
#include "solver/reference.h"

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
  uint64_t bytes;
} writer;

static void put(writer *w, const void *p, size_t len) {
  const unsigned char *b = p;
  w->crc = crc32(w->crc, b, (uInt)len);
  w->bytes += len;
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

/* The arrays of a checkpoint of n owned particles: the method's, the scene
 * reference's, and over MPI ranks with migrating particles the domain's
 * (its owned particles whole and its state; packed from the simulation
 * when fill); returns their count. */
static int state_arrays(const sph_sim *sim, size_t n, int fill,
                        sph_state_array *arr) {
  int na = sim->method->state((sph_sim *)sim, arr);
  na += sph_reference_state(sim->reference, arr + na);
  double *parts, *dom;
  size_t np, nd;
  if (sph_domain_checkpoint(sim->domain, sim->ps, n, fill, &parts, &np, &dom,
                            &nd)) {
    arr[na++] = (sph_state_array){"particles", parts, np};
    arr[na++] = (sph_state_array){"domain", dom, nd};
  }
  return na;
}

/* A piece's identity in its manifest: its length and its stored CRC-32. */
typedef struct piece_sum {
  uint64_t size;
  uint32_t crc;
} piece_sum;

/* Writes one checkpoint file at path (prev: where the one before is kept,
 * or NULL); *sum receives its length and checksum. */
static sph_status write_file(const char *path, const char *prev,
                             const sph_sim *sim, const sph_verdict *v,
                             int next_output, piece_sum *sum, sph_error *err) {
  unsigned crc = 0;
  SPH_TRY(sph_checkpoint_scene_crc(sim->scene, &crc, err));
  sph_state_array arr[SPH_MAX_STATE + 3];
  int na = state_arrays(sim, sim->ps->n, 1, arr);
  sph_atomic_file af;
  SPH_TRY(sph_atomic_open(&af, path, err));
  writer w = {af.f, crc32(0L, Z_NULL, 0), 0};
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
  uint32_t check = (uint32_t)w.crc;
  fwrite(&check, 4, 1, af.f);
  sum->size = w.bytes + 4;
  sum->crc = check;
  /* keep the last good one until the new one is in place (rename follows
   * no link; one under the name is refused as every output's is) */
  struct stat sb;
  if (prev && lstat(prev, &sb) == 0 && S_ISLNK(sb.st_mode)) {
    sph_atomic_abort(&af);
    return sph_error_at(err, SPH_ERR_IO, prev, 0, 0, NULL,
                        "is a symbolic link; sph does not write through "
                        "links (remove it, or write elsewhere with --out)");
  }
  if (prev && rename(path, prev) != 0 && errno != ENOENT) {
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

/* ---- manifests of runs over MPI ranks -------------------------------- */

static const char slot_name[2] = {'a', 'b'};

static void manifest_path(char *out, size_t len, const char *dir, int slot) {
  snprintf(out, len, "%s/checkpoint_%c.sphm", dir, slot_name[slot]);
}

static void piece_name(char *out, size_t len, int slot, int rank) {
  snprintf(out, len, "checkpoint_%c_p%d.sphc", slot_name[slot], rank);
}

/* What a manifest says: the rank count, the step and time, and the entry
 * of one rank's piece. */
typedef struct manifest {
  int ranks;
  unsigned long long step;
  double t;
  char scene[64], method[32];
  piece_sum mine;
  int have_mine;
} manifest;

/* Reads a manifest: its own CRC-32 line must hold; fills m with the
 * entry of `rank`. */
static sph_status manifest_read(const char *path, int rank, manifest *m,
                                sph_error *err) {
  memset(m, 0, sizeof *m);
  FILE *f;
  sph_error oe;
  if (sph_fopen_input(path, &f, NULL, &oe) != SPH_OK)
    return sph_error_set(err, SPH_ERR_IO, "%s", oe.message);
  char line[256];
  uLong crc = crc32(0L, Z_NULL, 0);
  int sealed = 0, ok = 1, version = 0;
  unsigned long stored = 0;
  while (ok && !sealed && fgets(line, sizeof line, f)) {
    if (sscanf(line, "crc %lx", &stored) == 1) {
      sealed = 1;
      break;
    }
    crc = crc32(crc, (const Bytef *)line, (uInt)strlen(line));
    int r;
    unsigned long long size;
    unsigned long pc;
    char name[64];
    if (line[0] == '#')
      continue;
    if (sscanf(line, "manifest %d", &version) == 1 ||
        sscanf(line, "scene %63s", m->scene) == 1 ||
        sscanf(line, "method %31s", m->method) == 1 ||
        sscanf(line, "ranks %d", &m->ranks) == 1 ||
        sscanf(line, "step %llu", &m->step) == 1 ||
        sscanf(line, "time %lg", &m->t) == 1)
      continue;
    if (sscanf(line, "piece %d %63s %llu %lx", &r, name, &size, &pc) == 4) {
      if (r == rank) {
        m->mine = (piece_sum){size, (uint32_t)pc};
        m->have_mine = 1;
      }
      continue;
    }
    ok = 0;
  }
  fclose(f);
  if (!sealed || !ok || (uint32_t)stored != (uint32_t)crc)
    return sph_error_set(err, SPH_ERR_IO,
                         "incomplete or damaged (its checksum line does "
                         "not hold)");
  if (version != 1 || m->ranks < 1)
    return sph_error_set(err, SPH_ERR_IO, "not a manifest this sph reads");
  return SPH_OK;
}

/* Rank 0: the manifest after every piece is in place. */
static sph_status manifest_write(const char *dir, int slot, const sph_sim *sim,
                                 const piece_sum *sums, int ranks,
                                 sph_error *err) {
  char path[1100], name[64];
  manifest_path(path, sizeof path, dir, slot);
  sph_atomic_file af;
  SPH_TRY(sph_atomic_open(&af, path, err));
  char *text = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&text, &len);
  if (!f) {
    sph_atomic_abort(&af);
    return sph_error_set(err, SPH_ERR_NOMEM, "checkpoint manifest");
  }
  fprintf(f,
          "# sph checkpoint over %d MPI ranks: one piece per rank, complete "
          "when this file ends with its crc\nmanifest 1\nscene %s\nmethod "
          "%s\nranks %d\nstep %lu\ntime %.17g\n",
          ranks, sim->scene->name, sim->method->name, ranks, sim->steps,
          sim->t);
  for (int r = 0; r < ranks; ++r) {
    piece_name(name, sizeof name, slot, r);
    fprintf(f, "piece %d %s %llu %08lx\n", r, name,
            (unsigned long long)sums[r].size, (unsigned long)sums[r].crc);
  }
  fclose(f);
  fwrite(text, 1, len, af.f);
  fprintf(af.f, "crc %08lx\n",
          (unsigned long)crc32(crc32(0L, Z_NULL, 0), (const Bytef *)text,
                               (uInt)len));
  free(text);
  sph_status st = sph_atomic_commit(&af, err);
  if (st != SPH_OK)
    sph_atomic_abort(&af);
  return st;
}

/* Rank 0: the slot to write, the one not holding the newest complete
 * checkpoint; its manifest is removed before any piece is rewritten. */
static int slot_to_write(const char *dir, int replace) {
  manifest m[2];
  int valid[2];
  for (int s = 0; s < 2; ++s) {
    char path[1100];
    manifest_path(path, sizeof path, dir, s);
    valid[s] = manifest_read(path, 0, &m[s], NULL) == SPH_OK;
  }
  int newest = valid[0] && (!valid[1] || m[0].step >= m[1].step) ? 0
               : valid[1]                                        ? 1
                                                                 : -1;
  return newest < 0 ? 0 : replace ? newest : 1 - newest;
}

static sph_status write_distributed(const char *dir, const sph_sim *sim,
                                    const sph_verdict *v, int next_output,
                                    int replace, sph_error *err) {
  sph_domain *d = sim->domain;
  int rank = sph_domain_rank(d), ranks = sph_domain_size(d), slot = 0;
  char path[1100], name[64];
  if (rank == 0) {
    slot = slot_to_write(dir, replace);
    manifest_path(path, sizeof path, dir, slot);
    remove(path);
  }
  slot = sph_domain_bcast_int(d, slot);
  piece_name(name, sizeof name, slot, rank);
  snprintf(path, sizeof path, "%s/%s", dir, name);
  piece_sum mine = {0, 0};
  sph_status st = write_file(path, NULL, sim, v, next_output, &mine, err);
  SPH_TRY(sph_domain_agree(d, st, err));
  /* every piece in place: rank 0 names them */
  uint64_t two[2] = {mine.size, mine.crc}, *all = NULL;
  piece_sum *sums = NULL;
  if (rank == 0) {
    all = malloc(2 * (size_t)ranks * sizeof *all);
    sums = malloc((size_t)ranks * sizeof *sums);
    if (!all || !sums)
      st = sph_error_set(err, SPH_ERR_NOMEM, "checkpoint manifest");
  }
  st = sph_domain_agree(d, st, err);
  if (st == SPH_OK)
    sph_domain_gather_u64(d, two, 2, all);
  for (int r = 0; st == SPH_OK && rank == 0 && r < ranks; ++r)
    sums[r] = (piece_sum){all[2 * r], (uint32_t)all[2 * r + 1]};
  if (st == SPH_OK && rank == 0)
    st = manifest_write(dir, slot, sim, sums, ranks, err);
  free(all);
  free(sums);
  return sph_domain_agree(d, st, err);
}

sph_status sph_checkpoint_write_as(const char *dir, const sph_sim *sim,
                                   const sph_verdict *v, int next_output,
                                   int replace, sph_error *err) {
  if (sim->domain)
    return write_distributed(dir, sim, v, next_output, replace, err);
  char path[1024], prev[1100];
  snprintf(path, sizeof path, "%s/%s", dir, SPH_CHECKPOINT_FILE);
  snprintf(prev, sizeof prev, "%s/%s", dir, SPH_CHECKPOINT_PREVIOUS);
  piece_sum sum;
  return write_file(path, replace ? NULL : prev, sim, v, next_output, &sum,
                    err);
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

/* What a file holds besides the state arrays. */
typedef struct loaded {
  header h;
  sph_verdict v;
  uint64_t calls[SPH_MAX_TIMERS + SPH_MAX_TERMS];
} loaded;

/* The most bytes a checkpoint of this simulation can hold: the header,
 * verdict and call counts with room to spare, and the state arrays of the
 * most particles this rank can own. */
static size_t most_bytes(sph_sim *sim) {
  sph_state_array arr[SPH_MAX_STATE + 3];
  size_t n_run = sim->ps->n, most = sph_domain_capacity(sim->domain, sim->ps);
  sim->ps->n = sph_domain_migrates(sim->domain) && most > n_run ? most : n_run;
  int na = state_arrays(sim, sim->ps->n, 0, arr);
  sim->ps->n = n_run;
  size_t bytes = 4096 + sizeof(sph_verdict) +
                 8 * (size_t)(SPH_MAX_TIMERS + SPH_MAX_TERMS) +
                 24 * (size_t)(SPH_MAX_STATE + 3);
  for (int i = 0; i < na; ++i)
    bytes += arr[i].len * sizeof(double);
  return bytes;
}

/* A file read whole (or its first 4096 bytes when it is larger than a
 * checkpoint of this simulation can be). */
typedef struct raw {
  unsigned char *buf;
  size_t len, limit;
  long long size;
  int oversize;
} raw;

#define FAIL(...)                                                              \
  return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL, __VA_ARGS__)

/* a regular file (a FIFO would hang); one larger than this simulation's
 * checkpoint can be is not read whole: its header says why (another
 * scene, method or particle count), else its size */
static sph_status read_whole(const char *path, sph_sim *sim, raw *w,
                             sph_error *err) {
  FILE *f;
  w->size = 0;
  SPH_TRY(sph_fopen_input(path, &f, &w->size, err));
  w->limit = most_bytes(sim);
  w->oversize = w->size < 0 || (unsigned long long)w->size > w->limit;
  size_t len = w->oversize ? 4096 : (size_t)w->size;
  w->buf = malloc(len ? len : 1);
  if (!w->buf) {
    fclose(f);
    return sph_error_set(err, SPH_ERR_NOMEM, "checkpoint");
  }
  size_t got = fread(w->buf, 1, len, f);
  int bad_read = (!w->oversize && got != len) || ferror(f);
  fclose(f);
  w->len = got;
  if (bad_read) {
    free(w->buf);
    FAIL("cannot read (it changed while read)");
  }
  return SPH_OK;
}

/* the magic, the checksum and, for a piece, its manifest's size and sum */
static sph_status check_bytes(const char *path, const manifest *m, const raw *w,
                              sph_error *err) {
  const unsigned char *buf = w->buf;
  size_t len = w->len;
  int oversize = w->oversize;
  if (len < 12 || memcmp(buf, magic, sizeof magic))
    FAIL("not an sph checkpoint");
  uint32_t sum;
  memcpy(&sum, buf + len - 4, 4);
  if (!oversize &&
      (uint32_t)crc32(crc32(0L, Z_NULL, 0), buf, (uInt)(len - 4)) != sum)
    FAIL("checksum mismatch: the file is damaged or truncated");
  if (!oversize && m && (len != m->mine.size || sum != m->mine.crc))
    FAIL("not the piece its manifest names (%zu bytes, checksum %08lx; the "
         "manifest: %llu bytes, %08lx): left by another checkpoint",
         len, (unsigned long)sum, (unsigned long long)m->mine.size,
         (unsigned long)m->mine.crc);
  return SPH_OK;
}

/* version, byte order and the header, checked against the simulation (and
 * the manifest m) before the file's size is */
static sph_status read_header(reader *r, const char *path, const manifest *m,
                              sph_sim *sim, const raw *w, header *hp,
                              sph_error *err) {
  uint32_t version = 0, tag = 0;
  header h;
  memset(&h, 0, sizeof h);
  if (!get(r, &version, 4) || !get(r, &tag, 4))
    FAIL("truncated header");
  if (version != SPH_CHECKPOINT_VERSION)
    FAIL("version %u, this sph reads version %u", version,
         SPH_CHECKPOINT_VERSION);
  if (tag != endian_tag)
    FAIL("written on a machine of the other byte order");
  for (size_t i = 0; i < NHEADER; ++i)
    if (!get(r, (char *)&h + header_fields[i].off, header_fields[i].size))
      FAIL("truncated header");
  h.method[sizeof h.method - 1] = h.scene[sizeof h.scene - 1] = '\0';
  unsigned crc = 0;
  SPH_TRY(sph_checkpoint_scene_crc(sim->scene, &crc, err));
  if (strcmp(h.scene, sim->scene->name))
    FAIL("written by scene '%s', not '%s'", h.scene, sim->scene->name);
  if (strcmp(h.method, sim->method->name))
    FAIL("written by method %s, not %s", h.method, sim->method->name);
  /* a rank of migrating particles owns its piece's count */
  size_t most = sph_domain_capacity(sim->domain, sim->ps);
  int moves = sph_domain_migrates(sim->domain);
  if (moves ? h.particles > most : h.particles != sim->ps->n)
    FAIL("holds %llu particles, the scene makes %zu%s",
         (unsigned long long)h.particles, moves ? most : sim->ps->n,
         moves ? " at most for this rank"
         : m   ? " for this rank"
               : "");
  if (h.scene_crc != crc)
    FAIL("written for a different configuration of scene '%s' (its "
         "resolved settings differ; resume with the same scene and --set "
         "options)",
         h.scene);
  if (w->oversize)
    FAIL("%lld bytes, a checkpoint of this run holds at most %zu: damaged, "
         "or not its checkpoint",
         w->size, w->limit);
  if (!(h.t >= 0.0 && h.t <= sim->scene->t_end) || h.next_output < 1 ||
      h.next_output > 100000)
    FAIL("time %g or output index %d out of range", h.t, h.next_output);
  if (m && (h.t != m->t || h.steps != m->step))
    FAIL("at step %llu, its manifest at step %llu", (unsigned long long)h.steps,
         m->step);
  *hp = h;
  return SPH_OK;
}

/* the verdict (over the caller's copy in *vv) and the call counts */
static sph_status read_verdict(reader *r, const char *path, const sph_sim *sim,
                               sph_verdict *vv, uint64_t *calls,
                               sph_error *err) {
  for (size_t i = 0; i < NVERDICT; ++i)
    if (!get(r, (char *)vv + verdict_fields[i].off, verdict_fields[i].size))
      FAIL("truncated verdict");
  vv->reason[sizeof vv->reason - 1] = '\0';
  sph_error ve;
  if (sph_verdict_check_restored(vv, &ve) != SPH_OK)
    FAIL("%s", ve.message);
  uint32_t ncalls = 0;
  if (!get(r, &ncalls, 4))
    FAIL("truncated call counts");
  if (ncalls != (uint32_t)(sim->ntimers + sim->nterms))
    FAIL("holds %u call counts, the run has %d timers and terms", ncalls,
         sim->ntimers + sim->nterms);
  if (!get(r, calls, ncalls * sizeof *calls))
    FAIL("truncated call counts");
  return SPH_OK;
}

/* the array table checked against the method's, then the state copied in
 * and the domain told the piece's owned count */
static sph_status read_state(reader *r, const char *path, sph_sim *sim,
                             const header *h, sph_error *err) {
  uint32_t na = 0;
  sph_state_array arr[SPH_MAX_STATE + 3];
  /* the arrays' lengths for the piece's owned count */
  size_t n_run = sim->ps->n;
  sim->ps->n = (size_t)h->particles;
  int nm = state_arrays(sim, sim->ps->n, 0, arr);
  sim->ps->n = n_run;
  if (!get(r, &na, 4) || na != (uint32_t)nm)
    FAIL("holds %u state arrays, method %s has %d", na, h->method, nm);
  for (int i = 0; i < nm; ++i) {
    char name[16];
    uint64_t n;
    if (!get(r, name, sizeof name) || !get(r, &n, 8))
      FAIL("truncated array table");
    name[sizeof name - 1] = '\0';
    if (strcmp(name, arr[i].name) || n != arr[i].len)
      FAIL("array %d is %s[%llu], expected %s[%zu]", i, name,
           (unsigned long long)n, arr[i].name, arr[i].len);
  }
  size_t data_at = r->at, need = 0;
  for (int i = 0; i < nm; ++i)
    need += arr[i].len * sizeof(double);
  if (r->len - data_at != need)
    FAIL("holds %zu bytes of state, expected %zu", r->len - data_at, need);
  /* everything checked: copy in */
  for (int i = 0; i < nm; ++i)
    get(r, arr[i].data, arr[i].len * sizeof(double));
  sph_error de;
  if (sph_domain_resume(sim->domain, sim->ps, (size_t)h->particles, &de))
    FAIL("%s", de.message);
  return SPH_OK;
}
#undef FAIL

/* Checks one file against the simulation (and, for a piece of a run over
 * MPI ranks, against its manifest m); on success copies the state arrays
 * in and the rest into *out (the verdict over a copy of v). */
static sph_status load(const char *path, const manifest *m, sph_sim *sim,
                       const sph_verdict *v, loaded *out, sph_error *err) {
  raw w;
  SPH_TRY(read_whole(path, sim, &w, err));
  sph_status st = check_bytes(path, m, &w, err);
  header h;
  sph_verdict vv = *v;
  if (st == SPH_OK) {
    reader r = {w.buf, w.oversize ? w.len : w.len - 4, sizeof magic};
    memset(out, 0, sizeof *out);
    st = read_header(&r, path, m, sim, &w, &h, err);
    if (st == SPH_OK)
      st = read_verdict(&r, path, sim, &vv, out->calls, err);
    if (st == SPH_OK)
      st = read_state(&r, path, sim, &h, err);
  }
  if (st == SPH_OK) {
    out->h = h;
    out->v = vv;
  }
  free(w.buf);
  return st;
}

/* After a load (on every rank: the method's rebuild may exchange halos):
 * what the method derives from its state, then counters, time and verdict. */
static sph_status apply(sph_sim *sim, const loaded *l, sph_verdict *v,
                        int *next_output, sph_error *err) {
  /* the time first: restore evaluates the rates at it (a moving wall) */
  sim->t = l->h.t;
  if (sim->method->restore)
    SPH_TRY(sim->method->restore(sim, err));
  /* after restore, which may count a rebuild of its own */
  for (int i = 0; i < sim->ntimers; ++i)
    sim->timers[i].calls = (unsigned long)l->calls[i];
  for (int i = 0; i < sim->nterms; ++i)
    sim->terms[i].calls = (unsigned long)l->calls[sim->ntimers + i];
  sim->steps = (unsigned long)l->h.steps;
  sim->dt_min = l->h.dt_min;
  sim->dt_max = l->h.dt_max;
  sim->dt_last = l->h.dt_last;
  *next_output = l->h.next_output;
  *v = l->v;
  return SPH_OK;
}

/* Over MPI ranks: the newest manifest whose every piece loads, tried on
 * every rank in the order rank 0 finds them. */
static sph_status resume_distributed(const char *dir, sph_sim *sim,
                                     sph_verdict *v, int *next_output,
                                     char *used, size_t used_len,
                                     sph_error *err) {
  sph_domain *d = sim->domain;
  int rank = sph_domain_rank(d), ranks = sph_domain_size(d), order = 0;
  char why[2][320] = {"", ""}, mpath[1100], piece[64], ppath[1200];
  if (rank == 0) { /* slots newest first, as digits base 3 (0: none) */
    manifest m[2];
    int ok[2];
    for (int s = 0; s < 2; ++s) {
      sph_error e;
      manifest_path(mpath, sizeof mpath, dir, s);
      ok[s] = manifest_read(mpath, 0, &m[s], &e) == SPH_OK;
      if (!ok[s])
        snprintf(why[s], sizeof why[s], "%.300s", e.message);
    }
    int first = ok[0] && (!ok[1] || m[0].step >= m[1].step) ? 0
                : ok[1]                                     ? 1
                                                            : -1;
    int second = first >= 0 && ok[1 - first] ? 1 - first : -1;
    order = first + 1 + 3 * (second + 1);
  }
  order = sph_domain_bcast_int(d, order);
  int cand[2] = {order % 3 - 1, order / 3 - 1};
  for (int k = 0; k < 2 && cand[k] >= 0; ++k) {
    int s = cand[k];
    manifest m;
    sph_error e;
    sph_error_clear(&e);
    manifest_path(mpath, sizeof mpath, dir, s);
    piece_name(piece, sizeof piece, s, rank);
    snprintf(ppath, sizeof ppath, "%s/%s", dir, piece);
    sph_status st = manifest_read(mpath, rank, &m, &e);
    if (st == SPH_OK && m.ranks != ranks)
      st = sph_error_set(&e, SPH_ERR_IO,
                         "written by %d MPI ranks, this run has %d: resume "
                         "with mpirun -np %d",
                         m.ranks, ranks, m.ranks);
    else if (st == SPH_OK && !m.have_mine)
      st = sph_error_set(&e, SPH_ERR_IO, "names no piece of rank %d", rank);
    loaded l;
    if (st == SPH_OK && (st = load(ppath, &m, sim, v, &l, &e))) {
      char msg[sizeof e.message];
      snprintf(msg, sizeof msg, "%s", e.message);
      sph_error_set(&e, st, "%s: %.600s", piece, msg);
    }
    if (sph_domain_agree(d, st, &e) == SPH_OK) {
      snprintf(used, used_len, "%s", mpath);
      st = apply(sim, &l, v, next_output, err);
      return sph_domain_agree(d, st, err);
    }
    snprintf(why[s], sizeof why[s], "%.300s", e.message);
  }
  char serial[1100];
  snprintf(serial, sizeof serial, "%s/%s", dir, SPH_CHECKPOINT_FILE);
  struct stat sb;
  int serial_there = stat(serial, &sb) == 0;
  return sph_error_at(err, SPH_ERR_IO, dir, 0, 0, NULL,
                      "no valid checkpoint of %d MPI ranks to resume from "
                      "(checkpoint_a.sphm: %s; checkpoint_b.sphm: %s)%s",
                      ranks, why[0], why[1],
                      serial_there
                          ? "; the folder holds the checkpoint of a run "
                            "without MPI (" SPH_CHECKPOINT_FILE
                            "): resume it without mpirun"
                          : "; start the run again with --overwrite");
}

sph_status sph_checkpoint_resume(const char *dir, sph_sim *sim, sph_verdict *v,
                                 int *next_output, char *used, size_t used_len,
                                 sph_error *err) {
  if (sim->domain)
    return resume_distributed(dir, sim, v, next_output, used, used_len, err);
  static const char *const names[] = {SPH_CHECKPOINT_FILE,
                                      SPH_CHECKPOINT_PREVIOUS};
  char why[2][900];
  for (int i = 0; i < 2; ++i) {
    char path[1100];
    snprintf(path, sizeof path, "%s/%s", dir, names[i]);
    sph_error e;
    sph_error_clear(&e);
    loaded l;
    if (load(path, NULL, sim, v, &l, &e) == SPH_OK &&
        apply(sim, &l, v, next_output, &e) == SPH_OK) {
      snprintf(used, used_len, "%s", path);
      return SPH_OK;
    }
    snprintf(why[i], sizeof why[i], "%s: %.800s", names[i], e.message);
  }
  /* a checkpoint written over MPI ranks resumes only over as many */
  for (int s = 0; s < 2; ++s) {
    char mpath[1100];
    manifest m;
    manifest_path(mpath, sizeof mpath, dir, s);
    if (manifest_read(mpath, 0, &m, NULL) == SPH_OK)
      return sph_error_at(err, SPH_ERR_IO, dir, 0, 0, NULL,
                          "no checkpoint of a run without MPI to resume "
                          "from (%.200s; %.200s); the folder holds one of "
                          "%d MPI ranks (checkpoint_%c.sphm): resume with "
                          "mpirun -np %d",
                          why[0], why[1], m.ranks, slot_name[s], m.ranks);
  }
  /* stopped (or a full disk) before its first checkpoint: start again */
  char first[1100];
  struct stat sb;
  snprintf(first, sizeof first, "%s/%s", dir, SPH_CHECKPOINT_FILE);
  if (stat(first, &sb) != 0 && errno == ENOENT &&
      snprintf(first, sizeof first, "%s/%s", dir, SPH_CHECKPOINT_PREVIOUS) >
          0 &&
      stat(first, &sb) != 0 && errno == ENOENT)
    return sph_error_at(err, SPH_ERR_IO, dir, 0, 0, NULL,
                        "no checkpoint to resume from: the run stopped "
                        "before its first one; start it again with "
                        "--overwrite (or write elsewhere with --out DIR)");
  return sph_error_at(err, SPH_ERR_IO, dir, 0, 0, NULL,
                      "no valid checkpoint to resume from (%.300s; %.300s); "
                      "start the run again with --overwrite",
                      why[0], why[1]);
}
