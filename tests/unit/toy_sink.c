/* A toy sink for test_sink_registry: counts the frames it is handed and
 * keeps their times; it writes no file. Added to the registry by one
 * entry, SPH_SINK_LIST_EXTRA(X) = X(toy). */
#include "toy_sink.h"
#include "io/sink.h"

toy_record toy_seen;

static int toy_enabled(const sph_scene *scene) { return 1; }

static sph_status toy_open(sph_sink *sink, const sph_sim *sim, const char *dir,
                           sph_error *err) {
  toy_seen.opened++;
  sink->data = &toy_seen;
  return SPH_OK;
}

static sph_status toy_write(sph_sink *sink, const sph_frame *fr,
                            sph_error *err) {
  toy_record *r = sink->data;
  if (r->frames < TOY_MAX_FRAMES) {
    r->time[r->frames] = fr->time;
    r->index[r->frames] = fr->index;
  }
  r->frames++;
  return SPH_OK;
}

static sph_status toy_close(sph_sink *sink, sph_error *err) {
  toy_seen.closed++;
  return SPH_OK;
}

static void toy_destroy(sph_sink *sink) { sink->data = NULL; }

const sph_sink_ops sph_toy_sink_ops = {
    .name = "toy",
    .enabled = toy_enabled,
    .distributed = 0,
    .open = toy_open,
    .write = toy_write,
    .close = toy_close,
    .destroy = toy_destroy,
};
