/* The scene's `output:` block: interval, fields, VTK format, probes,
 * checkpoints; the PNG frames' block is the PNG sink's own
 * (render/png_schema.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/png_schema.h"
#include "scene/schema_impl.h"

static sph_status field_list(sph_scene *s, sph_node *list, int *fields,
                             int *nfields, int max, int allow_ids,
                             sph_error *err) {
  *nfields = 0;
  for (size_t i = 0; i < list->count; ++i) {
    sph_node *it = list->items[i];
    if (it->kind != SPH_NODE_SCALAR)
      return sph_node_error(it, err, SPH_ERR_TYPE, "expected a field name");
    for (size_t j = 0; j < i; ++j) /* a field written twice: refused */
      if (list->items[j]->kind == SPH_NODE_SCALAR &&
          !strcmp(list->items[j]->value, it->value))
        return sph_node_error(it, err, SPH_ERR_RANGE,
                              "field '%s' is listed twice (first at %d:%d)",
                              it->value, list->items[j]->line,
                              list->items[j]->col);
    if (allow_ids && !strcmp(it->value, "body_id")) {
      s->output.body_id = 1;
      continue;
    }
    if (allow_ids && !strcmp(it->value, "particle_id")) {
      s->output.particle_id = 1;
      continue;
    }
    int f = sph_field_from_name(it->value);
    if (f < 0) {
      const char *names[SPH_FIELD_COUNT + 3];
      int k = 0;
      for (int j = 0; j < SPH_FIELD_COUNT; ++j)
        names[k++] = sph_field_name((sph_field)j);
      if (allow_ids) {
        names[k++] = "body_id";
        names[k++] = "particle_id";
      }
      names[k] = NULL;
      const char *hint = sph_suggest(it->value, names);
      return sph_node_error(it, err, SPH_ERR_RANGE, "unknown field '%s'%s%s%s",
                            it->value, hint ? "; did you mean '" : "",
                            hint ? hint : "", hint ? "'?" : "");
    }
    if (*nfields >= max)
      return sph_node_error(it, err, SPH_ERR_RANGE, "at most %d fields", max);
    fields[(*nfields)++] = f;
  }
  return SPH_OK;
}

/* The node an error of the output interval against the run's end belongs
 * to: time.end when only it was given on the command line (--set), else
 * output.every */
static sph_node *every_node(sph_node *root, sph_node *out) {
  sph_node *every = sph_node_child(out, "every");
  sph_node *time = sph_node_child(root, "time");
  sph_node *end = time ? sph_node_child(time, "end") : NULL;
  int end_set = end && end->file && !strcmp(end->file, "<command line>");
  int every_set =
      every && every->file && !strcmp(every->file, "<command line>");
  return end_set && !every_set ? end : every;
}

sph_status sph_schema_output(sph_scene *s, sph_node *root, sph_error *err) {
  sph_node *out;
  SPH_TRY(sph_node_insert_default(root, "output", "{}", &out, err));
  if (out->kind != SPH_NODE_MAP)
    return sph_node_error(out, err, SPH_ERR_TYPE, "expected a mapping");
  static const char *const keys[] = {"every",    "fields", "vtk",
                                     "png",      "probes", "checkpoint_every",
                                     "at_steps", NULL};
  SPH_TRY(sph_node_check_keys(out, keys, err));
  sph_output *o = &s->output;
  SPH_TRY(
      sph_node_get_positive(out, "every", 0, s->t_end / 100.0, &o->every, err));
  if (o->every > s->t_end * (1 + 1e-12))
    return sph_node_error(every_node(root, out), err, SPH_ERR_RANGE,
                          "output interval %g is longer than the run (%g)",
                          o->every, s->t_end);
  /* frame numbers have four digits (<scene>_NNNN.vtp, .png) */
  double frames = ceil(s->t_end / o->every * (1.0 - 1e-12)) + 1.0;
  if (frames > 10000.0) {
    char count[40]; /* no 300-digit counts */
    if (frames < 1e15)
      snprintf(count, sizeof count, "%.0f", frames);
    else
      snprintf(count, sizeof count, "%.3g", frames);
    return sph_node_error(every_node(root, out), err, SPH_ERR_RANGE,
                          "%s output frames (end %g s every %g s); at "
                          "most 10000: a longer interval, or a shorter run",
                          count, s->t_end, o->every);
  }
  sph_node *fields;
  SPH_TRY(sph_node_insert_default(
      out, "fields",
      "[pressure, velocity, displacement, von_mises, J, body_id]", &fields,
      err));
  if (fields->kind != SPH_NODE_SEQ)
    return sph_node_error(fields, err, SPH_ERR_TYPE,
                          "expected a list of field names");
  SPH_TRY(
      field_list(s, fields, o->fields, &o->nfields, SPH_FIELD_COUNT, 1, err));
  sph_node *vtk = sph_node_child(out, "vtk");
  o->vtk = 1;
  if (vtk && vtk->kind == SPH_NODE_MAP) {
    vtk->used = 1;
    static const char *const vkeys[] = {"format", "compress", NULL};
    SPH_TRY(sph_node_check_keys(vtk, vkeys, err));
    const char *fmt, *zip;
    SPH_TRY(sph_node_get_string(vtk, "format", 0, "binary", &fmt, err));
    if (strcmp(fmt, "binary") && strcmp(fmt, "ascii"))
      return sph_node_error(sph_node_child(vtk, "format"), err, SPH_ERR_RANGE,
                            "format is binary or ascii, got '%s'", fmt);
    o->vtk_ascii = !strcmp(fmt, "ascii");
    SPH_TRY(sph_node_get_string(vtk, "compress", 0, "none", &zip, err));
    if (strcmp(zip, "none") && strcmp(zip, "zlib"))
      return sph_node_error(sph_node_child(vtk, "compress"), err, SPH_ERR_RANGE,
                            "compress is none or zlib, got '%s'", zip);
    o->vtk_zlib = !strcmp(zip, "zlib");
    if (o->vtk_zlib && o->vtk_ascii)
      return sph_node_error(sph_node_child(vtk, "compress"), err, SPH_ERR_ARG,
                            "compress: zlib applies to the binary format");
  } else {
    SPH_TRY(sph_node_get_bool(out, "vtk", 0, 1, &o->vtk, err));
  }
  SPH_TRY(sph_png_schema_parse(&s->output.png, out, err));
  if (sph_node_child(out, "at_steps")) /* no default: scene_used as given */
    SPH_TRY(sph_node_get_bool(out, "at_steps", 1, 0, &o->at_steps, err));
  if (sph_node_child(out, "checkpoint_every"))
    SPH_TRY(sph_node_get_positive(out, "checkpoint_every", 1, 0,
                                  &o->checkpoint_every, err));
  sph_node *probes;
  SPH_TRY(sph_schema_get_seq(out, "probes", 0, &probes, err));
  if (probes && probes->count) {
    o->probes = calloc(probes->count, sizeof *o->probes);
    if (!o->probes)
      return sph_error_set(err, SPH_ERR_NOMEM, "probes");
    static const char *const pkeys[] = {"name", "at", "fields", NULL};
    for (size_t i = 0; i < probes->count; ++i) {
      sph_node *n = probes->items[i];
      sph_probe *p = &o->probes[i];
      o->nprobes++;
      if (n->kind != SPH_NODE_MAP)
        return sph_node_error(n, err, SPH_ERR_TYPE,
                              "expected a probe (a mapping)");
      SPH_TRY(sph_node_check_keys(n, pkeys, err));
      const char *name;
      SPH_TRY(sph_node_get_string(n, "name", 1, NULL, &name, err));
      sph_schema_copy_name(p->name, name);
      if (!name[0])
        return sph_node_error(sph_node_child(n, "name"), err, SPH_ERR_RANGE,
                              "a probe needs a name");
      for (size_t j = 0; j < i; ++j)
        if (!strcmp(o->probes[j].name, p->name))
          return sph_node_error(sph_node_child(n, "name"), err, SPH_ERR_ARG,
                                "two probes are named '%s' (their columns in "
                                "probes.csv would clash)",
                                name);
      SPH_TRY(sph_node_get_doubles(n, "at", 1, (size_t)s->dimension, p->at,
                                   NULL, err));
      sph_node *at = sph_node_child(n, "at");
      p->line = at->line;
      p->col = at->col;
      sph_node *pf;
      SPH_TRY(sph_node_insert_default(n, "fields", "[displacement, velocity]",
                                      &pf, err));
      if (pf->kind != SPH_NODE_SEQ)
        return sph_node_error(pf, err, SPH_ERR_TYPE,
                              "expected a list of field names");
      SPH_TRY(field_list(s, pf, p->fields, &p->nfields, 8, 0, err));
    }
  }
  return SPH_OK;
}
