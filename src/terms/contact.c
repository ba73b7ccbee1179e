/* Frictionless contact by a penalty force: rigid walls (a symmetry plane
 * between two colliding bodies, seed 001 sec. 2.4.2; the rigid tool of the
 * punch, sec. 2.4.3) and particles of different bodies (the two rubber
 * rings, sec. 2.4.2, where the total-Lagrangian neighbour lists never join
 * bodies). The papers impose the contact exactly; here it is a spring that
 * acts along the normal while a particle is closer than r_c:
 *   f = kappa M A (r_c - r) / r_c,
 * M = lambda + 2 mu the p-wave modulus (harmonic mean across a pair), A the
 * area a particle presents (V0 / dp), r_c = dp / 2 to a wall and
 * (dp_a + dp_b) / 2 between particles. Mirrored about a wall, a pair of
 * particles feels exactly the wall's force. The force is conservative and
 * equal and opposite across a pair, so momentum is kept to round-off; the
 * spring bounds the time step (term_stable_dt).
 *
 * Over MPI ranks (issue 20) a wall acts on each owned particle alone. Pairs
 * of bodies take their partners from the other ranks: with the dynamic
 * domain of the updated-Lagrangian methods its ghosts (the other ranks'
 * particles within a kernel support at the last rebuild) carry their
 * current positions, and the ghost layer covers the contact radius while
 * no particle has moved more than (support - r_c) / 2 since the rebuild
 * (checked); the total-Lagrangian methods' ghosts are fixed in the
 * reference configuration, so at every stage each rank sends its particles
 * near another body to the ranks whose such particles are within the
 * contact radius (sph_domain_box_points). Either way the pair lists are
 * sorted into the serial storage order and only owned particles take a
 * force, so each pair's force is the same bits on both ranks and the
 * serial run's sums are repeated. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "materials/material.h"
#include "terms/terms_impl.h"

typedef struct contact {
  size_t n;  /* owned particles */
  size_t ne; /* and the ghosts of a dynamic domain */
  int dim;
  int per_volume; /* dp is a momentum rate per V0 */
  const sph_contact *spec;
  double kappa;
  double *inv_mass; /* 1 / V0 (dp is a momentum rate) or 1 / m */
  double *modulus;  /* lambda + 2 mu of the particle's material */
  double *area;     /* V0 / dp */
  double *spacing;  /* dp of the particle's body */
  double dt_bound;
  /* between bodies: the particles near another body, their positions and
   * bodies gathered for the search, and the pairs closer than `radius` */
  int between;
  int nbodies;
  double radius;
  double *box; /* per body: min[3], max[3] of the stage positions */
  size_t *cand;
  double *xc;
  int32_t *bc;
  sph_neighbors *nl;
  /* over MPI ranks: positions at the last ghost search, and the distance a
   * particle may move from them while the ghosts cover the contact radius */
  sph_domain *dom;
  double *x_found;
  double slack;
  /* over MPI ranks with fixed ghosts: the candidates' rows (x, body,
   * storage index, spacing, modulus, area), the other ranks' received,
   * and the candidates' keys and constants (cap of each, grown only) */
  sph_domain *ranks;
  double *rows, *near;
  size_t near_cap, cap;
  int64_t *keyc;
  double *sc, *mc, *ac;
} contact;

enum { ROW_BODY = 3, ROW_KEY, ROW_SPACING, ROW_MODULUS, ROW_AREA, ROW_W };

/* A particle of body b within `pad` of the box of another body. */
static int near_other_body(const contact *ct, const double *x, int b,
                           double pad) {
  for (int o = 0; o < ct->nbodies; ++o) {
    if (o == b)
      continue;
    const double *lo = ct->box + 6 * o, *hi = lo + 3;
    int in = 1;
    for (int c = 0; c < ct->dim && in; ++c)
      in = x[c] > lo[c] - pad && x[c] < hi[c] + pad;
    if (in)
      return 1;
  }
  return 0;
}

/* over MPI ranks: every pair closer than the contact radius joins an owned
 * particle and a ghost while no particle has moved more than `slack` since
 * the ghosts were found (collective) */
static sph_status ghosts_cover(const contact *ct, const double *x,
                               sph_error *err) {
  double d2max = 0.0;
#pragma omp parallel for schedule(static) reduction(max : d2max)
  for (size_t a = 0; a < ct->n; ++a) {
    double d2 = 0.0;
    for (int c = 0; c < 3; ++c) {
      double u = x[3 * a + c] - ct->x_found[3 * a + c];
      d2 += u * u;
    }
    d2max = fmax(d2max, d2);
  }
  d2max = sph_domain_max(ct->dom, d2max);
  if (d2max <= ct->slack * ct->slack)
    return SPH_OK;
  return sph_error_set(err, SPH_ERR_RANGE,
                       "contact over MPI ranks: a particle moved %.3g "
                       "spacings since the ghosts were found, more than the "
                       "%.3g the ghost layer leaves beyond the contact "
                       "radius; update the reference more often "
                       "(method.update_every or update_distance)",
                       sqrt(d2max) / ct->radius, ct->slack / ct->radius);
}

/* e = xa - xb; returns |e|^2 */
static inline double separation(const double *xa, const double *xb,
                                double e[3]) {
  double r2 = 0.0;
  for (int c = 0; c < 3; ++c) {
    e[c] = xa[c] - xb[c];
    r2 += e[c] * e[c];
  }
  return r2;
}

/* the spring of a pair at separation e (r2 = |e|^2) onto f: contact
 * distance half the sum of spacings, the moduli's harmonic mean, the mean
 * area */
static inline void pair_force(double kappa, const double e[3], double r2,
                              double spacings, double Ma, double Mb,
                              double areas, double f[3]) {
  double r = sqrt(r2), rc = 0.5 * spacings;
  if (!(r < rc) || r == 0.0)
    return;
  double M = 2.0 * Ma * Mb / (Ma + Mb);
  double A = 0.5 * areas;
  double mag = kappa * M * A * (rc - r) / (rc * r);
  for (int c = 0; c < 3; ++c)
    f[c] += mag * e[c];
}

/* the boxes of the bodies at positions x of points [0, n) (over MPI ranks
 * with fixed ghosts, of every rank's owned particles) */
static void body_boxes(contact *ct, const double *x, const int32_t *body,
                       size_t n) {
  for (int b = 0; b < ct->nbodies; ++b)
    for (int c = 0; c < 3; ++c) {
      ct->box[6 * b + c] = INFINITY;
      ct->box[6 * b + 3 + c] = -INFINITY;
    }
  for (size_t a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c) {
      double *bx = ct->box + 6 * body[a];
      bx[c] = fmin(bx[c], x[3 * a + c]);
      bx[3 + c] = fmax(bx[3 + c], x[3 * a + c]);
    }
  for (int b = 0; ct->ranks && b < ct->nbodies; ++b)
    sph_domain_minmax(ct->ranks, ct->box + 6 * b, ct->box + 6 * b + 3, 3);
}

/* room for m candidates (grown only, amortised; each array stays as it
 * was when its growth fails) */
static sph_status candidates_room(contact *ct, size_t m, sph_error *err) {
  if (m <= ct->cap)
    return SPH_OK;
  size_t cap = 2 * m;
  size_t *cand = realloc(ct->cand, cap * sizeof *cand);
  ct->cand = cand ? cand : ct->cand;
  double *xc = realloc(ct->xc, 3 * cap * sizeof *xc);
  ct->xc = xc ? xc : ct->xc;
  int32_t *bc = realloc(ct->bc, cap * sizeof *bc);
  ct->bc = bc ? bc : ct->bc;
  int64_t *keyc = realloc(ct->keyc, cap * sizeof *keyc);
  ct->keyc = keyc ? keyc : ct->keyc;
  double *sc = realloc(ct->sc, cap * sizeof *sc);
  ct->sc = sc ? sc : ct->sc;
  double *mc = realloc(ct->mc, cap * sizeof *mc);
  ct->mc = mc ? mc : ct->mc;
  double *ac = realloc(ct->ac, cap * sizeof *ac);
  ct->ac = ac ? ac : ct->ac;
  if (!cand || !xc || !bc || !keyc || !sc || !mc || !ac)
    return sph_error_set(err, SPH_ERR_NOMEM, "contact candidates");
  ct->cap = cap;
  return SPH_OK;
}

/* over MPI ranks with fixed ghosts: the owned particles near another body
 * and the other ranks' within the contact radius of them, their pair
 * forces into dp (owned ones) */
static sph_status between_ranks(contact *ct, const sph_sim *sim,
                                sph_stage *stage, sph_error *err) {
  const double *x = stage->x;
  const int32_t *body = sim->ps->body;
  const int64_t *gidx = sph_domain_storage_index(ct->ranks);
  body_boxes(ct, x, body, ct->n);
  size_t nc = 0;
  for (size_t a = 0; a < ct->n; ++a)
    if (near_other_body(ct, x + 3 * a, body[a], ct->radius)) {
      double *r = ct->rows + (size_t)ROW_W * nc++;
      memcpy(r, x + 3 * a, 3 * sizeof *r);
      r[ROW_BODY] = body[a];
      r[ROW_KEY] = (double)gidx[a];
      r[ROW_SPACING] = ct->spacing[a];
      r[ROW_MODULUS] = ct->modulus[a];
      r[ROW_AREA] = ct->area[a];
      ct->cand[nc - 1] = a;
    }
  size_t m = 0;
  SPH_TRY(sph_domain_box_points(ct->ranks, ct->rows, nc, ROW_W, ct->radius,
                                &ct->near, &ct->near_cap, &m, err));
  sph_status st = candidates_room(ct, nc + m, err);
  SPH_TRY(sph_domain_agree(ct->ranks, st, err));
  for (size_t i = 0; i < nc + m; ++i) {
    const double *r =
        i < nc ? ct->rows + (size_t)ROW_W * i : ct->near + ROW_W * (i - nc);
    memcpy(ct->xc + 3 * i, r, 3 * sizeof *r);
    ct->bc[i] = (int32_t)r[ROW_BODY];
    ct->keyc[i] = (int64_t)r[ROW_KEY];
    ct->sc[i] = r[ROW_SPACING];
    ct->mc[i] = r[ROW_MODULUS];
    ct->ac[i] = r[ROW_AREA];
  }
  st = nc + m < 2
           ? SPH_OK
           : sph_neighbors_build(ct->nl, ct->xc, nc + m, ct->dim, ct->radius,
                                 ct->bc, SPH_PAIRS_OTHER_BODY, err);
  SPH_TRY(sph_domain_agree(ct->ranks, st, err));
  if (nc == 0 || nc + m < 2)
    return SPH_OK;
  const sph_neighbors *nl = ct->nl;
  sph_domain_sort_lists_by(ct->nl, nc, ct->keyc);
  const double kappa = ct->kappa, *xc = ct->xc;
  double *dp = stage->dp;
#pragma omp parallel for schedule(static)
  for (size_t i = 0; i < nc; ++i) {
    double f[3] = {0, 0, 0};
    for (size_t s = nl->offset[i]; s < nl->offset[i + 1]; ++s) {
      size_t j = (size_t)nl->index[s];
      double e[3], r2 = separation(xc + 3 * i, xc + 3 * j, e);
      pair_force(kappa, e, r2, ct->sc[i] + ct->sc[j], ct->mc[i], ct->mc[j],
                 ct->ac[i] + ct->ac[j], f);
    }
    size_t a = ct->cand[i];
    for (int c = 0; c < 3; ++c)
      dp[3 * a + c] += ct->inv_mass[a] * f[c];
  }
  return SPH_OK;
}

/* the pair forces of particles near another body, into dp (owned ones) */
static sph_status between_bodies(contact *ct, const sph_sim *sim,
                                 sph_stage *stage, sph_error *err) {
  const double *x = stage->x;
  const int32_t *body = sim->ps->body;
  if (ct->dom)
    SPH_TRY(ghosts_cover(ct, x, err));
  body_boxes(ct, x, body, ct->ne);
  size_t nc = 0;
  for (size_t a = 0; a < ct->ne; ++a)
    if (near_other_body(ct, x + 3 * a, body[a], ct->radius)) {
      ct->cand[nc] = a;
      memcpy(ct->xc + 3 * nc, x + 3 * a, 3 * sizeof *x);
      ct->bc[nc++] = body[a];
    }
  /* a search failing on one rank (positions no longer finite) fails on
   * all, or the others would wait in the next exchange */
  sph_status st =
      nc < 2 ? SPH_OK
             : sph_neighbors_build(ct->nl, ct->xc, nc, ct->dim, ct->radius,
                                   ct->bc, SPH_PAIRS_OTHER_BODY, err);
  SPH_TRY(sph_domain_agree(ct->dom, st, err));
  if (nc < 2)
    return SPH_OK;
  const sph_neighbors *nl = ct->nl;
  /* the lists name particles, in the serial run's order over ranks */
  for (size_t s = 0; s < nl->count; ++s)
    nl->index[s] = (int32_t)ct->cand[nl->index[s]];
  sph_domain_sort_lists(ct->dom, ct->nl, nc);
  const double kappa = ct->kappa;
  double *dp = stage->dp;
#pragma omp parallel for schedule(static)
  for (size_t i = 0; i < nc; ++i) {
    size_t a = ct->cand[i];
    if (a >= ct->n) /* a ghost: its owner adds its force */
      continue;
    double f[3] = {0, 0, 0};
    for (size_t s = nl->offset[i]; s < nl->offset[i + 1]; ++s) {
      size_t b = (size_t)nl->index[s];
      double e[3], r2 = separation(x + 3 * a, x + 3 * b, e);
      pair_force(kappa, e, r2, ct->spacing[a] + ct->spacing[b], ct->modulus[a],
                 ct->modulus[b], ct->area[a] + ct->area[b], f);
    }
    for (int c = 0; c < 3; ++c)
      dp[3 * a + c] += ct->inv_mass[a] * f[c];
  }
  return SPH_OK;
}

static sph_status contact_rates(sph_term *term, sph_sim *sim, sph_stage *stage,
                                sph_error *err) {
  contact *ct = term->data;
  const sph_contact *spec = ct->spec;
  const double *x = stage->x;
  double *dp = stage->dp;
  const double t = stage->t, kappa = ct->kappa;
  const int dim = ct->dim;
  if (spec->nwalls) {
#pragma omp parallel for schedule(static)
    for (size_t a = 0; a < ct->n; ++a) {
      double rc = 0.5 * ct->spacing[a];
      for (size_t w = 0; w < spec->nwalls; ++w) {
        double nrm[3],
            g = sph_wall_distance(&spec->walls[w], t, dim, x + 3 * a, nrm);
        if (!(g < rc))
          continue;
        double mag = kappa * ct->modulus[a] * ct->area[a] * (rc - g) / rc;
        for (int c = 0; c < 3; ++c)
          dp[3 * a + c] += ct->inv_mass[a] * mag * nrm[c];
      }
    }
  }
  if (ct->ranks)
    SPH_TRY(between_ranks(ct, sim, stage, err));
  else if (ct->between)
    SPH_TRY(between_bodies(ct, sim, stage, err));
  return SPH_OK;
}

static double contact_stable_dt(sph_term *term, const sph_sim *sim) {
  (void)sim;
  return ((contact *)term->data)->dt_bound;
}

/* a particle's spring: the material and body values of points [0, ne) */
static void particle_constants(contact *ct, const sph_sim *sim) {
  const sph_scene *s = sim->scene;
  const sph_particles *ps = sim->ps;
  const double *V0 = ps->field[SPH_FIELD_VOLUME0];
  for (size_t a = 0; a < ct->ne; ++a) {
    const sph_body *b = &s->bodies[ps->body[a]];
    const sph_material *mat = &s->materials[b->material];
    ct->spacing[a] = b->spacing;
    ct->modulus[a] = mat->lambda + 2.0 * mat->mu;
    ct->area[a] = V0[a] / b->spacing;
    ct->inv_mass[a] =
        ct->per_volume ? 1.0 / V0[a] : 1.0 / (mat->density * V0[a]);
  }
}

/* the owned particles and ghosts after a rebuild of the dynamic domain */
static void take_points(contact *ct, const sph_sim *sim) {
  ct->n = ct->ne = sim->ps->n;
  if (!ct->dom)
    return;
  ct->ne += sph_domain_ghosts(ct->dom);
  memcpy(ct->x_found, sim->ps->field[SPH_FIELD_POSITION],
         3 * ct->ne * sizeof *ct->x_found);
}

static sph_status contact_renumber(sph_term *term, sph_sim *sim,
                                   sph_error *err) {
  (void)err;
  contact *ct = term->data;
  take_points(ct, sim);
  particle_constants(ct, sim);
  return SPH_OK;
}

static void contact_destroy(sph_term *term) {
  contact *ct = term->data;
  if (!ct)
    return;
  free(ct->inv_mass);
  free(ct->modulus);
  free(ct->area);
  free(ct->spacing);
  free(ct->box);
  free(ct->cand);
  free(ct->xc);
  free(ct->bc);
  free(ct->x_found);
  free(ct->rows);
  free(ct->near);
  free(ct->keyc);
  free(ct->sc);
  free(ct->mc);
  free(ct->ac);
  sph_neighbors_destroy(ct->nl);
  free(ct);
}

const sph_term_ops contact_term_ops = {
    .name = "contact",
    .reference = "seed 001 sec. 2.4.2-2.4.3 (frictionless contact, penalty)",
    .distributed = 1,
    .rates = contact_rates,
    .stable_dt = contact_stable_dt,
    .renumber = contact_renumber,
    .destroy = contact_destroy,
};

sph_status contact_create(sph_sim *sim, const double *rho0, sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_particles *ps = sim->ps;
  /* room for every particle a rank may hold after migrations */
  const size_t cap = sph_domain_capacity(sim->domain, ps), nn = cap ? cap : 1;
  contact *ct = calloc(1, sizeof *ct);
  sph_term t = {.data = ct};
  if (!ct)
    return sph_error_set(err, SPH_ERR_NOMEM, "contact");
  ct->dim = s->dimension;
  ct->spec = &s->contact;
  ct->kappa = s->contact.stiffness;
  ct->per_volume = rho0 != NULL;
  ct->between = s->contact.between_bodies;
  ct->nbodies = (int)s->nbodies;
  /* the dynamic domain's ghosts follow the bodies, fixed ones do not */
  if (ct->between && sim->domain &&
      sim->method->distributed == SPH_DISTRIBUTED_DYNAMIC)
    ct->dom = sim->domain;
  else if (ct->between && sim->domain)
    ct->ranks = sim->domain;
  ct->inv_mass = malloc(nn * sizeof *ct->inv_mass);
  ct->modulus = malloc(nn * sizeof *ct->modulus);
  ct->area = malloc(nn * sizeof *ct->area);
  ct->spacing = malloc(nn * sizeof *ct->spacing);
  ct->x_found = ct->dom ? malloc(3 * nn * sizeof *ct->x_found) : NULL;
  sph_status st = SPH_OK;
  if (!ct->inv_mass || !ct->modulus || !ct->area || !ct->spacing ||
      (ct->dom && !ct->x_found))
    st = sph_error_set(err, SPH_ERR_NOMEM, "contact");
  st = sph_domain_agree(sim->domain, st, err);
  if (st != SPH_OK) {
    contact_destroy(&t);
    return st;
  }
  take_points(ct, sim);
  particle_constants(ct, sim);
  /* the contact spring of a particle (at most about four springs' worth
   * between bodies, two on a wall) stays below 1 / dt, over every rank */
  double omega2 = 0.0;
  for (size_t a = 0; a < ct->n; ++a) {
    double k =
        ct->kappa * ct->modulus[a] * ct->area[a] / (0.5 * ct->spacing[a]);
    double mass = s->materials[s->bodies[ps->body[a]].material].density *
                  ps->field[SPH_FIELD_VOLUME0][a];
    omega2 = fmax(omega2, 2.0 * k / mass);
  }
  omega2 = sph_domain_max(sim->domain, omega2);
  ct->dt_bound = omega2 > 0.0 ? 1.0 / sqrt(omega2) : INFINITY;
  if (ct->between) {
    for (size_t k = 0; k < s->nbodies; ++k)
      ct->radius = fmax(ct->radius, s->bodies[k].spacing);
    /* a ghost is within a support of an owned particle at the rebuild */
    ct->slack = 0.5 * (sim->kernel.support - ct->radius);
    ct->box = malloc(6 * s->nbodies * sizeof *ct->box);
    ct->cand = malloc(nn * sizeof *ct->cand);
    ct->xc = malloc(3 * nn * sizeof *ct->xc);
    ct->bc = malloc(nn * sizeof *ct->bc);
    ct->cap = nn;
    if (ct->ranks) {
      ct->rows = malloc((size_t)ROW_W * nn * sizeof *ct->rows);
      ct->keyc = malloc(nn * sizeof *ct->keyc);
      ct->sc = malloc(nn * sizeof *ct->sc);
      ct->mc = malloc(nn * sizeof *ct->mc);
      ct->ac = malloc(nn * sizeof *ct->ac);
    }
    st = !ct->box || !ct->cand || !ct->xc || !ct->bc ||
                 (ct->ranks &&
                  (!ct->rows || !ct->keyc || !ct->sc || !ct->mc || !ct->ac))
             ? sph_error_set(err, SPH_ERR_NOMEM, "contact")
             : sph_neighbors_create(&ct->nl, err);
    /* room for the searches of the time steps, made here: every pair of
     * the reference set within 1.5 contact distances (a contact lists
     * only surface particles' pairs within one) */
    if (st == SPH_OK)
      st = sph_neighbors_build(ct->nl, ps->field[SPH_FIELD_POSITION0], ct->ne,
                               ct->dim, 1.5 * ct->radius, NULL, SPH_PAIRS_ALL,
                               err);
    if (st == SPH_OK && ct->dom && !(ct->slack > 0.0))
      st = sph_error_at(err, SPH_ERR_UNSUPPORTED, s->path, s->contact.line,
                        s->contact.col, "contact",
                        "contact between bodies over MPI ranks needs a "
                        "kernel support wider than the largest spacing");
    st = sph_domain_agree(sim->domain, st, err);
    if (st != SPH_OK) {
      contact_destroy(&t);
      return st;
    }
  }
  st = sph_sim_add_term(sim, &contact_term_ops, ct, err);
  if (st != SPH_OK)
    contact_destroy(&t);
  return st;
}
