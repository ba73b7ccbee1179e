/* The PNG frames' block of a scene (`output.png`), owned by the PNG sink:
 * what it holds once read, the reader the scene loader calls (keys,
 * defaults and checks with errors at file:line:col and key) and the
 * block's nodes the sink's pre-run check (sph_png_check) reports at.
 * Implemented in render/png_schema.c, part of the scene library. */
#ifndef SPH_PNG_SCHEMA_H
#define SPH_PNG_SCHEMA_H

/* Bytes a frame's pixel takes while drawn (the memory estimate, sim.c):
 * the GL colour (RGBA8) and depth (32F) renderbuffers, the read-back and
 * the image (RGBA8 each); over MPI ranks, the tag attachment (RGBA32UI), its
 * read-back and rank 0's composite (16 bytes each, render/gl.c, png_sink.c). */
#define SPH_PNG_BYTES_PER_PIXEL 16
#define SPH_PNG_TAG_BYTES_PER_PIXEL 48

#include "scene/node.h"
#include "sph/status.h"

typedef struct sph_camera {
  int given;
  double position[3], target[3], up[3];
  int has_position;
  double azimuth, elevation, zoom;
  int orthographic;
  int follow; /* refit to the current bodies (fitted cameras only) */
} sph_camera;

typedef struct sph_png_output {
  int enabled;
  int width, height;
  int color_field;     /* sph_field */
  char range_mode[16]; /* robust | auto | symmetric | fixed | global */
  char colormap[16];   /* cool-warm | viridis; empty: the field's own */
  double range[2];
  sph_camera camera;
  int mp4;    /* assemble <scene>.mp4 from the frames after the run */
  double fps; /* its frame rate */
  int clip;   /* draw only particles with clip_normal . x <= clip_at */
  double clip_normal[3], clip_at;
  int cut_half;  /* per body, only the half behind its reference centroid */
  int ghost;     /* the reference configuration drawn behind the frame */
  int axes;      /* the world axes triad in the bottom-left corner */
  int scale_bar; /* a length scale at the camera's target */
} sph_png_output;

/* Reads `png` of the output block `out` into p (p->enabled 0 without
 * frames: no block, or png: false), filling its defaults into the tree. */
sph_status sph_png_schema_parse(sph_png_output *p, sph_node *out,
                                sph_error *err);

/* The png block's child `key` of the scene tree `root` (or the block
 * itself when the key is absent, NULL without a block): where errors about
 * the frames point. */
const sph_node *sph_png_schema_node(const sph_node *root, const char *key);

/* SPH_ERR_RANGE with msg at node n, or without a location ("output.png: ")
 * when there is none. */
sph_status sph_png_schema_error(const sph_node *n, sph_error *err,
                                const char *msg);

#endif
