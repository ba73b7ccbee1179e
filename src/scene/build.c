/* The particles of a scene's bodies (sph_scene_build_particles), with the
 * checks that need them: non-finite initial velocities, positions doubles
 * cannot resolve, bodies that overlap, selections that select nothing,
 * probes outside every body, particles behind a contact wall. The checks
 * are shared with the per-rank share (share.c, build_impl.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/neighbors.h"
#include "scene/build_impl.h"
#include "scene/expr.h"
#include "scene/geometry.h"

static void initial_velocity(const sph_velocity *v, const double X[3],
                             double out[3]) {
  out[0] = out[1] = out[2] = 0.0;
  switch (v->kind) {
  case SPH_VEL_NONE:
    return;
  case SPH_VEL_UNIFORM:
    memcpy(out, v->value, 3 * sizeof *out);
    return;
  case SPH_VEL_ROTATION: {
    double w =
        v->omega *
        (v->profile ? sph_expr_eval(v->profile, X[0], X[1], X[2], 0.0) : 1.0);
    double omega[3] = {w * v->axis[0], w * v->axis[1], w * v->axis[2]}, r[3];
    for (int c = 0; c < 3; ++c)
      r[c] = X[c] - v->center[c];
    out[0] = omega[1] * r[2] - omega[2] * r[1];
    out[1] = omega[2] * r[0] - omega[0] * r[2];
    out[2] = omega[0] * r[1] - omega[1] * r[0];
    return;
  }
  case SPH_VEL_EXPRESSION:
    for (int c = 0; c < 3; ++c)
      out[c] = sph_expr_eval(v->expr[c], X[0], X[1], X[2], 0.0);
    return;
  }
}

sph_status sph_build_checks_create(const sph_scene *s, build_checks *c,
                                   sph_error *err) {
  memset(c, 0, sizeof *c);
  c->wall = s->contact.nwalls;
  c->hit = calloc(s->nboundaries + 1, 1);
  c->inside = calloc(s->output.nprobes + 1, 1);
  if (!c->hit || !c->inside)
    return sph_error_set(err, SPH_ERR_NOMEM, "particle checks");
  return SPH_OK;
}

void sph_build_checks_destroy(build_checks *c) {
  free(c->hit);
  free(c->inside);
}

/* Positions a double can tell apart at the particle spacing: beyond 1e9
 * spacings from the origin a coordinate's rounding step exceeds 1e-7 dp
 * (kernel sums and neighbour cells lose their meaning). */
static void check_resolvable(const sph_scene *s, size_t b, const double X[3],
                             build_checks *c) {
  double limit = 1e9 * sph_scene_min_spacing(s);
  for (int k = 0; k < 3 && !c->resolvable; ++k)
    if (!(fabs(X[k]) <= limit)) {
      const sph_body *bd = &s->bodies[b];
      char key[32];
      snprintf(key, sizeof key, "bodies[%d]", (int)b);
      c->resolvable = 1;
      sph_error_at(
          &c->resolvable_err, SPH_ERR_GEOMETRY, s->path, bd->line, bd->col, key,
          "a particle at %g m lies more than 1e9 particle spacings (%g m) "
          "from the origin, where double precision cannot resolve the "
          "spacing: place the body nearer the origin",
          X[k], sph_scene_min_spacing(s));
    }
}

/* The particle of body b at Xb (body frame): its world position X, initial
 * velocity v (world frame) and flags, the checks updated when c is given. */
void sph_build_particle_state(const sph_scene *s, size_t b, const double Xb[3],
                              double X[3], double v[3], uint32_t *flags,
                              build_checks *c) {
  const sph_body *bd = &s->bodies[b];
  double vb[3];
  sph_body_world(bd, Xb, X);
  initial_velocity(&bd->velocity, Xb, vb);
  if (bd->transform.given)
    sph_transform_rotate(&bd->transform, vb, v);
  else
    memcpy(v, vb, sizeof vb);
  *flags = 0;
  for (size_t k = 0; k < s->nboundaries; ++k)
    if (sph_selection_contains(s, &s->boundaries[k].select, (int)b, X)) {
      *flags |= SPH_FLAG_BOUNDARY;
      if (c)
        c->hit[k] = 1;
    }
  if (!c)
    return;
  if (!c->velocity && !isfinite(vb[0] + vb[1] + vb[2])) {
    char key[48];
    snprintf(key, sizeof key, "bodies[%zu].initial_velocity", b);
    c->velocity = 1;
    sph_error_at(&c->velocity_err, SPH_ERR_RANGE, s->path, bd->line, bd->col,
                 key, "not finite at (%g, %g, %g) (body frame)", Xb[0], Xb[1],
                 Xb[2]);
  }
  check_resolvable(s, b, X, c);
  /* probes: within one spacing of a particle */
  for (size_t k = 0; k < s->output.nprobes; ++k) {
    const sph_probe *p = &s->output.probes[k];
    double d2 = 0.0;
    for (int e = 0; e < s->dimension; ++e)
      d2 += (X[e] - p->at[e]) * (X[e] - p->at[e]);
    c->inside[k] |= d2 <= bd->spacing * bd->spacing;
  }
  /* walls: no particle starts behind one */
  for (size_t k = 0; k < c->wall; ++k) {
    const sph_wall *w = &s->contact.walls[k];
    double nrm[3], g = sph_wall_distance(w, 0.0, s->dimension, X, nrm);
    if (g >= 0.0)
      continue;
    char key[48];
    snprintf(key, sizeof key, "contact.walls[%zu]", k);
    sph_error_at(&c->wall_err, SPH_ERR_GEOMETRY, s->path, w->line, w->col, key,
                 "body '%s' starts inside wall '%s' (a particle %g m "
                 "beyond it)",
                 bd->name, w->name, -g);
    c->wall = k;
    break;
  }
}

/* the checks' first failure in the serial order: velocities, positions */
sph_status sph_build_checks_first(const build_checks *c, sph_error *err) {
  if (c->velocity || c->resolvable) {
    *err = c->velocity ? c->velocity_err : c->resolvable_err;
    return err->code;
  }
  return SPH_OK;
}

/* then selections, probes and walls */
sph_status sph_build_checks_rest(const sph_scene *s, const build_checks *c,
                                 sph_error *err) {
  for (size_t k = 0; k < s->nboundaries; ++k)
    if (!c->hit[k]) {
      const sph_boundary *bc = &s->boundaries[k];
      char key[48];
      snprintf(key, sizeof key, "boundaries[%zu].select", k);
      return sph_error_at(err, SPH_ERR_GEOMETRY, s->path, bc->line, bc->col,
                          key, "boundary '%s' selects no particle", bc->name);
    }
  for (size_t k = 0; k < s->output.nprobes; ++k)
    if (!c->inside[k]) {
      const sph_probe *p = &s->output.probes[k];
      char key[48];
      snprintf(key, sizeof key, "output.probes[%zu].at", k);
      return sph_error_at(err, SPH_ERR_GEOMETRY, s->path, p->line, p->col, key,
                          "probe '%s' at (%g, %g, %g) is outside every body",
                          p->name, p->at[0], p->at[1],
                          s->dimension == 3 ? p->at[2] : 0.0);
    }
  if (c->wall < s->contact.nwalls) {
    *err = c->wall_err;
    return err->code;
  }
  return SPH_OK;
}

/* a body's generation error at its key */
sph_status sph_build_body_error(const sph_scene *s, size_t b, sph_status st,
                                sph_error *err) {
  char msg[768], key[32];
  snprintf(msg, sizeof msg, "%s", err->message);
  snprintf(key, sizeof key, "bodies[%zu]", b);
  return sph_error_at(err, st, s->path, s->bodies[b].line, s->bodies[b].col,
                      key, "%s", msg);
}

/* bodies A and B overlap: particles at Xa and Xb closer than dp / 2 */
static sph_status overlap_error(const sph_scene *s, int32_t A, int32_t B,
                                const double Xa[3], const double Xb[3],
                                sph_error *err) {
  const sph_body *later = &s->bodies[A > B ? A : B];
  const sph_body *first = &s->bodies[A > B ? B : A];
  char key[32];
  snprintf(key, sizeof key, "bodies[%d]", (int)(later - s->bodies));
  return sph_error_at(err, SPH_ERR_GEOMETRY, s->path, later->line, later->col,
                      key,
                      "body '%s' overlaps body '%s' (particles %.3g m "
                      "apart)",
                      later->name, first->name,
                      sqrt(pow(Xa[0] - Xb[0], 2) + pow(Xa[1] - Xb[1], 2) +
                           pow(Xa[2] - Xb[2], 2)));
}

/* the first of the n points X (bodies, in creation order) that `check`
 * marks with a point of another body closer than dp / 2, and the first
 * such point: as an error, *first its index (n: none) */
sph_status sph_build_find_overlap(const sph_scene *s, const double *X,
                                  const int32_t *body, const char *check,
                                  size_t n, size_t *first, sph_error *err) {
  *first = n;
  sph_neighbors *nl;
  SPH_TRY(sph_neighbors_create(&nl, err));
  sph_status st = sph_neighbors_build(nl, X, n, s->dimension,
                                      0.5 * sph_scene_min_spacing(s), NULL,
                                      SPH_PAIRS_ALL, err);
  for (size_t a = 0; st == SPH_OK && a < n; ++a)
    for (size_t k = nl->offset[a];
         (!check || check[a]) && k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      if (body[b] == body[a])
        continue;
      *first = a;
      st = overlap_error(s, body[a], body[b], X + 3 * a, X + 3 * b, err);
      break;
    }
  sph_neighbors_destroy(nl);
  return st;
}

static sph_status check_overlap(const sph_scene *s, sph_particles *ps,
                                sph_error *err) {
  if (s->nbodies < 2)
    return SPH_OK;
  size_t first;
  return sph_build_find_overlap(s, ps->field[SPH_FIELD_POSITION0], ps->body,
                                NULL, ps->n, &first, err);
}

sph_status sph_scene_build_particles(const sph_scene *s, sph_particles **out,
                                     sph_error *err) {
  *out = NULL;
  double **xs = calloc(s->nbodies, sizeof *xs);
  double **vs = calloc(s->nbodies, sizeof *vs);
  size_t *ns = calloc(s->nbodies, sizeof *ns), total = 0;
  build_checks c;
  sph_status st = sph_build_checks_create(s, &c, err);
  if (st == SPH_OK && !(xs && vs && ns))
    st = sph_error_set(err, SPH_ERR_NOMEM, "bodies");
  for (size_t b = 0; st == SPH_OK && b < s->nbodies; ++b) {
    st = sph_body_generate(&s->bodies[b], s->dimension, &xs[b], &vs[b], &ns[b],
                           err);
    if (st != SPH_OK)
      st = sph_build_body_error(s, b, st, err);
    total += ns[b];
  }
  sph_particles *ps = NULL;
  if (st == SPH_OK)
    st = sph_particles_create(&ps, total, s->dimension, err);
  if (st == SPH_OK)
    st = sph_particles_require(ps, SPH_FIELD_VELOCITY, err);
  /* positions and initial velocities from the body frame to the world */
  for (size_t b = 0; st == SPH_OK && b < s->nbodies; ++b)
    for (size_t i = 0; st == SPH_OK && i < ns[b]; ++i) {
      double X[3], v[3];
      uint32_t flags;
      sph_build_particle_state(s, b, xs[b] + 3 * i, X, v, &flags, &c);
      st = sph_particles_append(ps, X, vs[b][i], (int32_t)b, err);
      if (st == SPH_OK) {
        memcpy(ps->field[SPH_FIELD_VELOCITY] + 3 * (ps->n - 1), v, sizeof v);
        ps->flags[ps->n - 1] = flags;
      }
    }
  for (size_t b = 0; xs && vs && b < s->nbodies; ++b) {
    free(xs[b]);
    free(vs[b]);
  }
  free(xs);
  free(vs);
  free(ns);
  if (st == SPH_OK)
    st = sph_build_checks_first(&c, err);
  if (st == SPH_OK)
    st = check_overlap(s, ps, err);
  if (st == SPH_OK)
    st = sph_build_checks_rest(s, &c, err);
  sph_build_checks_destroy(&c);
  if (st != SPH_OK) {
    sph_particles_destroy(ps);
    return st;
  }
  *out = ps;
  return SPH_OK;
}
