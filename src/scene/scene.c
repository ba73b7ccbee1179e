/* Queries on a loaded scene: essential boundaries, wall distances, output
 * times, spacing, names, body frames (world X = R X_body + t) and whether a
 * selection holds a particle. The schema is in schema*.c, the particles in
 * build.c and share.c. */
#include "scene/scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/geometry.h"
#include "scene/mesh.h"

/* out = R v */
void sph_transform_rotate(const sph_transform *T, const double v[3],
                          double out[3]) {
  for (int i = 0; i < 3; ++i)
    out[i] =
        T->R[3 * i] * v[0] + T->R[3 * i + 1] * v[1] + T->R[3 * i + 2] * v[2];
}

int sph_scene_has_essential_bc(const sph_scene *s) {
  for (size_t k = 0; k < s->nboundaries; ++k)
    if (s->boundaries[k].kind == SPH_BC_CLAMP ||
        s->boundaries[k].kind == SPH_BC_ROLLER ||
        s->boundaries[k].kind == SPH_BC_VELOCITY)
      return 1;
  return 0;
}

double sph_wall_distance(const sph_wall *w, double t, int dim,
                         const double x[3], double n[3]) {
  double y[3]; /* x in the frame of the wall at t = 0 */
  for (int c = 0; c < 3; ++c)
    y[c] = c < dim ? x[c] - t * w->velocity[c] : 0.0;
  if (w->kind == SPH_WALL_PLANE) {
    double g = 0.0;
    for (int c = 0; c < 3; ++c) {
      n[c] = w->normal[c];
      g += (y[c] - w->point[c]) * n[c];
    }
    return g;
  }
  /* box: distance to the nearest point of its surface, negative inside */
  double out[3], out2 = 0.0, depth = INFINITY;
  int face = 0;
  for (int c = 0; c < dim; ++c) {
    out[c] = y[c] < w->min[c]   ? y[c] - w->min[c]
             : y[c] > w->max[c] ? y[c] - w->max[c]
                                : 0.0;
    out2 += out[c] * out[c];
    double lo = y[c] - w->min[c], hi = w->max[c] - y[c];
    if (lo < depth) {
      depth = lo;
      face = -(c + 1);
    }
    if (hi < depth) {
      depth = hi;
      face = c + 1;
    }
  }
  n[0] = n[1] = n[2] = 0.0;
  if (out2 > 0.0) {
    double g = sqrt(out2);
    for (int c = 0; c < dim; ++c)
      n[c] = out[c] / g;
    return g;
  }
  n[abs(face) - 1] = face > 0 ? 1.0 : -1.0;
  return -depth;
}

double sph_output_time(const sph_scene *s, int index) {
  return fmin(s->t_end, s->output.every * (double)index);
}

double sph_scene_min_spacing(const sph_scene *s) {
  double dp = INFINITY;
  for (size_t b = 0; b < s->nbodies; ++b)
    dp = s->bodies[b].spacing < dp ? s->bodies[b].spacing : dp;
  return dp;
}

int sph_scene_find_material(const sph_scene *s, const char *name) {
  for (size_t i = 0; i < s->nmaterials; ++i)
    if (!strcmp(s->materials[i].name, name))
      return (int)i;
  return -1;
}

int sph_scene_find_body(const sph_scene *s, const char *name) {
  for (size_t i = 0; i < s->nbodies; ++i)
    if (!strcmp(s->bodies[i].name, name))
      return (int)i;
  return -1;
}

void sph_body_local(const sph_body *b, const double X[3], double Xb[3]) {
  const sph_transform *T = &b->transform;
  if (!T->given) {
    memmove(Xb, X, 3 * sizeof *X);
    return;
  }
  double d[3] = {X[0] - T->t[0], X[1] - T->t[1], X[2] - T->t[2]};
  for (int i = 0; i < 3; ++i)
    Xb[i] = T->R[i] * d[0] + T->R[3 + i] * d[1] + T->R[6 + i] * d[2];
}

void sph_body_world(const sph_body *b, const double Xb[3], double X[3]) {
  const sph_transform *T = &b->transform;
  if (!T->given) {
    memmove(X, Xb, 3 * sizeof *X);
    return;
  }
  double r[3];
  sph_transform_rotate(T, Xb, r);
  for (int i = 0; i < 3; ++i)
    X[i] = r[i] + T->t[i];
}

int sph_axis_index(const double n[3]) {
  for (int a = 0; a < 3; ++a)
    if (n[a] == 1.0 && n[(a + 1) % 3] == 0.0 && n[(a + 2) % 3] == 0.0)
      return a;
  return -1;
}

int sph_selection_contains(const sph_scene *s, const sph_selection *sel,
                           int body, const double X[3]) {
  if (sel->body >= 0 && body != sel->body)
    return 0;
  double Xb[3];
  if (sel->kind != SPH_SELECT_PLANE && sel->body >= 0) {
    sph_body_local(&s->bodies[sel->body], X, Xb);
    X = Xb;
  }
  switch (sel->kind) {
  case SPH_SELECT_PLANE:
    if (sel->axis >= 0)
      return fabs(X[sel->axis] - sel->at) <= sel->tolerance;
    return fabs(X[0] * sel->normal[0] + X[1] * sel->normal[1] +
                X[2] * sel->normal[2] - sel->at) <= sel->tolerance;
  case SPH_SELECT_BOX:
    for (int c = 0; c < s->dimension; ++c)
      if (X[c] < sel->min[c] - sel->tolerance ||
          X[c] > sel->max[c] + sel->tolerance)
        return 0;
    return 1;
  case SPH_SELECT_FACE: {
    double lo[3], hi[3];
    const sph_body *b = &s->bodies[sel->body];
    sph_shape_bounds(&b->shape, s->dimension, lo, hi);
    double at = sel->side > 0 ? hi[sel->axis] : lo[sel->axis];
    /* first layer: on the face (face lattice) or about dp / 2 inside */
    double tol = (b->lattice == SPH_LATTICE_FACES ? 0.5 : 1.0) * b->spacing;
    return fabs(X[sel->axis] - at) <= tol;
  }
  case SPH_SELECT_NEAR:
    return sph_mesh_distance(sel->near, X) <= sel->tolerance;
  }
  return 0;
}
