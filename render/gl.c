/* OSMesa sphere pass: a GL 3.3 core context with an off-screen framebuffer
 * draws each particle as an instanced camera-facing quad whose fragment
 * shader ray-casts the sphere (exact silhouette, normal and depth) and
 * shades it with a head-light (or not: flat silhouettes); layers of spheres
 * are painted in order over one another; the frame is read back top row
 * first. */
#define GL_GLEXT_PROTOTYPES 1
#include "gl_impl.h"

#include <GL/osmesa.h>
/* osmesa.h includes GL/gl.h */
#include <GL/glext.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Vertex stage: one instance per sphere, the unit quad corner expanded in
 * eye space around the centre. Perspective quads face the eye and have the
 * half size of the tangent cone's circle in the plane of the centre, so the
 * silhouette is inscribed exactly; ortho quads are 2r x 2r squares. */
static const char *const vertex_src =
    "layout(location = 0) in vec2 corner;\n"
    "layout(location = 1) in vec3 centre;\n"
    "layout(location = 2) in vec3 colour;\n"
    "layout(location = 3) in float scale;\n"
    "uniform mat4 view;\n"
    "uniform mat4 proj;\n"
    "uniform float radius;\n"
    "uniform int ortho;\n"
    "uniform int use_clip;\n"
    "uniform vec4 clip_plane;\n"
    "out vec3 v_colour;\n"
    "flat out vec3 v_centre;\n"
    "flat out float v_radius;\n"
    "out vec3 v_pos;\n"
    "out vec2 v_quad;\n"
    "out float gl_ClipDistance[1];\n"
    "#ifdef TAGGED\n"
    "layout(location = 4) in uint key;\n"
    "flat out uint v_key;\n"
    "#endif\n"
    "void main() {\n"
    "#ifdef TAGGED\n"
    "  v_key = key;\n"
    "#endif\n"
    "  vec3 c = (view * vec4(centre, 1.0)).xyz;\n"
    "  float r = radius * scale;\n"
    "  v_radius = r;\n"
    "  v_colour = colour;\n"
    "  v_centre = c;\n"
    "  v_quad = corner;\n"
    "  gl_ClipDistance[0] =\n"
    "      use_clip != 0 ? dot(clip_plane.xyz, centre) + clip_plane.w : 1.0;\n"
    "  if (ortho != 0) {\n"
    "    v_pos = c + vec3(r * corner, 0.0);\n"
    "  } else {\n"
    "    float d2 = dot(c, c), r2 = r * r;\n"
    "    if (d2 <= r2) {\n"
    "      v_pos = c;\n"
    "      gl_Position = vec4(0.0, 0.0, 2.0, 1.0);\n"
    "      return;\n"
    "    }\n"
    "    vec3 axis = c * inversesqrt(d2);\n"
    "    vec3 ref = abs(axis.y) < 0.9 ? vec3(0.0, 1.0, 0.0)\n"
    "                                 : vec3(1.0, 0.0, 0.0);\n"
    "    vec3 s = normalize(cross(ref, axis));\n"
    "    vec3 t = cross(axis, s);\n"
    "    float h = r * sqrt(d2 / (d2 - r2));\n"
    "    v_pos = c + h * (corner.x * s + corner.y * t);\n"
    "  }\n"
    "  gl_Position = proj * vec4(v_pos, 1.0);\n"
    "}\n";

/* Fragment stage: the front hit of the eye ray with the sphere (ortho: the
 * disc point lifted onto the hemisphere), its window depth, and ambient +
 * Lambert + Blinn-Phong shading under a light fixed to the camera. */
static const char *const fragment_src =
    "in vec3 v_colour;\n"
    "flat in vec3 v_centre;\n"
    "flat in float v_radius;\n"
    "in vec3 v_pos;\n"
    "in vec2 v_quad;\n"
    "uniform mat4 proj;\n"
    "uniform int ortho;\n"
    "uniform int flat_colour;\n"
    "out vec4 frag;\n"
    "#ifdef TAGGED\n"
    "flat in uint v_key;\n"
    "uniform uint layer;\n"
    "out uvec4 tag;\n"
    "#endif\n"
    "void main() {\n"
    "  vec3 light = normalize(vec3(-0.3, 0.4, 1.0));\n"
    "  vec3 n, p, to_eye;\n"
    "  if (ortho != 0) {\n"
    "    float q2 = dot(v_quad, v_quad);\n"
    "    if (q2 > 1.0) discard;\n"
    "    n = vec3(v_quad, sqrt(1.0 - q2));\n"
    "    p = v_centre + v_radius * n;\n"
    "    to_eye = vec3(0.0, 0.0, 1.0);\n"
    "  } else {\n"
    "    vec3 dir = normalize(v_pos);\n"
    "    float b = dot(v_centre, dir);\n"
    "    vec3 off = v_centre - b * dir;\n"
    "    float disc = v_radius * v_radius - dot(off, off);\n"
    "    if (disc < 0.0) discard;\n"
    "    p = (b - sqrt(disc)) * dir;\n"
    "    n = normalize(p - v_centre);\n"
    "    to_eye = -dir;\n"
    "  }\n"
    "  vec4 clip = proj * vec4(p, 1.0);\n"
    "  float depth = 0.5 * clip.z / clip.w + 0.5;\n"
    "  if (depth < 0.0 || depth > 1.0) discard;\n"
    "  gl_FragDepth = depth;\n"
    "#ifdef TAGGED\n"
    "  tag = uvec4(layer, floatBitsToUint(depth), v_key, 0u);\n"
    "#endif\n"
    "  if (flat_colour != 0) {\n"
    "    frag = vec4(v_colour, 1.0);\n"
    "    return;\n"
    "  }\n"
    "  float lambert = max(dot(n, light), 0.0);\n"
    "  vec3 half_vec = normalize(light + to_eye);\n"
    "  float spec = pow(max(dot(n, half_vec), 0.0), 48.0);\n"
    "  vec3 rgb = v_colour * (0.22 + 0.78 * lambert) + vec3(0.25 * spec);\n"
    "  frag = vec4(min(rgb, vec3(1.0)), 1.0);\n"
    "}\n";

/* A sphere program and its uniforms. */
typedef struct gl_program {
  GLuint id;
  GLint view, proj, radius, ortho, use_clip, plane, flat, layer;
} gl_program;

struct sph_gl {
  OSMesaContext ctx;
  unsigned char front[4]; /* 1x1 window buffer OSMesa needs; unused */
  int width, height;
  gl_program prog; /* the frame's colours */
  gl_program tag;  /* the same with the tag output (made on first use) */
  GLuint vao, quad_vbo, centre_vbo, colour_vbo, scale_vbo, key_vbo;
  GLuint fbo, colour_rb, depth_rb, tag_fbo, tag_rb;
  size_t capacity;         /* instances the centre/colour buffers hold */
  unsigned char *readback; /* width * height * 4, bottom row first */
  sph_composite_px *px;    /* tagged frames: width * height, then 2 rows */
};

/* Makes the context current on this thread. */
static sph_status make_current(sph_gl *gl, sph_error *err) {
  if (!OSMesaMakeCurrent(gl->ctx, gl->front, GL_UNSIGNED_BYTE, 1, 1))
    return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                         "OSMesa: cannot make the context current");
  return SPH_OK;
}

/* Maps the pending GL error, if any, to a status. */
static sph_status gl_check(const char *what, sph_error *err) {
  GLenum e = glGetError(), first = e;
  while (e != GL_NO_ERROR)
    e = glGetError();
  if (first == GL_NO_ERROR)
    return SPH_OK;
  if (first == GL_OUT_OF_MEMORY)
    return sph_error_set(err, SPH_ERR_NOMEM, "OpenGL: out of memory (%s)",
                         what);
  return sph_error_set(err, SPH_ERR_IO, "OpenGL error 0x%04x (%s)",
                       (unsigned)first, what);
}

/* Compiles one shader stage (tagged: with TAGGED defined); the info log
 * goes into the error on failure. */
static sph_status compile(GLenum type, const char *src, int tagged, GLuint *out,
                          sph_error *err) {
  GLuint sh = glCreateShader(type);
  GLint ok = 0;
  const char *parts[3] = {"#version 330 core\n",
                          tagged ? "#define TAGGED 1\n" : "", src};
  glShaderSource(sh, 3, parts, NULL);
  glCompileShader(sh);
  glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[512] = "";
    glGetShaderInfoLog(sh, sizeof log, NULL, log);
    glDeleteShader(sh);
    return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                         "OpenGL: %s shader does not compile: %s",
                         type == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
  }
  *out = sh;
  return SPH_OK;
}

/* Builds the sphere program (tagged: with the tag output on draw buffer
 * 1) and looks up its uniforms. */
static sph_status build_program(gl_program *pr, int tagged, sph_error *err) {
  GLuint vs = 0, fs = 0;
  GLint ok = 0;
  SPH_TRY(compile(GL_VERTEX_SHADER, vertex_src, tagged, &vs, err));
  sph_status st = compile(GL_FRAGMENT_SHADER, fragment_src, tagged, &fs, err);
  if (st != SPH_OK) {
    glDeleteShader(vs);
    return st;
  }
  /* link, then the shader objects are no longer needed */
  pr->id = glCreateProgram();
  glAttachShader(pr->id, vs);
  glAttachShader(pr->id, fs);
  if (tagged) {
    glBindFragDataLocation(pr->id, 0, "frag");
    glBindFragDataLocation(pr->id, 1, "tag");
  }
  glLinkProgram(pr->id);
  glDetachShader(pr->id, vs);
  glDetachShader(pr->id, fs);
  glDeleteShader(vs);
  glDeleteShader(fs);
  glGetProgramiv(pr->id, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[512] = "";
    glGetProgramInfoLog(pr->id, sizeof log, NULL, log);
    return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                         "OpenGL: sphere program does not link: %s", log);
  }
  pr->view = glGetUniformLocation(pr->id, "view");
  pr->proj = glGetUniformLocation(pr->id, "proj");
  pr->radius = glGetUniformLocation(pr->id, "radius");
  pr->ortho = glGetUniformLocation(pr->id, "ortho");
  pr->use_clip = glGetUniformLocation(pr->id, "use_clip");
  pr->plane = glGetUniformLocation(pr->id, "clip_plane");
  pr->flat = glGetUniformLocation(pr->id, "flat_colour");
  pr->layer = glGetUniformLocation(pr->id, "layer");
  return SPH_OK;
}

/* Vertex array: the static unit quad and the per-instance attributes. */
static void build_vertex_array(sph_gl *gl) {
  static const float quad[8] = {-1.f, -1.f, 1.f, -1.f, -1.f, 1.f, 1.f, 1.f};
  glGenVertexArrays(1, &gl->vao);
  glBindVertexArray(gl->vao);
  glGenBuffers(1, &gl->quad_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, gl->quad_vbo);
  glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, NULL);
  /* centres: 3 floats per instance */
  glGenBuffers(1, &gl->centre_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, gl->centre_vbo);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, NULL);
  glVertexAttribDivisor(1, 1);
  /* colours: 3 normalised bytes per instance */
  glGenBuffers(1, &gl->colour_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, gl->colour_vbo);
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 3, GL_UNSIGNED_BYTE, GL_TRUE, 0, NULL);
  glVertexAttribDivisor(2, 1);
  /* radius factors: 1 float per instance (a layer without them: 1) */
  glGenBuffers(1, &gl->scale_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, gl->scale_vbo);
  glVertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, 0, NULL);
  glVertexAttribDivisor(3, 1);
  glVertexAttrib1f(3, 1.0f);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

/* Whether the bound framebuffer is complete. */
static sph_status complete(const char *which, sph_error *err) {
  GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                         "OpenGL: %s framebuffer incomplete (0x%04x)", which,
                         (unsigned)status);
  return SPH_OK;
}

/* Off-screen framebuffer: RGBA8 colour and 32-bit float depth. */
static sph_status build_framebuffer(sph_gl *gl, sph_error *err) {
  glGenRenderbuffers(1, &gl->colour_rb);
  glBindRenderbuffer(GL_RENDERBUFFER, gl->colour_rb);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, gl->width, gl->height);
  glGenRenderbuffers(1, &gl->depth_rb);
  glBindRenderbuffer(GL_RENDERBUFFER, gl->depth_rb);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, gl->width,
                        gl->height);
  glGenFramebuffers(1, &gl->fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, gl->fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                            GL_RENDERBUFFER, gl->colour_rb);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT,
                            GL_RENDERBUFFER, gl->depth_rb);
  SPH_TRY(gl_check("framebuffer storage", err));
  return complete("off-screen", err);
}

sph_status sph_gl_create(int width, int height, sph_gl **out, sph_error *err) {
  static const int attribs[] = {OSMESA_FORMAT,
                                OSMESA_RGBA,
                                OSMESA_DEPTH_BITS,
                                0,
                                OSMESA_STENCIL_BITS,
                                0,
                                OSMESA_PROFILE,
                                OSMESA_CORE_PROFILE,
                                OSMESA_CONTEXT_MAJOR_VERSION,
                                3,
                                OSMESA_CONTEXT_MINOR_VERSION,
                                3,
                                0};
  if (!out)
    return sph_error_set(err, SPH_ERR_ARG, "render: no output pointer");
  *out = NULL;
  if (width < 1 || height < 1)
    return sph_error_set(err, SPH_ERR_RANGE,
                         "render: frame size must be positive, got %d x %d",
                         width, height);
  /* llvmpipe unless the user chose a driver; swrast crashes inside OSMesa */
  setenv("GALLIUM_DRIVER", "llvmpipe", 0);
  const char *driver = getenv("GALLIUM_DRIVER");
  if (driver && strcmp(driver, "swrast") == 0)
    return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                         "render: GALLIUM_DRIVER=swrast does not work with "
                         "OSMesa; use llvmpipe (default) or softpipe");
  sph_gl *gl = calloc(1, sizeof *gl);
  if (!gl)
    return sph_error_set(err, SPH_ERR_NOMEM, "render: out of memory");
  gl->width = width;
  gl->height = height;
  /* the context */
  gl->ctx = OSMesaCreateContextAttribs(attribs, NULL);
  if (!gl->ctx) {
    free(gl);
    return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                         "render: OSMesa cannot create an OpenGL 3.3 core "
                         "context (GALLIUM_DRIVER=%s)",
                         driver ? driver : "");
  }
  sph_status st = make_current(gl, err);
  if (st != SPH_OK) {
    sph_gl_destroy(gl);
    return st;
  }
  /* size limits of the driver */
  GLint max_rb = 0, max_vp[2] = {0, 0};
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_rb);
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, max_vp);
  if (width > max_rb || height > max_rb || width > max_vp[0] ||
      height > max_vp[1]) {
    sph_gl_destroy(gl);
    return sph_error_set(err, SPH_ERR_RANGE,
                         "render: frame %d x %d exceeds the driver limit %d x "
                         "%d",
                         width, height, max_rb < max_vp[0] ? max_rb : max_vp[0],
                         max_rb < max_vp[1] ? max_rb : max_vp[1]);
  }
  /* host read-back buffer */
  gl->readback = malloc((size_t)width * (size_t)height * 4);
  if (!gl->readback) {
    sph_gl_destroy(gl);
    return sph_error_set(err, SPH_ERR_NOMEM, "render: out of memory");
  }
  /* program, vertex arrays, framebuffer */
  st = build_program(&gl->prog, 0, err);
  if (st == SPH_OK) {
    build_vertex_array(gl);
    st = build_framebuffer(gl, err);
  }
  if (st == SPH_OK)
    st = gl_check("setup", err);
  if (st != SPH_OK) {
    sph_gl_destroy(gl);
    return st;
  }
  *out = gl;
  return SPH_OK;
}

/* Grows the instance buffers to hold n spheres (never shrinks). */
static sph_status reserve(sph_gl *gl, size_t n, sph_error *err) {
  if (n <= gl->capacity)
    return SPH_OK;
  size_t cap = gl->capacity ? gl->capacity : 1024;
  while (cap < n)
    cap = cap > SIZE_MAX / 2 ? n : 2 * cap;
  if (cap > (size_t)INT_MAX / (3 * sizeof(float)))
    cap = n;
  if (cap > (size_t)INT_MAX / (3 * sizeof(float)))
    return sph_error_set(err, SPH_ERR_RANGE,
                         "render: %zu spheres exceed one draw call", n);
  glBindBuffer(GL_ARRAY_BUFFER, gl->centre_vbo);
  glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(cap * 3 * sizeof(float)), NULL,
               GL_DYNAMIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, gl->colour_vbo);
  glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(cap * 3), NULL, GL_DYNAMIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, gl->scale_vbo);
  glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(cap * sizeof(float)), NULL,
               GL_DYNAMIC_DRAW);
  if (gl->key_vbo) {
    glBindBuffer(GL_ARRAY_BUFFER, gl->key_vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(cap * sizeof(uint32_t)), NULL,
                 GL_DYNAMIC_DRAW);
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  SPH_TRY(gl_check("instance buffers", err));
  gl->capacity = cap;
  return SPH_OK;
}

/* Fixes every piece of state the pass depends on. */
static void set_state(sph_gl *gl) {
  glBindFramebuffer(GL_FRAMEBUFFER, gl->fbo);
  glDrawBuffer(GL_COLOR_ATTACHMENT0);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glViewport(0, 0, gl->width, gl->height);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_DITHER);
  glDisable(GL_CULL_FACE);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_MULTISAMPLE);
  glDisable(GL_SAMPLE_ALPHA_TO_COVERAGE);
  glDisable(GL_POLYGON_OFFSET_FILL);
  glDisable(GL_FRAMEBUFFER_SRGB);
  glDisable(GL_RASTERIZER_DISCARD);
  glEnable(GL_CLIP_DISTANCE0);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDepthRange(0.0, 1.0);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glPixelStorei(GL_PACK_SKIP_ROWS, 0);
  glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
}

/* Uploads the camera, radius, clip plane and shading uniforms. */
static void set_uniforms(sph_gl *gl, const gl_program *prog,
                         const sph_view *view, float radius,
                         const double *clip_plane, int flat) {
  double mv[16], pr[16];
  float mvf[16], prf[16];
  sph_view_matrix(view, mv);
  sph_view_projection(view, (double)gl->width / gl->height, pr);
  for (int k = 0; k < 16; ++k) {
    mvf[k] = (float)mv[k];
    prf[k] = (float)pr[k];
  }
  glUseProgram(prog->id);
  glUniformMatrix4fv(prog->view, 1, GL_FALSE, mvf);
  glUniformMatrix4fv(prog->proj, 1, GL_FALSE, prf);
  glUniform1f(prog->radius, radius);
  glUniform1i(prog->ortho, view->ortho ? 1 : 0);
  glUniform1i(prog->use_clip, clip_plane ? 1 : 0);
  glUniform1i(prog->flat, flat ? 1 : 0);
  if (clip_plane)
    glUniform4f(prog->plane, (float)clip_plane[0], (float)clip_plane[1],
                (float)clip_plane[2], (float)clip_plane[3]);
  else
    glUniform4f(prog->plane, 0.f, 0.f, 0.f, 1.f);
}

/* Checks one layer's arguments. */
static sph_status check_layer(const sph_gl_layer *l, sph_error *err) {
  if (l->n > 0 && (!l->xyz || !l->rgb))
    return sph_error_set(err, SPH_ERR_ARG, "render: missing centres/colours");
  if (l->n > 0 && !(l->radius > 0.0f && isfinite(l->radius)))
    return sph_error_set(err, SPH_ERR_ARG,
                         "render: sphere radius must be > 0, got %g",
                         (double)l->radius);
  if (l->clip_plane)
    for (int k = 0; k < 4; ++k)
      if (!isfinite(l->clip_plane[k]))
        return sph_error_set(err, SPH_ERR_ARG, "render: non-finite clip plane");
  for (size_t i = 0; l->scale && i < l->n; ++i)
    if (!(l->scale[i] > 0.0f && isfinite(l->scale[i])))
      return sph_error_set(err, SPH_ERR_ARG,
                           "render: sphere %zu has radius factor %g", i,
                           (double)l->scale[i]);
  for (size_t i = 0; i < 3 * l->n; ++i)
    if (!isfinite(l->xyz[i]))
      return sph_error_set(err, SPH_ERR_NUMERIC,
                           "render: sphere %zu has a non-finite centre", i / 3);
  if (l->n > (size_t)INT_MAX)
    return sph_error_set(err, SPH_ERR_RANGE,
                         "render: %zu spheres exceed one draw call", l->n);
  return SPH_OK;
}

/* The tagged program, its key buffer, the tag attachment and its
 * framebuffer (colour and depth shared with the plain one), made once. */
static sph_status tag_setup(sph_gl *gl, sph_error *err) {
  if (gl->tag.id)
    return SPH_OK;
  size_t npix = (size_t)gl->width * (size_t)(gl->height + 2);
  gl->px = malloc(npix * sizeof *gl->px);
  if (!gl->px)
    return sph_error_set(err, SPH_ERR_NOMEM, "render: out of memory");
  SPH_TRY(build_program(&gl->tag, 1, err));
  /* keys: 1 unsigned integer per instance */
  glGenBuffers(1, &gl->key_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, gl->key_vbo);
  glBufferData(
      GL_ARRAY_BUFFER,
      (GLsizeiptr)((gl->capacity ? gl->capacity : 1) * sizeof(uint32_t)), NULL,
      GL_DYNAMIC_DRAW);
  glBindVertexArray(gl->vao);
  glVertexAttribIPointer(4, 1, GL_UNSIGNED_INT, 0, NULL);
  glVertexAttribDivisor(4, 1);
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  /* the tag attachment */
  glGenRenderbuffers(1, &gl->tag_rb);
  glBindRenderbuffer(GL_RENDERBUFFER, gl->tag_rb);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32UI, gl->width, gl->height);
  glGenFramebuffers(1, &gl->tag_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, gl->tag_fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                            GL_RENDERBUFFER, gl->colour_rb);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1,
                            GL_RENDERBUFFER, gl->tag_rb);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT,
                            GL_RENDERBUFFER, gl->depth_rb);
  SPH_TRY(gl_check("tag framebuffer", err));
  return complete("tagged", err);
}

/* Instances a tagged draw hands llvmpipe at once: its binned triangles
 * (about 600 bytes an instance) then stay bounded however many a rank
 * draws. */
#define SPH_GL_CHUNK 4096

/* Draws layer l's instances in order, SPH_GL_CHUNK at a time (the
 * attribute pointers moved along the buffers; GL 3.3 has no base
 * instance), each chunk flushed: the same fragments in the same order. */
static void draw_chunks(sph_gl *gl, const sph_gl_layer *l) {
  for (size_t first = 0; first < l->n; first += SPH_GL_CHUNK) {
    size_t count = l->n - first < SPH_GL_CHUNK ? l->n - first : SPH_GL_CHUNK;
    glBindBuffer(GL_ARRAY_BUFFER, gl->centre_vbo);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0,
                          (const void *)(first * 3 * sizeof(float)));
    glBindBuffer(GL_ARRAY_BUFFER, gl->colour_vbo);
    glVertexAttribPointer(2, 3, GL_UNSIGNED_BYTE, GL_TRUE, 0,
                          (const void *)(first * 3));
    glBindBuffer(GL_ARRAY_BUFFER, gl->scale_vbo);
    glVertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, 0,
                          (const void *)(first * sizeof(float)));
    glBindBuffer(GL_ARRAY_BUFFER, gl->key_vbo);
    glVertexAttribIPointer(4, 1, GL_UNSIGNED_INT, 0,
                           (const void *)(first * sizeof(uint32_t)));
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)count);
    glFlush();
  }
  /* the pointers back at the buffers' starts */
  glBindBuffer(GL_ARRAY_BUFFER, gl->centre_vbo);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, NULL);
  glBindBuffer(GL_ARRAY_BUFFER, gl->colour_vbo);
  glVertexAttribPointer(2, 3, GL_UNSIGNED_BYTE, GL_TRUE, 0, NULL);
  glBindBuffer(GL_ARRAY_BUFFER, gl->scale_vbo);
  glVertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, 0, NULL);
  glBindBuffer(GL_ARRAY_BUFFER, gl->key_vbo);
  glVertexAttribIPointer(4, 1, GL_UNSIGNED_INT, 0, NULL);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

/* Checks the arguments and draws the layers (tagged: into the colour and
 * tag attachments, each layer's keys with its instances). */
static sph_status draw_pass(sph_gl *gl, const sph_view *view,
                            const sph_gl_layer *layers, int nlayers, int tagged,
                            sph_error *err) {
  /* arguments */
  if (!gl || (nlayers > 0 && !layers))
    return sph_error_set(err, SPH_ERR_ARG, "render: missing context or image");
  size_t most = 0;
  for (int i = 0; i < nlayers; ++i) {
    SPH_TRY(check_layer(&layers[i], err));
    if (tagged && layers[i].n > 0 && !layers[i].key)
      return sph_error_set(err, SPH_ERR_ARG, "render: missing keys");
    most = layers[i].n > most ? layers[i].n : most;
  }
  SPH_TRY(sph_view_check(view, err));
  SPH_TRY(make_current(gl, err));
  if (tagged)
    SPH_TRY(tag_setup(gl, err));
  SPH_TRY(reserve(gl, most, err));
  /* state, background */
  set_state(gl);
  const gl_program *pr = tagged ? &gl->tag : &gl->prog;
  if (tagged) {
    static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    static const GLuint none[4] = {0, 0, 0, 0};
    const GLfloat bg[4] = {SPH_GL_BACKGROUND / 255.0f,
                           SPH_GL_BACKGROUND / 255.0f,
                           SPH_GL_BACKGROUND / 255.0f, 1.0f};
    glBindFramebuffer(GL_FRAMEBUFFER, gl->tag_fbo);
    glDrawBuffers(2, bufs);
    glClearBufferfv(GL_COLOR, 0, bg);
    glClearBufferuiv(GL_COLOR, 1, none);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
  } else {
    glClearColor(SPH_GL_BACKGROUND / 255.0f, SPH_GL_BACKGROUND / 255.0f,
                 SPH_GL_BACKGROUND / 255.0f, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }
  /* each layer's instances in index order, over the layers before it */
  for (int i = 0; i < nlayers; ++i) {
    const sph_gl_layer *l = &layers[i];
    if (l->n == 0)
      continue;
    if (i > 0)
      glClear(GL_DEPTH_BUFFER_BIT);
    glBindBuffer(GL_ARRAY_BUFFER, gl->centre_vbo);
    glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(l->n * 3 * sizeof(float)),
                    l->xyz);
    glBindBuffer(GL_ARRAY_BUFFER, gl->colour_vbo);
    glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(l->n * 3), l->rgb);
    glBindVertexArray(gl->vao);
    if (l->scale) {
      glBindBuffer(GL_ARRAY_BUFFER, gl->scale_vbo);
      glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(l->n * sizeof(float)),
                      l->scale);
      glEnableVertexAttribArray(3);
    } else {
      glDisableVertexAttribArray(3);
      glVertexAttrib1f(3, 1.0f);
    }
    if (tagged) {
      glBindBuffer(GL_ARRAY_BUFFER, gl->key_vbo);
      glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(l->n * sizeof(uint32_t)),
                      l->key);
      glEnableVertexAttribArray(4);
    }
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    set_uniforms(gl, pr, view, l->radius, l->clip_plane, l->flat);
    if (tagged)
      glUniform1ui(pr->layer, (GLuint)(i + 1));
    if (tagged)
      draw_chunks(gl, l);
    else
      glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)l->n);
    if (tagged)
      glDisableVertexAttribArray(4);
    glBindVertexArray(0);
  }
  return SPH_OK;
}

sph_status sph_gl_draw_layers(sph_gl *gl, const sph_view *view,
                              const sph_gl_layer *layers, int nlayers,
                              sph_image *img, sph_error *err) {
  if (!gl || !img)
    return sph_error_set(err, SPH_ERR_ARG, "render: missing context or image");
  if (img->width != gl->width || img->height != gl->height || !img->rgba)
    return sph_error_set(err, SPH_ERR_ARG,
                         "render: image is %d x %d, the context draws %d x %d",
                         img->width, img->height, gl->width, gl->height);
  SPH_TRY(draw_pass(gl, view, layers, nlayers, 0, err));
  /* read back (GL rows run bottom-up) and flip into the image */
  glReadPixels(0, 0, gl->width, gl->height, GL_RGBA, GL_UNSIGNED_BYTE,
               gl->readback);
  SPH_TRY(gl_check("draw", err));
  size_t row = (size_t)gl->width * 4;
  for (int y = 0; y < gl->height; ++y)
    memcpy(img->rgba + (size_t)y * row,
           gl->readback + (size_t)(gl->height - 1 - y) * row, row);
  return SPH_OK;
}

/* Output row y of the tagged frame from GL row g (bottom-up), its tags
 * read from tag and colours from gl->readback. */
static void tag_row(sph_gl *gl, int y, int g, const sph_composite_px *tag) {
  size_t w = (size_t)gl->width;
  const unsigned char *c = gl->readback + (size_t)g * w * 4;
  sph_composite_px *o = gl->px + (size_t)y * w;
  for (size_t x = 0; x < w; ++x) {
    o[x] = tag[x];
    o[x].depth &= 0x7fffffffu; /* -0 as +0, as GL compares */
    memcpy(&o[x].rgba, c + 4 * x, 4);
  }
}

sph_status sph_gl_draw_tagged(sph_gl *gl, const sph_view *view,
                              const sph_gl_layer *layers, int nlayers,
                              const sph_composite_px **px, sph_error *err) {
  if (!px)
    return sph_error_set(err, SPH_ERR_ARG, "render: missing pixels");
  SPH_TRY(draw_pass(gl, view, layers, nlayers, 1, err));
  /* colours and tags back, bottom row first (a tag is 4 unsigned ints:
   * layer, depth bits, key, 0, as sph_composite_px) */
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, gl->width, gl->height, GL_RGBA, GL_UNSIGNED_BYTE,
               gl->readback);
  glReadBuffer(GL_COLOR_ATTACHMENT1);
  glReadPixels(0, 0, gl->width, gl->height, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
               gl->px);
  SPH_TRY(gl_check("tagged draw", err));
  /* in place, top row first: rows y and its mirror through two spare rows */
  size_t w = (size_t)gl->width;
  sph_composite_px *spare = gl->px + (size_t)gl->height * w;
  for (int y = 0; y <= (gl->height - 1) / 2; ++y) {
    int g = gl->height - 1 - y;
    memcpy(spare, gl->px + (size_t)y * w, w * sizeof *spare);
    memcpy(spare + w, gl->px + (size_t)g * w, w * sizeof *spare);
    tag_row(gl, y, g, spare + w);
    if (g != y)
      tag_row(gl, g, y, spare);
  }
  *px = gl->px;
  return SPH_OK;
}

sph_status sph_gl_draw_spheres(sph_gl *gl, const sph_view *view, size_t n,
                               const float *xyz, float radius,
                               const unsigned char *rgb,
                               const double *clip_plane, sph_image *img,
                               sph_error *err) {
  sph_gl_layer layer = {n, xyz, radius, rgb, clip_plane, 0, NULL, NULL};
  return sph_gl_draw_layers(gl, view, &layer, 1, img, err);
}

void sph_gl_destroy(sph_gl *gl) {
  if (!gl)
    return;
  /* GL objects die with the context; release them explicitly anyway */
  if (gl->ctx && make_current(gl, NULL) == SPH_OK) {
    if (gl->prog.id)
      glDeleteProgram(gl->prog.id);
    if (gl->tag.id)
      glDeleteProgram(gl->tag.id);
    GLuint bufs[5] = {gl->quad_vbo, gl->centre_vbo, gl->colour_vbo,
                      gl->scale_vbo, gl->key_vbo};
    GLuint rbs[3] = {gl->colour_rb, gl->depth_rb, gl->tag_rb};
    GLuint fbos[2] = {gl->fbo, gl->tag_fbo};
    glDeleteBuffers(5, bufs);
    glDeleteVertexArrays(1, &gl->vao);
    glDeleteFramebuffers(2, fbos);
    glDeleteRenderbuffers(3, rbs);
    OSMesaMakeCurrent(NULL, NULL, 0, 0, 0);
  }
  if (gl->ctx)
    OSMesaDestroyContext(gl->ctx);
  free(gl->readback);
  free(gl->px);
  free(gl);
}
