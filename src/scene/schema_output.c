/* The scene's `output:` block: interval, fields, VTK format, probes,
 * checkpoints and the PNG frames. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/schema_impl.h"

static sph_status field_list(sph_scene *s, sph_node *list, int *fields,
                             int *nfields, int max, int allow_ids,
                             sph_error *err) {
  *nfields = 0;
  for (size_t i = 0; i < list->count; ++i) {
    sph_node *it = list->items[i];
    if (it->kind != SPH_NODE_SCALAR)
      return sph_node_error(it, err, SPH_ERR_TYPE, "expected a field name");
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

static sph_status parse_png(sph_scene *s, sph_node *out, sph_error *err) {
  sph_node *png = sph_node_child(out, "png");
  /* png: false turns the frames off (sph study, --set output.png=false);
   * png: true is png: {} (frames with the defaults) */
  if (png && png->kind == SPH_NODE_SCALAR && !png->quoted) {
    int on;
    if (sph_node_as_bool(png, &on, err) != SPH_OK)
      return sph_node_error(png, err, SPH_ERR_TYPE,
                            "expected a mapping, true or false");
    png->used = 1;
    if (!on)
      return SPH_OK;
    free(png->value);
    png->value = NULL;
    png->kind = SPH_NODE_MAP;
  }
  SPH_TRY(sph_node_get_map(out, "png", 0, &png, err));
  sph_png_output *p = &s->output.png;
  if (!png)
    return SPH_OK;
  static const char *const keys[] = {
      "width", "height", "color", "range", "colormap", "camera",    "mp4",
      "fps",   "clip",   "cut",   "ghost", "axes",     "scale_bar", NULL};
  SPH_TRY(sph_node_check_keys(png, keys, err));
  p->enabled = 1;
  long w, h;
  SPH_TRY(sph_node_get_int(png, "width", 0, 1280, &w, err));
  SPH_TRY(sph_node_get_int(png, "height", 0, 720, &h, err));
  if (w < 16 || w > 16384)
    return sph_node_error(sph_node_child(png, "width"), err, SPH_ERR_RANGE,
                          "width must be in [16, 16384], got %ld", w);
  if (h < 16 || h > 16384)
    return sph_node_error(sph_node_child(png, "height"), err, SPH_ERR_RANGE,
                          "height must be in [16, 16384], got %ld", h);
  p->width = (int)w;
  p->height = (int)h;
  const char *color;
  SPH_TRY(sph_node_get_string(png, "color", 0, "pressure", &color, err));
  int f = sph_field_from_name(color);
  if (f < 0)
    return sph_node_error(sph_node_child(png, "color"), err, SPH_ERR_RANGE,
                          "unknown field '%s'", color);
  p->color_field = f;
  sph_node *range = sph_node_child(png, "range");
  snprintf(p->range_mode, sizeof p->range_mode, "robust");
  if (range && range->kind == SPH_NODE_SEQ) {
    range->used = 1;
    SPH_TRY(sph_node_get_doubles(png, "range", 1, 2, p->range, NULL, err));
    if (!(p->range[1] > p->range[0]))
      return sph_node_error(range, err, SPH_ERR_RANGE,
                            "range [min, max] needs min < max");
    snprintf(p->range_mode, sizeof p->range_mode, "fixed");
  } else {
    const char *mode;
    SPH_TRY(sph_node_get_string(png, "range", 0, "robust", &mode, err));
    if (strcmp(mode, "robust") && strcmp(mode, "auto") &&
        strcmp(mode, "symmetric") && strcmp(mode, "global"))
      return sph_node_error(sph_node_child(png, "range"), err, SPH_ERR_RANGE,
                            "range is robust, auto, symmetric, global or "
                            "[min, max], got '%s'",
                            mode);
    snprintf(p->range_mode, sizeof p->range_mode, "%s", mode);
  }
  const char *cmap;
  SPH_TRY(sph_node_get_string(png, "colormap", 0, "", &cmap, err));
  if (*cmap && strcmp(cmap, "cool-warm") && strcmp(cmap, "viridis"))
    return sph_node_error(sph_node_child(png, "colormap"), err, SPH_ERR_RANGE,
                          "colormap is cool-warm or viridis, got '%s'", cmap);
  snprintf(p->colormap, sizeof p->colormap, "%s", cmap);
  sph_node *cam;
  SPH_TRY(sph_node_get_map(png, "camera", 0, &cam, err));
  if (cam) {
    static const char *const ckeys[] = {"position",   "target",    "up",
                                        "azimuth",    "elevation", "zoom",
                                        "projection", "follow",    NULL};
    SPH_TRY(sph_node_check_keys(cam, ckeys, err));
    sph_camera *c = &p->camera;
    c->given = 1;
    c->up[1] = 1.0;
    c->zoom = 1.0;
    if (sph_node_child(cam, "position")) {
      c->has_position = 1;
      SPH_TRY(
          sph_node_get_doubles(cam, "position", 1, 3, c->position, NULL, err));
    }
    if (sph_node_child(cam, "target"))
      SPH_TRY(sph_node_get_doubles(cam, "target", 1, 3, c->target, NULL, err));
    if (sph_node_child(cam, "up"))
      SPH_TRY(sph_node_get_doubles(cam, "up", 1, 3, c->up, NULL, err));
    SPH_TRY(sph_node_get_double(cam, "azimuth", 0, 0.0, &c->azimuth, err));
    SPH_TRY(sph_node_get_double(cam, "elevation", 0, 0.0, &c->elevation, err));
    SPH_TRY(sph_node_get_positive(cam, "zoom", 0, 1.0, &c->zoom, err));
    const char *proj;
    SPH_TRY(
        sph_node_get_string(cam, "projection", 0, "orthographic", &proj, err));
    if (strcmp(proj, "orthographic") && strcmp(proj, "perspective"))
      return sph_node_error(sph_node_child(cam, "projection"), err,
                            SPH_ERR_RANGE,
                            "projection is orthographic or perspective");
    c->orthographic = !strcmp(proj, "orthographic");
    SPH_TRY(sph_node_get_bool(cam, "follow", 0, 1, &c->follow, err));
  } else {
    p->camera.follow = 1;
  }
  /* the animation, the cutaway and the reference outline */
  SPH_TRY(sph_node_get_bool(png, "mp4", 0, 1, &p->mp4, err));
  SPH_TRY(sph_node_get_positive(png, "fps", 0, 30.0, &p->fps, err));
  if (p->fps > 240.0)
    return sph_node_error(sph_node_child(png, "fps"), err, SPH_ERR_RANGE,
                          "fps must be in (0, 240], got %g", p->fps);
  sph_node *clip;
  SPH_TRY(sph_node_get_map(png, "clip", 0, &clip, err));
  if (clip) {
    static const char *const pkeys[] = {"normal", "at", NULL};
    SPH_TRY(sph_node_check_keys(clip, pkeys, err));
    SPH_TRY(
        sph_node_get_doubles(clip, "normal", 1, 3, p->clip_normal, NULL, err));
    SPH_TRY(sph_node_get_double(clip, "at", 1, 0.0, &p->clip_at, err));
    double nn = 0.0;
    for (int k = 0; k < 3; ++k)
      nn += p->clip_normal[k] * p->clip_normal[k];
    if (!(nn > 0.0) || !isfinite(nn))
      return sph_node_error(sph_node_child(clip, "normal"), err, SPH_ERR_RANGE,
                            "the clip normal must be a non-zero vector");
    p->clip = 1;
  }
  const char *cut;
  SPH_TRY(sph_node_get_string(png, "cut", 0, "none", &cut, err));
  if (strcmp(cut, "none") && strcmp(cut, "half"))
    return sph_node_error(sph_node_child(png, "cut"), err, SPH_ERR_RANGE,
                          "cut is none or half, got '%s'", cut);
  p->cut_half = !strcmp(cut, "half");
  SPH_TRY(sph_node_get_bool(png, "ghost", 0, 0, &p->ghost, err));
  SPH_TRY(sph_node_get_bool(png, "axes", 0, 0, &p->axes, err));
  SPH_TRY(sph_node_get_bool(png, "scale_bar", 0, 0, &p->scale_bar, err));
  return SPH_OK;
}

sph_status sph_schema_output(sph_scene *s, sph_node *root, sph_error *err) {
  sph_node *out;
  SPH_TRY(sph_node_insert_default(root, "output", "{}", &out, err));
  if (out->kind != SPH_NODE_MAP)
    return sph_node_error(out, err, SPH_ERR_TYPE, "expected a mapping");
  static const char *const keys[] = {"every",  "fields",           "vtk", "png",
                                     "probes", "checkpoint_every", NULL};
  SPH_TRY(sph_node_check_keys(out, keys, err));
  sph_output *o = &s->output;
  SPH_TRY(
      sph_node_get_positive(out, "every", 0, s->t_end / 100.0, &o->every, err));
  if (o->every > s->t_end * (1 + 1e-12))
    return sph_node_error(sph_node_child(out, "every"), err, SPH_ERR_RANGE,
                          "output interval %g is longer than the run (%g)",
                          o->every, s->t_end);
  /* frame numbers have four digits (<scene>_NNNN.vtp, .png) */
  double frames = ceil(s->t_end / o->every * (1.0 - 1e-12)) + 1.0;
  if (frames > 10000.0)
    return sph_node_error(sph_node_child(out, "every"), err, SPH_ERR_RANGE,
                          "%.0f output frames (end %g s every %g s); at "
                          "most 10000: a longer interval, or a shorter run",
                          frames, s->t_end, o->every);
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
  SPH_TRY(parse_png(s, out, err));
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
