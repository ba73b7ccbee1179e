/* Off-screen OpenGL sphere renderer (OSMesa, GL 3.3 core): the camera, its
 * matrices and fitting (view.c) and the impostor-sphere pass (gl.c).
 *
 * Conventions. World space is right-handed with +Y up. A frame is RGBA8, top
 * row first, tightly packed (width * 4 bytes per row); every pixel has alpha
 * 255. Pixel coordinates returned by sph_view_project run from the left and
 * top edges of the frame (pixel (i, j) covers [i, i+1) x [j, j+1)).
 *
 * Determinism. The same inputs give the same bytes run to run on one
 * machine: all GL state is set on every draw, spheres are drawn in index
 * order with a strict depth test (the earlier sphere wins an exact depth
 * tie), there is no multisampling, blending or dithering, and sph_gl_create
 * selects Mesa's llvmpipe rasteriser by setting GALLIUM_DRIVER=llvmpipe in
 * the process environment when the variable is unset (setenv without
 * overwrite; softpipe also works, swrast is refused because it crashes in
 * OSMesa on Mesa 22). The number of llvmpipe threads (LP_NUM_THREADS) does
 * not change the bytes. */
#ifndef SPH_RENDER_GL_IMPL_H
#define SPH_RENDER_GL_IMPL_H

#include <stddef.h>

#include "parallel/composite.h"
#include "render/image.h"
#include "sph/status.h"

/* Background grey of every frame, 0-255 per channel (alpha is 255). */
#define SPH_GL_BACKGROUND 237

/* Camera: eye looking at target with the given up direction (need not be
 * orthogonal to the view direction, must not be parallel to it). */
typedef struct sph_view {
  double eye[3], target[3], up[3];
  double fovy_deg;     /* perspective vertical field of view; unused if ortho */
  int ortho;           /* 1 = orthographic projection */
  double ortho_height; /* world units visible vertically when ortho */
  double near_clip, far_clip; /* distances along the view direction */
} sph_view;

/* Camera that frames the axis-aligned box [lo, hi] with a 5 % margin in a
 * width x height frame, looking at the box centre.
 *
 * Direction convention: at azimuth 0 and elevation 0 the camera sits on the
 * +Z side of the box looking along -Z, with +X to the right and +Y up.
 * Azimuth (degrees) turns the camera about +Y by the right-hand rule
 * (azimuth 90 puts it on the +X side looking along -X); elevation (degrees)
 * raises it above the XZ plane so it looks down (90 = straight down, with
 * the screen's up direction continuing the tilt, i.e. -Z at azimuth 0).
 *
 * zoom > 1 magnifies about the box centre (narrower field of view or
 * smaller ortho height, the camera does not move); zoom <= 0 counts as 1.
 * Perspective uses a 30 degree vertical field of view (before zoom); the
 * distance is the smallest that keeps all 8 corners inside the frame.
 * dim == 2 gives an orthographic plane view along -Z (+X right, +Y up),
 * ignoring azimuth, elevation and the ortho flag. */
void sph_view_fit(const double lo[3], const double hi[3], double azimuth,
                  double elevation, double zoom, int ortho, int dim, int width,
                  int height, sph_view *out);

/* SPH_OK when the camera is usable: finite values, eye != target, up not
 * parallel to the view direction, 0 < fovy < 180 (perspective), ortho_height
 * > 0 (ortho), 0 < near < far (perspective) or near < far (ortho). */
sph_status sph_view_check(const sph_view *view, sph_error *err);

/* Column-major 4x4 matrices (OpenGL layout): world -> eye (right-handed,
 * looking along -Z) and eye -> clip for an aspect ratio width / height. */
void sph_view_matrix(const sph_view *view, double m[16]);
void sph_view_projection(const sph_view *view, double aspect, double m[16]);

/* Projects world point p into a width x height frame: out[0], out[1] are
 * pixel coordinates from the left and top edges, out[2] the window depth in
 * [0, 1] inside the clip range. Returns 0 when p is not in front of the
 * camera (clip w <= 0), 1 otherwise. */
int sph_view_project(const sph_view *view, int width, int height,
                     const double p[3], double out[3]);

typedef struct sph_gl sph_gl;

/* Creates the OSMesa GL 3.3 core context, an off-screen width x height
 * framebuffer (RGBA8 colour, 32-bit float depth) and the sphere program.
 * SPH_ERR_UNSUPPORTED when OSMesa cannot give a 3.3 core context or the
 * shaders do not build (the compile/link log is in the message);
 * SPH_ERR_RANGE when the size exceeds the driver's limits. The context is
 * made current on the calling thread; use one sph_gl per thread and keep
 * it for many frames (Mesa keeps about 200 bytes per context it ever made
 * current). The first call may set GALLIUM_DRIVER (setenv), so make it
 * before other threads read the environment. */
sph_status sph_gl_create(int width, int height, sph_gl **out, sph_error *err);

/* Draws n spheres of common radius (world units) into img and returns the
 * frame there. xyz holds 3n floats (x, y, z of each centre), rgb 3n bytes
 * (the sphere colours). clip_plane, when not NULL, holds a, b, c, d: only
 * spheres whose centre satisfies a x + b y + c z + d >= 0 are drawn, each
 * whole (a cutaway that shows complete particles on the cut). img must be
 * width x height of the context with img->rgba holding width * height * 4
 * bytes (the caller owns it). GPU buffers are kept and grown between calls.
 * Spheres crossing the near or far plane are cut there (possibly whole:
 * no inside surface is shown); a sphere that contains the eye is not drawn.
 * n = 0 gives the background. SPH_ERR_NUMERIC for a non-finite centre,
 * SPH_ERR_ARG for a bad camera, radius or image. */
sph_status sph_gl_draw_spheres(sph_gl *gl, const sph_view *view, size_t n,
                               const float *xyz, float radius,
                               const unsigned char *rgb,
                               const double *clip_plane, sph_image *img,
                               sph_error *err);

/* One set of spheres of a frame, as the arguments of sph_gl_draw_spheres. */
typedef struct sph_gl_layer {
  size_t n;
  const float *xyz;
  float radius;
  const unsigned char *rgb;
  const double *clip_plane; /* NULL: no clip */
  int flat;                 /* 1: the colour unshaded (a flat silhouette) */
  const float *scale;       /* per sphere factor on radius, or NULL (1) */
  const uint32_t *key;      /* tagged draws: each sphere's serial draw index */
} sph_gl_layer;

/* Draws nlayers layers into one frame, in order: each layer is depth-tested
 * only against itself and painted over the ones before it, so an earlier
 * layer shows only where the later ones leave background (a reference
 * outline behind the current state). The same checks and errors as
 * sph_gl_draw_spheres, which is this call with one layer; nlayers = 0 gives
 * the background. */
sph_status sph_gl_draw_layers(sph_gl *gl, const sph_view *view,
                              const sph_gl_layer *layers, int nlayers,
                              sph_image *img, sph_error *err);

/* sph_gl_draw_layers for a frame composited over ranks (sph/composite.h):
 * *px points to the context's width * height pixels (top row first, valid
 * until the next draw) holding the colour, layer (i + 1, 0 for the
 * background), window depth bits and key of the fragment that won each
 * pixel, the layers' spheres drawn in the order given (ascending keys give
 * the serial winner at a depth tie). Every layer with spheres needs keys. */
sph_status sph_gl_draw_tagged(sph_gl *gl, const sph_view *view,
                              const sph_gl_layer *layers, int nlayers,
                              const sph_composite_px **px, sph_error *err);

/* Releases the context and its buffers. Accepts NULL. */
void sph_gl_destroy(sph_gl *gl);

#endif
