/* The PNG frames' block of a scene (`output.png`), owned by the PNG sink
 * (render/png_sink.c): its keys, defaults and checks, read into
 * sph_png_output when the scene loads (the scene library calls
 * sph_png_schema_parse), and the block's nodes that the sink's pre-run
 * check (sph_png_check) points its errors at. */
#include "render/png_schema.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/particles.h"

/* png: false turns the frames off (sph study, --set output.png=false);
 * png: true is png: {} (frames with the defaults); *out_png the block, NULL
 * without frames */
static sph_status png_block(sph_node *out, sph_node **out_png, sph_error *err) {
  sph_node *png = sph_node_child(out, "png");
  *out_png = NULL;
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
  return sph_node_get_map(out, "png", 0, out_png, err);
}

/* size, colour field, range and colour map */
static sph_status png_picture(sph_png_output *p, sph_node *png,
                              sph_error *err) {
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
  return SPH_OK;
}

static sph_status png_camera(sph_png_output *p, sph_node *png, sph_error *err) {
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
  return SPH_OK;
}

/* the animation, the cutaway and the reference outline */
static sph_status png_cutaway(sph_png_output *p, sph_node *png,
                              sph_error *err) {
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

sph_status sph_png_schema_parse(sph_png_output *p, sph_node *out,
                                sph_error *err) {
  sph_node *png;
  SPH_TRY(png_block(out, &png, err));
  if (!png)
    return SPH_OK;
  static const char *const keys[] = {
      "width", "height", "color", "range", "colormap", "camera",    "mp4",
      "fps",   "clip",   "cut",   "ghost", "axes",     "scale_bar", NULL};
  SPH_TRY(sph_node_check_keys(png, keys, err));
  p->enabled = 1;
  SPH_TRY(png_picture(p, png, err));
  SPH_TRY(png_camera(p, png, err));
  return png_cutaway(p, png, err);
}

const sph_node *sph_png_schema_node(const sph_node *root, const char *key) {
  const sph_node *n = root ? sph_node_child(root, "output") : NULL;
  n = n ? sph_node_child(n, "png") : NULL;
  const sph_node *k = n && key ? sph_node_child(n, key) : NULL;
  return k ? k : n;
}

sph_status sph_png_schema_error(const sph_node *n, sph_error *err,
                                const char *msg) {
  if (n)
    return sph_node_error(n, err, SPH_ERR_RANGE, "%s", msg);
  return sph_error_set(err, SPH_ERR_RANGE, "output.png: %s", msg);
}
