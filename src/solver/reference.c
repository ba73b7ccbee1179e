/* Reference solutions (see include/sph/reference.h): the swinging cube of
 * seed 000 sec. 8.2 eq. 52, the swinging plate of seed 004 sec. 5.1 eq. 42-43,
 * and a measured period against a scalar value.
 *
 * Eq. 52 for any amplitudes (A1, A2, A3) = (A, B, C): with a = pi/2 and
 * u_i = A_i f_i(X) g(t), f = (sin cos cos, cos sin cos, cos cos sin)(a X),
 * lap f_i = -3 a^2 f_i and grad(div u)_i = -a^2 (A1 + A2 + A3) f_i g, so
 * rho u'' = (lambda + mu) grad div u + mu lap u reads, per component,
 * rho w^2 A_i = a^2 ((lambda + mu) sum_k A_k + 3 mu A_i).
 * One frequency serves all three components only for A_i = m (dilatational,
 * w_d = sqrt(3) a c_d) or sum_k A_k = 0 (shear, w_s = sqrt(3) a c_s); every
 * mode is the sum of its mean part m = (A + B + C)/3 at w_d and its zero-sum
 * part A_i - m at w_s. Both parts meet the symmetry (X_i = 0) and
 * skew-symmetry (X_i = 1) planes. */
#include "solver/reference.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"
#include "parallel/domain.h"
#include "solver/reference_gauss.h"

typedef enum { REF_SWINGING_CUBE, REF_SWINGING_PLATE, REF_PERIOD } ref_kind;

/* the period observer's state, kept as doubles for checkpoints */
enum { OBS_U, OBS_T, OBS_SIGN, OBS_CROSSINGS, OBS_FIRST, OBS_LAST, OBS_N };

struct sph_reference {
  ref_kind kind;
  /* period: probe position, displacement component, reference value */
  double at[3];
  int component;
  double value, tolerance;
  int64_t key; /* the observed particle's storage index */
  size_t slot; /* where this rank last found it */
  double obs[OBS_N];
  /* swinging cube */
  double U0, A[3];
  double Ad[3], As[3]; /* dilatational and shear parts of A */
  double omega_d;      /* sqrt(3)/2 c_d pi */
  double omega_s;      /* sqrt(3)/2 c_s pi */
  double lambda, mu;   /* small strain moduli of the body */
  double P_amp, v_amp; /* normalisations */
  int from_rest;       /* u = U0 sin(w t) f: zero displacement at t = 0 */
  int gauss;           /* norm: gauss, seed 004 eq. 44-45 beside the nodal */
  sph_gauss_norm *gn;  /* its particle table (rank 0), made at set-up */
  double t_exact;      /* the time the Gauss norm's exact field is taken at */
};

/* a mode of amplitudes A at U0 = 1: f_i = A_i f_i(X), G_ij = d f_i / d X_j */
static void mode(const double A[3], const double X[3], double f[3],
                 double G[9]) {
  double s[3], c[3], h = M_PI / 2;
  for (int k = 0; k < 3; ++k) {
    s[k] = sin(h * X[k]);
    c[k] = cos(h * X[k]);
  }
  for (int i = 0; i < 3; ++i) {
    double v = A[i];
    for (int k = 0; k < 3; ++k)
      v *= k == i ? s[k] : c[k];
    f[i] = v;
    for (int j = 0; j < 3; ++j) {
      double d = A[i] * h;
      for (int k = 0; k < 3; ++k)
        d *= k == j ? (k == i ? c[k] : -s[k]) : (k == i ? s[k] : c[k]);
      G[3 * i + j] = d;
    }
  }
}

/* the exact displacement, velocity and displacement gradient at (X, t):
 * each part is f cos(w t) (the cube, released from rest deformed) or
 * f sin(w t) (the plate, set moving from the undeformed state) */
static void exact(const sph_reference *r, const double X[3], double t,
                  double u[3], double v[3], double G[9]) {
  double fd[3], Gd[9], fs[3], Gs[9];
  mode(r->Ad, X, fd, Gd);
  mode(r->As, X, fs, Gs);
  double pd = r->omega_d * t, ps = r->omega_s * t;
  /* displacement factors and their time derivatives */
  double ud = cos(pd), us = cos(ps);
  double vd = -r->omega_d * sin(pd), vs = -r->omega_s * sin(ps);
  if (r->from_rest) {
    ud = sin(pd);
    us = sin(ps);
    vd = r->omega_d * cos(pd);
    vs = r->omega_s * cos(ps);
  }
  for (int i = 0; i < 3; ++i) {
    u[i] = r->U0 * (ud * fd[i] + us * fs[i]);
    v[i] = r->U0 * (vd * fd[i] + vs * fs[i]);
  }
  for (int k = 0; k < 9; ++k)
    G[k] = r->U0 * (ud * Gd[k] + us * Gs[k]);
}

/* small strain stress of a displacement gradient */
static void stress(const sph_reference *r, const double G[9], double P[9]) {
  double tr = G[0] + G[4] + G[8];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      P[3 * i + j] =
          r->mu * (G[3 * i + j] + G[3 * j + i]) + (i == j) * r->lambda * tr;
}

/* reference: {period: {at: [x, y, (z)], component: x|y|z}, value: T,
 *             tolerance: tol} */
static sph_status period_create(sph_reference *r, const sph_scene *s,
                                sph_node *n, sph_error *err) {
  static const char *const keys[] = {"period", "value", "tolerance", NULL};
  static const char *const pkeys[] = {"at", "component", NULL};
  static const char *const axes[] = {"x", "y", "z", NULL};
  SPH_TRY(sph_node_check_keys(n, keys, err));
  sph_node *p;
  SPH_TRY(sph_node_get_map(n, "period", 1, &p, err));
  SPH_TRY(sph_node_check_keys(p, pkeys, err));
  SPH_TRY(
      sph_node_get_doubles(p, "at", 1, (size_t)s->dimension, r->at, NULL, err));
  SPH_TRY(sph_node_get_choice(p, "component", axes, "y", &r->component, err));
  if (r->component >= s->dimension)
    return sph_node_error(sph_node_child(p, "component"), err, SPH_ERR_RANGE,
                          "component %s of a %dD scene", axes[r->component],
                          s->dimension);
  SPH_TRY(sph_node_get_double(n, "value", 1, 0.0, &r->value, err));
  SPH_TRY(sph_node_get_double(n, "tolerance", 0, NAN, &r->tolerance, err));
  if (!(r->value > 0.0))
    return sph_node_error(sph_node_child(n, "value"), err, SPH_ERR_RANGE,
                          "a period must be positive");
  r->kind = REF_PERIOD;
  return SPH_OK;
}

static sph_status swinging_cube_create(sph_reference *r, const sph_scene *s,
                                       sph_node *n, sph_error *err) {
  static const char *const keys[] = {"analytic", "U0", "A", "B", "C", NULL};
  SPH_TRY(sph_node_check_keys(n, keys, err));
  if (s->dimension != 3 || s->nbodies != 1)
    return sph_node_error(n, err, SPH_ERR_ARG,
                          "swinging_cube needs one body in 3D");
  if (s->bodies[0].transform.given)
    return sph_node_error(n, err, SPH_ERR_ARG,
                          "swinging_cube is given in the world frame: the "
                          "body cannot have a transform");
  SPH_TRY(sph_node_get_double(n, "U0", 0, 5e-4, &r->U0, err));
  static const char *const amp[] = {"A", "B", "C"};
  for (int i = 0; i < 3; ++i)
    SPH_TRY(sph_node_get_double(n, amp[i], 0, 1.0, &r->A[i], err));
  const sph_material *m = &s->materials[s->bodies[0].material];
  r->lambda = m->lambda;
  r->mu = m->mu;
  r->omega_d = sqrt(3.0) / 2.0 * sph_material_wave_speed(m) * M_PI;
  r->omega_s = sqrt(3.0) / 2.0 * sqrt(m->mu / m->density) * M_PI;
  const double mean = (r->A[0] + r->A[1] + r->A[2]) / 3.0;
  r->v_amp = 0.0;
  for (int i = 0; i < 3; ++i) {
    r->Ad[i] = mean;
    r->As[i] = r->A[i] - mean;
    r->v_amp = fmax(r->v_amp, r->U0 * (r->omega_d * fabs(r->Ad[i]) +
                                       r->omega_s * fabs(r->As[i])));
  }
  r->kind = REF_SWINGING_CUBE;
  return SPH_OK;
}

/* reference: {analytic: swinging_plate, U: 0.01} on [0, 2]^2 (seed 004
 * eq. 42-43): the zero-sum mode A = (-1, 1) of the cube in the plane,
 * w = (pi / 2) sqrt(2 mu / rho) */
static sph_status swinging_plate_create(sph_reference *r, const sph_scene *s,
                                        sph_node *n, sph_error *err) {
  static const char *const keys[] = {"analytic", "U", "norm", NULL};
  static const char *const norms[] = {"nodal", "gauss", NULL};
  SPH_TRY(sph_node_check_keys(n, keys, err));
  /* absent: nodal, left out of the resolved scene (scene_used.yaml as
   * before the option) */
  if (sph_node_child(n, "norm"))
    SPH_TRY(sph_node_get_choice(n, "norm", norms, "nodal", &r->gauss, err));
  if (s->dimension != 2 || s->nbodies != 1)
    return sph_node_error(n, err, SPH_ERR_ARG,
                          "swinging_plate needs one body in 2D");
  if (s->bodies[0].transform.given)
    return sph_node_error(n, err, SPH_ERR_ARG,
                          "swinging_plate is given in the world frame: the "
                          "body cannot have a transform");
  SPH_TRY(sph_node_get_double(n, "U", 0, 0.01, &r->U0, err));
  if (!(r->U0 > 0.0) || !isfinite(r->U0))
    return sph_node_error(sph_node_child(n, "U"), err, SPH_ERR_RANGE,
                          "U must be a positive amplitude");
  const sph_material *m = &s->materials[s->bodies[0].material];
  r->lambda = m->lambda;
  r->mu = m->mu;
  r->As[0] = -1.0;
  r->As[1] = 1.0;
  r->omega_s = M_PI / 2.0 * sqrt(2.0 * m->mu / m->density);
  r->v_amp = r->U0 * r->omega_s;
  r->from_rest = 1;
  r->kind = REF_SWINGING_PLATE;
  return SPH_OK;
}

static sph_status analytic_create(sph_reference *r, const sph_scene *s,
                                  sph_node *n, sph_error *err) {
  const char *kind;
  SPH_TRY(sph_node_get_string(n, "analytic", 1, NULL, &kind, err));
  if (!strcmp(kind, "swinging_plate"))
    return swinging_plate_create(r, s, n, err);
  if (strcmp(kind, "swinging_cube"))
    return sph_node_error(sph_node_child(n, "analytic"), err, SPH_ERR_RANGE,
                          "unknown reference '%s' (known: swinging_cube, "
                          "swinging_plate)",
                          kind);
  return swinging_cube_create(r, s, n, err);
}

sph_status sph_reference_create(sph_reference **out, const sph_scene *s,
                                sph_error *err) {
  *out = NULL;
  sph_node *n = s->reference;
  if (!n)
    return SPH_OK;
  sph_reference *r = calloc(1, sizeof *r);
  if (!r)
    return sph_error_set(err, SPH_ERR_NOMEM, "reference");
  sph_status st = sph_node_child(n, "period") ? period_create(r, s, n, err)
                                              : analytic_create(r, s, n, err);
  if (st != SPH_OK) {
    free(r);
    return st;
  }
  *out = r;
  return SPH_OK;
}

void sph_reference_destroy(sph_reference *r) {
  if (r)
    sph_gauss_norm_destroy(r->gn);
  free(r);
}

/* the Gauss norm's table on rank 0: one row a particle in storage order
 * (seed 004: 10 x 10 tiles of [0, 2]^2, 5 x 5 points each) */
static sph_status gauss_create(sph_reference *r, const sph_sim *sim,
                               sph_error *err) {
  sph_status st = SPH_OK;
  if (sph_domain_rank(sim->domain) == 0) {
    const double lo[3] = {0.0, 0.0, 0.0}, hi[3] = {2.0, 2.0, 0.0};
    size_t N = sph_domain_particles(sim->domain, sim->ps);
    st = sph_gauss_norm_create(&r->gn, &sim->kernel, lo, hi, 10, 5, N, err);
  }
  return sph_domain_agree(sim->domain, st, err);
}

sph_status sph_reference_initialise(const sph_reference *r, sph_sim *sim,
                                    sph_error *err) {
  sph_particles *ps = sim->ps;
  sph_reference *rw = (sph_reference *)r; /* amplitude found on the set */
  if (r->kind == REF_PERIOD) {
    memset(rw->obs, 0, sizeof rw->obs);
    /* the particle nearest to `at` in the reference configuration, ties
     * to the first in storage order (over MPI ranks: of every rank's) */
    const int64_t *g = sph_domain_storage_index(sim->domain);
    double best = INFINITY, key = INFINITY;
    for (size_t a = 0; a < ps->n; ++a) {
      const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * a;
      double d = 0.0, k = g ? (double)g[a] : (double)a;
      for (int c = 0; c < 3; ++c)
        d += (X[c] - r->at[c]) * (X[c] - r->at[c]);
      if (d < best || (d == best && k < key)) {
        best = d;
        key = k;
      }
    }
    double dmin = sph_domain_min(sim->domain, best);
    rw->key =
        (int64_t)sph_domain_min(sim->domain, best == dmin ? key : INFINITY);
    rw->slot = SIZE_MAX;
    return SPH_OK;
  }
  /* over MPI ranks each rank sets its owned particles' state */
  SPH_TRY(sph_particles_require(ps, SPH_FIELD_DEFGRAD, err));
  SPH_TRY(sph_particles_require(ps, SPH_FIELD_POSITION, err));
  rw->P_amp = 0.0;
  sph_status st = SPH_OK;
  for (size_t a = 0; st == SPH_OK && a < ps->n; ++a) {
    double u[3], v[3], G[9], P[9];
    const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * a;
    exact(r, X, 0.0, u, v, G);
    double *F = ps->field[SPH_FIELD_DEFGRAD] + 9 * a;
    for (int k = 0; k < 9; ++k)
      F[k] = (k % 4 == 0) + G[k];
    for (int c = 0; c < 3; ++c) {
      ps->field[SPH_FIELD_POSITION][3 * a + c] = X[c] + u[c];
      ps->field[SPH_FIELD_VELOCITY][3 * a + c] = v[c];
    }
    /* the stress amplitude: both parts at their extremes */
    double f[3], Gd[9], Gs[9], Ga[9];
    mode(r->Ad, X, f, Gd);
    mode(r->As, X, f, Gs);
    for (int k = 0; k < 9; ++k)
      Ga[k] = r->U0 * (Gd[k] + Gs[k]);
    stress(r, Ga, P);
    rw->P_amp = fmax(rw->P_amp, sqrt(sph_mat3_ddot(P, P)));
    /* an initial state the material can have: finite, not inverted */
    double J = sph_mat3_det(F);
    if (!(J > 0.0) || !isfinite(J) || !isfinite(rw->P_amp) ||
        !isfinite(v[0] + v[1] + v[2]) || !isfinite(u[0] + u[1] + u[2])) {
      const sph_node *ref = sim->scene->reference;
      st = sph_node_error(
          ref ? ref : sim->scene->root, err, SPH_ERR_RANGE,
          "the analytic initial state is %s at particle %zu (J = %g): "
          "a smaller amplitude",
          isfinite(J) && isfinite(rw->P_amp) ? "inverted" : "not finite", a, J);
    }
  }
  /* every rank learns of a failure; the amplitude is a maximum, exact */
  SPH_TRY(sph_domain_agree(sim->domain, st, err));
  rw->P_amp = sph_domain_max(sim->domain, rw->P_amp);
  sim->initial_defgrad = 1;
  if (r->gauss && !r->gn)
    SPH_TRY(gauss_create(rw, sim, err));
  return SPH_OK;
}

void sph_reference_observe(sph_reference *r, const sph_frame *fr) {
  if (r->kind != REF_PERIOD)
    return;
  const sph_particles *ps = fr->ps;
  sph_domain *dom = fr->sim->domain;
  const int64_t *g = sph_domain_storage_index(dom);
  /* the observed particle, where this rank last had it or found again */
  size_t a = r->slot;
  if (!(a < ps->n && (g ? g[a] : (int64_t)a) == r->key))
    for (a = 0; a < ps->n && (g ? g[a] : (int64_t)a) != r->key; ++a)
      ;
  r->slot = a;
  int c = r->component;
  /* its owner's displacement, zeros from the others: the sum is exact */
  double u = a < ps->n ? ps->field[SPH_FIELD_POSITION][3 * a + c] -
                             ps->field[SPH_FIELD_POSITION0][3 * a + c]
                       : 0.0;
  sph_domain_sum(dom, &u, 1);
  double *o = r->obs, sign = u > 0.0 ? 1.0 : u < 0.0 ? -1.0 : 0.0;
  /* a zero crossing between the previous sample and this one */
  if (sign != 0.0 && o[OBS_SIGN] != 0.0 && sign != o[OBS_SIGN]) {
    double tc = o[OBS_T] + (fr->time - o[OBS_T]) * o[OBS_U] / (o[OBS_U] - u);
    if (o[OBS_CROSSINGS] == 0.0)
      o[OBS_FIRST] = tc;
    o[OBS_LAST] = tc;
    o[OBS_CROSSINGS] += 1.0;
  }
  if (sign != 0.0)
    o[OBS_SIGN] = sign;
  o[OBS_U] = u;
  o[OBS_T] = fr->time;
}

int sph_reference_state(sph_reference *r, sph_state_array *arr) {
  if (!r || r->kind != REF_PERIOD)
    return 0;
  *arr = (sph_state_array){.name = "reference", .data = r->obs, .len = OBS_N};
  return 1;
}

/* a particle's row for the errors: V, X, v, u, P, F */
enum {
  ROW_V = 0,
  ROW_X = 1,
  ROW_VEL = 4,
  ROW_U = 7,
  ROW_P = 10,
  ROW_F = 19,
  ROW_W = 28
};

static void error_row(const sph_particles *ps, size_t a, double *row) {
  row[ROW_V] = ps->field[SPH_FIELD_VOLUME0][a];
  memcpy(row + ROW_X, ps->field[SPH_FIELD_POSITION0] + 3 * a, 3 * sizeof *row);
  memcpy(row + ROW_VEL, ps->field[SPH_FIELD_VELOCITY] + 3 * a, 3 * sizeof *row);
  memcpy(row + ROW_U, ps->field[SPH_FIELD_DISPLACEMENT] + 3 * a,
         3 * sizeof *row);
  memcpy(row + ROW_P, ps->field[SPH_FIELD_PK1] + 9 * a, 9 * sizeof *row);
  memcpy(row + ROW_F, ps->field[SPH_FIELD_DEFGRAD] + 9 * a, 9 * sizeof *row);
}

/* one particle's terms added to the sums sv, ev, eP, eu, eg */
static void error_add(const sph_reference *r, double t, const double *row,
                      double s[5]) {
  double uex[3], vex[3], G[9], P[9];
  const double V = row[ROW_V];
  exact(r, row + ROW_X, t, uex, vex, G);
  stress(r, G, P);
  const double *v = row + ROW_VEL, *u = row + ROW_U, *Pn = row + ROW_P,
               *Fn = row + ROW_F;
  for (int i = 0; i < 3; ++i) {
    s[1] += V * (v[i] - vex[i]) * (v[i] - vex[i]);
    s[3] += V * (u[i] - uex[i]) * (u[i] - uex[i]);
  }
  for (int k = 0; k < 9; ++k) {
    double dG = Fn[k] - (k % 4 == 0) - G[k]; /* grad u_h = F - I */
    s[2] += V * (Pn[k] - P[k]) * (Pn[k] - P[k]);
    s[4] += V * dG * dG;
  }
  s[0] += V;
}

/* the exact displacement and its gradient for the Gauss norm */
static void gauss_exact(const void *ctx, const double X[3], double u[3],
                        double G[9]) {
  const sph_reference *r = ctx;
  double v[3];
  exact(r, X, r->t_exact, u, v, G);
}

typedef struct {
  int64_t key;
  size_t a;
} keyed;

static int cmp_keyed(const void *pa, const void *pb) {
  int64_t a = ((const keyed *)pa)->key, b = ((const keyed *)pb)->key;
  return (a > b) - (a < b);
}

/* the sums over every particle in storage order: over MPI ranks rank 0
 * adds the rows of a range of storage indices at a time, received from
 * their owners, so the sums have the serial bits */
static sph_status error_sums(const sph_reference *r, const sph_sim *sim,
                             double s[5], sph_error *err) {
  enum { RANGE = 1 << 13 };
  const sph_particles *ps = sim->ps;
  sph_domain *d = sim->domain;
  const int64_t *g = sph_domain_storage_index(d);
  size_t n = ps->n, N = sph_domain_particles(d, ps);
  int root = sph_domain_rank(d) == 0;
  keyed *order = malloc((n ? n : 1) * sizeof *order);
  int64_t *keys = malloc(RANGE * sizeof *keys);
  double *rows = malloc((size_t)RANGE * ROW_W * sizeof *rows);
  double *got = root ? malloc((size_t)RANGE * ROW_W * sizeof *got) : NULL;
  sph_status st = !order || !keys || !rows || (root && !got)
                      ? sph_error_set(err, SPH_ERR_NOMEM, "reference errors")
                      : SPH_OK;
  st = sph_domain_agree(d, st, err);
  for (size_t a = 0; st == SPH_OK && a < n; ++a)
    order[a] = (keyed){g ? g[a] : (int64_t)a, a};
  if (st == SPH_OK && g)
    qsort(order, n, sizeof *order, cmp_keyed);
  size_t next = 0;
  for (size_t lo = 0; st == SPH_OK && lo < N; lo += RANGE) {
    size_t m = N - lo < RANGE ? N - lo : RANGE, k = 0;
    for (; next < n && order[next].key < (int64_t)(lo + m); ++next, ++k) {
      keys[k] = order[next].key;
      error_row(ps, order[next].a, rows + (size_t)ROW_W * k);
    }
    st = sph_domain_gather_range(d, keys, rows, k, ROW_W, (int64_t)lo, m, got,
                                 err);
    for (size_t i = 0; st == SPH_OK && root && i < m; ++i) {
      const double *row = got + (size_t)ROW_W * i;
      error_add(r, sim->t, row, s);
      if (r->gn) {
        double *gr = sph_gauss_norm_table(r->gn) + SPH_GAUSS_ROW * (lo + i);
        memcpy(gr + SPH_GAUSS_X, row + ROW_X, 3 * sizeof *gr);
        gr[SPH_GAUSS_V] = row[ROW_V];
        memcpy(gr + SPH_GAUSS_U, row + ROW_U, 3 * sizeof *gr);
      }
    }
  }
  free(order);
  free(keys);
  free(rows);
  free(got);
  return st;
}

sph_status sph_reference_errors(const sph_reference *r, const sph_sim *sim,
                                sph_reference_error *e, sph_error *err) {
  e->l2_velocity = e->l2_stress = e->l2_displacement = e->h1_displacement = NAN;
  e->period = e->period_value = e->period_error = NAN;
  e->period_tolerance = r->tolerance;
  e->l2_displacement_gauss = e->h1_displacement_gauss = NAN;
  if (r->kind == REF_PERIOD) {
    /* mean period over the half periods between the first and last
     * crossings */
    double n = r->obs[OBS_CROSSINGS];
    e->period_value = r->value;
    if (n >= 2.0) {
      e->period = 2.0 * (r->obs[OBS_LAST] - r->obs[OBS_FIRST]) / (n - 1.0);
      e->period_error = fabs(e->period - r->value) / r->value;
    }
    return SPH_OK;
  }
  double s[5] = {0.0, 0.0, 0.0, 0.0, 0.0}; /* sv, ev, eP, eu, eg */
  SPH_TRY(error_sums(r, sim, s, err));
  e->l2_velocity = sqrt(s[1] / s[0]) / r->v_amp;
  e->l2_stress = sqrt(s[2] / s[0]) / r->P_amp;
  e->l2_displacement = sqrt(s[3] / s[0]) / r->U0;
  e->h1_displacement = sqrt(s[4] / s[0]) / (r->U0 * M_PI / 2.0);
  if (!r->gn) /* nodal, or not rank 0 */
    return SPH_OK;
  double g[2];
  sph_reference *rw = (sph_reference *)r; /* the time the exact field has */
  rw->t_exact = sim->t;
  sph_gauss_norm_bin(r->gn);
  SPH_TRY(sph_gauss_norm_errors(r->gn, gauss_exact, r, g, err));
  e->l2_displacement_gauss = g[0];
  e->h1_displacement_gauss = g[1];
  return SPH_OK;
}
