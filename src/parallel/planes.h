/* Reflection through a symmetry or skew-symmetry plane X . n = at (seed 000
 * sec. 8.2, docs/benchmarks.md D.1): the one implementation of the geometry of
 * mirror images, used by the methods' image particles
 * (methods/common/images.c) and by the domain's reflected boxes, which find
 * the ghosts the images' sources are (parallel/domain_fixed.c,
 * domain_share.c, domain_dynamic.c). A coordinate plane (axis >= 0)
 * reflects exactly, X_axis -> 2 at - X_axis; a plane of any other unit
 * normal n reflects X -> X - 2 d n with d = X . n - at. */
#ifndef SPH_PARALLEL_PLANES_H
#define SPH_PARALLEL_PLANES_H

/* A symmetry or skew-symmetry plane X . n = at (axis: the coordinate axis
 * of n, or -1) whose mirror images the method builds over owned and ghost
 * particles (methods/common/images.c). */
typedef struct sph_domain_plane {
  double n[3], at;
  int axis;
} sph_domain_plane;

/* Signed distance of X from the plane (exact for a coordinate axis). */
static inline double sph_plane_distance(const sph_domain_plane *p,
                                        const double X[3]) {
  if (p->axis >= 0)
    return X[p->axis] - p->at;
  return X[0] * p->n[0] + X[1] * p->n[1] + X[2] * p->n[2] - p->at;
}

/* The reflection of X, whose signed distance from the plane is dist
 * (sph_plane_distance), into out (which may be X). */
static inline void sph_plane_reflect(const sph_domain_plane *p,
                                     const double X[3], double dist,
                                     double out[3]) {
  for (int c = 0; c < 3; ++c)
    out[c] = p->axis >= 0 ? (c == p->axis ? 2.0 * p->at - X[c] : X[c])
                          : X[c] - 2.0 * dist * p->n[c];
}

#endif
