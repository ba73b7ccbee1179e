/* Camera maths of the sphere renderer: look-at and projection matrices,
 * world-to-pixel projection and the camera that frames a box. */
#include "gl_impl.h"

#include <math.h>
#include <string.h>

static const double deg = 3.14159265358979323846 / 180.0;

static double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

static double normalize3(double a[3]) {
  double n = sqrt(dot3(a, a));
  if (n > 0.0)
    for (int k = 0; k < 3; ++k)
      a[k] /= n;
  return n;
}

/* Right (s), up (u) and forward (f) unit vectors of the camera; 0 when the
 * view direction or the up vector is degenerate. */
static int camera_basis(const sph_view *v, double s[3], double u[3],
                        double f[3]) {
  for (int k = 0; k < 3; ++k)
    f[k] = v->target[k] - v->eye[k];
  double fl = normalize3(f);
  cross3(f, v->up, s);
  double sl = normalize3(s);
  if (!(fl > 0.0) || !(sl > 1e-12 * sqrt(dot3(v->up, v->up))))
    return 0;
  cross3(s, f, u);
  return 1;
}

static int all_finite(const double *a, int n) {
  for (int k = 0; k < n; ++k)
    if (!isfinite(a[k]))
      return 0;
  return 1;
}

sph_status sph_view_check(const sph_view *v, sph_error *err) {
  double s[3], u[3], f[3];
  if (!v)
    return sph_error_set(err, SPH_ERR_ARG, "view: missing camera");
  /* finite numbers everywhere */
  if (!all_finite(v->eye, 3) || !all_finite(v->target, 3) ||
      !all_finite(v->up, 3) || !isfinite(v->near_clip) ||
      !isfinite(v->far_clip))
    return sph_error_set(err, SPH_ERR_ARG, "view: non-finite camera value");
  /* a view direction and an up vector not parallel to it */
  if (!camera_basis(v, s, u, f))
    return sph_error_set(err, SPH_ERR_ARG,
                         "view: eye equals target or up is parallel to the "
                         "view direction");
  /* projection parameters */
  if (v->ortho) {
    if (!(v->ortho_height > 0.0) || !isfinite(v->ortho_height))
      return sph_error_set(err, SPH_ERR_ARG,
                           "view: ortho_height must be > 0, got %g",
                           v->ortho_height);
    if (!(v->near_clip < v->far_clip))
      return sph_error_set(err, SPH_ERR_ARG,
                           "view: need near < far, got %g and %g", v->near_clip,
                           v->far_clip);
  } else {
    if (!(v->fovy_deg > 0.0 && v->fovy_deg < 180.0))
      return sph_error_set(err, SPH_ERR_ARG,
                           "view: fovy must be in (0, 180) degrees, got %g",
                           v->fovy_deg);
    if (!(v->near_clip > 0.0 && v->near_clip < v->far_clip))
      return sph_error_set(err, SPH_ERR_ARG,
                           "view: need 0 < near < far, got %g and %g",
                           v->near_clip, v->far_clip);
  }
  return SPH_OK;
}

void sph_view_matrix(const sph_view *v, double m[16]) {
  double s[3], u[3], f[3];
  memset(m, 0, 16 * sizeof *m);
  m[0] = m[5] = m[10] = m[15] = 1.0;
  if (!camera_basis(v, s, u, f))
    return;
  /* rows s, u, -f; translation moves the eye to the origin */
  for (int k = 0; k < 3; ++k) {
    m[4 * k + 0] = s[k];
    m[4 * k + 1] = u[k];
    m[4 * k + 2] = -f[k];
  }
  m[12] = -dot3(s, v->eye);
  m[13] = -dot3(u, v->eye);
  m[14] = dot3(f, v->eye);
}

void sph_view_projection(const sph_view *v, double aspect, double m[16]) {
  double n = v->near_clip, fa = v->far_clip;
  memset(m, 0, 16 * sizeof *m);
  if (v->ortho) {
    /* box of ortho_height x ortho_height*aspect, depth [near, far] */
    double h = v->ortho_height, w = h * aspect;
    m[0] = 2.0 / w;
    m[5] = 2.0 / h;
    m[10] = -2.0 / (fa - n);
    m[14] = -(fa + n) / (fa - n);
    m[15] = 1.0;
  } else {
    /* symmetric frustum */
    double t = 1.0 / tan(0.5 * v->fovy_deg * deg);
    m[0] = t / aspect;
    m[5] = t;
    m[10] = (fa + n) / (n - fa);
    m[11] = -1.0;
    m[14] = 2.0 * fa * n / (n - fa);
  }
}

int sph_view_project(const sph_view *v, int width, int height,
                     const double p[3], double out[3]) {
  double mv[16], pr[16], e[4], c[4];
  sph_view_matrix(v, mv);
  sph_view_projection(v, (double)width / height, pr);
  /* world -> eye -> clip */
  for (int r = 0; r < 4; ++r)
    e[r] = mv[r] * p[0] + mv[4 + r] * p[1] + mv[8 + r] * p[2] + mv[12 + r];
  for (int r = 0; r < 4; ++r)
    c[r] =
        pr[r] * e[0] + pr[4 + r] * e[1] + pr[8 + r] * e[2] + pr[12 + r] * e[3];
  if (!(c[3] > 0.0))
    return 0;
  /* clip -> normalised device -> pixels, top row first */
  out[0] = (0.5 * c[0] / c[3] + 0.5) * width;
  out[1] = (0.5 - 0.5 * c[1] / c[3]) * height;
  out[2] = 0.5 * c[2] / c[3] + 0.5;
  return 1;
}

void sph_view_fit(const double lo[3], const double hi[3], double azimuth,
                  double elevation, double zoom, int ortho, int dim, int width,
                  int height, sph_view *out) {
  const double margin = 1.05, fovy = 30.0;
  double c[3], e[3], d[3], u[3], s[3];
  double aspect = (width > 0 && height > 0) ? (double)width / height : 1.0;
  if (!(zoom > 0.0) || !isfinite(zoom))
    zoom = 1.0;
  /* centre, half extents and bounding radius of the box */
  for (int k = 0; k < 3; ++k) {
    c[k] = 0.5 * (lo[k] + hi[k]);
    e[k] = 0.5 * fabs(hi[k] - lo[k]);
  }
  double radius = sqrt(dot3(e, e));
  if (!(radius > 0.0))
    radius = 1.0;
  /* direction to the camera (d) and screen up (u, d/d elevation of d) */
  if (dim == 2) {
    ortho = 1;
    azimuth = elevation = 0.0;
  }
  double ca = cos(azimuth * deg), sa = sin(azimuth * deg);
  double ce = cos(elevation * deg), se = sin(elevation * deg);
  d[0] = ce * sa, d[1] = se, d[2] = ce * ca;
  u[0] = -se * sa, u[1] = ce, u[2] = -se * ca;
  cross3(u, d, s);
  /* tightest distance (perspective) or height (ortho) over the 8 corners */
  double ty = tan(0.5 * fovy * deg) / margin, tx = ty * aspect;
  double dist = 0.0, half = 0.0;
  for (int i = 0; i < 8; ++i) {
    double q[3] = {(i & 1 ? e[0] : -e[0]), (i & 2 ? e[1] : -e[1]),
                   (i & 4 ? e[2] : -e[2])};
    double x = fabs(dot3(q, s)), y = fabs(dot3(q, u)), z = dot3(q, d);
    double need = z + fmax(x / tx, y / ty);
    dist = fmax(dist, need);
    half = fmax(half, fmax(y, x / aspect) * margin);
  }
  if (!(half > 0.0))
    half = radius;
  memset(out, 0, sizeof *out);
  out->ortho = ortho ? 1 : 0;
  if (out->ortho) {
    /* eye outside the bounding sphere; depth range covers it twice over */
    dist = 3.0 * radius;
    out->fovy_deg = fovy;
    out->ortho_height = 2.0 * half / zoom;
  } else {
    dist = fmax(dist, 1.05 * radius);
    out->fovy_deg = 2.0 * atan(tan(0.5 * fovy * deg) / zoom) / deg;
    out->ortho_height = 2.0 * half;
  }
  out->near_clip = fmax(dist - 2.0 * radius, 1e-3 * dist);
  out->far_clip = dist + 2.0 * radius;
  for (int k = 0; k < 3; ++k) {
    out->eye[k] = c[k] + dist * d[k];
    out->target[k] = c[k];
    out->up[k] = u[k];
  }
}
