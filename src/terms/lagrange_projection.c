/* Essential boundary conditions by the Lagrange-multiplier least-squares
 * projection of seed 000 App. B (eq. B.1-B.6).
 *
 * The boundary points B are the particles a boundary selects. The corrected
 * kernel interpolant at X_B of the momentum rate must equal the prescribed
 * rate (B.1); optionally the correction keeps the total linear and angular
 * momentum rates (B.2). Minimising sum V |p^ - p|^2 under these constraints
 * (B.3) gives p^_a = p_a + sum_B V_B W~_a(X_B) beta_B + beta_ang x X_a +
 * beta_lin (B.4). With gamma_B = V_B beta_B the system (B.5-B.6) becomes
 * symmetric: K gamma + H g = r, H^T gamma + Q g = 0, where
 * K_BB' = sum_a V_a W~_a(X_B) W~_a(X_B') is the same for every component
 * (a component's active points take a principal block of it), so each block
 * is factorised once per set of active constraints (Cholesky) and the six
 * global multipliers come from a 6x6 Schur complement.
 *
 * The rates are projected at every stage (B.1 with zero prescribed rate) and
 * the state after every update with the prescribed momentum as target, so
 * the initial state and the start of a velocity window honour the
 * constraints too. Symmetry planes constrain the normal component,
 * skew-symmetric planes the tangential ones (no mirror images then).
 *
 * B.2 as printed forces the total momentum of a clamped body to evolve as
 * if it were free: the clamp's reaction becomes a uniform body force on the
 * whole body. It is therefore an option (`lagrange_momentum`), off by
 * default.
 *
 * Over MPI ranks (issue 20) the boundary points, their rows W~_a(X_B) and
 * densities are gathered to every rank at set-up; each rank sums its owned
 * particles' share of K, of the interpolants and of H and Q, the shares are
 * added in rank order, every rank solves the same system and corrects its
 * owned particles. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/corrections.h"
#include "core/tensor.h"
#include "parallel/domain.h"
#include "terms/terms_impl.h"

#define LP_MAX_POINTS 4096
#define LP_CHUNK 4096 /* values per reduction message */

typedef struct lp_block {
  size_t n;     /* active points of this component */
  size_t *pt;   /* their boundary-point indices */
  double *chol; /* lower Cholesky factor of K restricted to them */
  double *Y;    /* K^-1 H (n x 6) when the global rows are on */
  double *H;    /* H (n x 6) */
} lp_block;

typedef struct lagrange_projection {
  size_t n; /* particles (this rank's owned ones over MPI ranks) */
  const double *X, *V;
  double *w, *wself; /* W~_b(X_a) per slot, W~_a(X_a) */
  const sph_scene *scene;
  sph_domain *dom;         /* NULL in a serial run */
  double *work;            /* rank count x LP_CHUNK for the reductions */
  size_t nb;               /* boundary points */
  size_t *roff, *ridx;     /* row of each point: its owned particles a, */
  double *rw;              /* self first, with W~_a(X_B) */
  double *rho0;            /* reference density at each point */
  uint32_t *member;        /* which boundaries select each point */
  double *K;               /* nb x nb */
  double *target;          /* prescribed momentum at each point (3 nb) */
  unsigned *mask, *cached; /* active components, and those factorised */
  int global, have_cache;
  double xc[3];     /* centroid (conditioning of the global rows) */
  double Schol[36]; /* Cholesky factor of the 6x6 Schur complement */
  lp_block blk[3];
  double *gam, *tmp; /* work: 3 nb, n */
} lagrange_projection;

/* Components fixed by one boundary at time t, and their target velocity. */
static unsigned bc_mask(const sph_boundary *bc, double t) {
  switch (bc->kind) {
  case SPH_BC_CLAMP:
    return 7u;
  case SPH_BC_ROLLER:
  case SPH_BC_SYMMETRY:
    return 1u << bc->axis;
  case SPH_BC_SKEW_SYMMETRY:
    return 7u & ~(1u << bc->axis);
  case SPH_BC_VELOCITY:
    return (t >= bc->from && t < bc->until) ? bc->mask : 0u;
  default:
    return 0u;
  }
}

static int is_constraint(const sph_boundary *bc) {
  return bc->kind == SPH_BC_CLAMP || bc->kind == SPH_BC_ROLLER ||
         bc->kind == SPH_BC_SYMMETRY || bc->kind == SPH_BC_SKEW_SYMMETRY ||
         bc->kind == SPH_BC_VELOCITY;
}

/* Correction direction of global multiplier j at particle position X. */
static void global_dir(int j, const double *X, const double *xc, double e[3]) {
  e[0] = e[1] = e[2] = 0.0;
  if (j < 3) {
    e[j] = 1.0;
    return;
  }
  double u[3] = {0.0, 0.0, 0.0}, r[3];
  u[j - 3] = 1.0;
  for (int c = 0; c < 3; ++c)
    r[c] = X[c] - xc[c];
  sph_vec3_cross(u, r, e);
}

/* Lower Cholesky factor of the SPD matrix A (n x n) in place. */
static sph_status cholesky(double *A, size_t n, sph_error *err) {
  double dmax = 0.0;
  for (size_t i = 0; i < n; ++i)
    dmax = fmax(dmax, A[i * n + i]);
  for (size_t j = 0; j < n; ++j) {
    double d = A[j * n + j];
    for (size_t k = 0; k < j; ++k)
      d -= A[j * n + k] * A[j * n + k];
    if (!(d > 1e-13 * dmax))
      return sph_error_set(err, SPH_ERR_SINGULAR,
                           "essential boundary conditions: the Lagrange "
                           "constraints are dependent (pivot %g of %g); "
                           "boundaries overlap or select too few particles",
                           d, dmax);
    double l = sqrt(d);
    A[j * n + j] = l;
    for (size_t i = j + 1; i < n; ++i) {
      double s = A[i * n + j];
      for (size_t k = 0; k < j; ++k)
        s -= A[i * n + k] * A[j * n + k];
      A[i * n + j] = s / l;
    }
  }
  return SPH_OK;
}

/* Solves L L^T x = b in place (x given in b, stride `stride`). */
static void chol_solve(const double *L, size_t n, double *b, size_t stride) {
  for (size_t i = 0; i < n; ++i) {
    double s = b[i * stride];
    for (size_t k = 0; k < i; ++k)
      s -= L[i * n + k] * b[k * stride];
    b[i * stride] = s / L[i * n + i];
  }
  for (size_t i = n; i-- > 0;) {
    double s = b[i * stride];
    for (size_t k = i + 1; k < n; ++k)
      s -= L[k * n + i] * b[k * stride];
    b[i * stride] = s / L[i * n + i];
  }
}

/* Active components and prescribed momenta of every point at time t. */
static void lp_targets(lagrange_projection *lp, double t) {
  const sph_scene *s = lp->scene;
  for (size_t B = 0; B < lp->nb; ++B) {
    lp->mask[B] = 0u;
    for (int c = 0; c < 3; ++c)
      lp->target[3 * B + c] = 0.0;
    for (size_t k = 0; k < s->nboundaries; ++k) {
      const sph_boundary *bc = &s->boundaries[k];
      unsigned m = (lp->member[B] >> k) & 1u ? bc_mask(bc, t) : 0u;
      lp->mask[B] |= m;
      for (int c = 0; c < 3; ++c)
        if ((m & (1u << c)) && bc->kind == SPH_BC_VELOCITY)
          lp->target[3 * B + c] = lp->rho0[B] * bc->value[c];
    }
  }
}

/* Factorises each component's block for the current active set. */
static sph_status lp_factorise(lagrange_projection *lp, sph_error *err) {
  size_t nb = lp->nb;
  for (int c = 0; c < 3; ++c) {
    lp_block *b = &lp->blk[c];
    b->n = 0;
    for (size_t B = 0; B < nb; ++B)
      if (lp->mask[B] & (1u << c))
        b->pt[b->n++] = B;
    for (size_t i = 0; i < b->n; ++i)
      for (size_t j = 0; j < b->n; ++j)
        b->chol[i * b->n + j] = lp->K[b->pt[i] * nb + b->pt[j]];
    SPH_TRY(cholesky(b->chol, b->n, err));
  }
  memcpy(lp->cached, lp->mask, nb * sizeof *lp->mask);
  lp->have_cache = 1;
  return SPH_OK;
}

/* Global rows (B.2) about the positions xm of this stage (seed 000 eq. 45):
 * H[i, j] = sum_a V_a W~_a(X_B) e_j(a)_c, Y = K^-1 H and the Cholesky
 * factor of S = Q - sum_c H_c^T Y_c. */
static sph_status lp_schur(lagrange_projection *lp, const double *xm,
                           sph_error *err) {
  double m[4] = {0.0, 0.0, 0.0, 0.0}; /* volume, first moment */
  for (size_t a = 0; a < lp->n; ++a) {
    m[0] += lp->V[a];
    for (int c = 0; c < 3; ++c)
      m[1 + c] += lp->V[a] * xm[3 * a + c];
  }
  sph_domain_sum(lp->dom, m, 4);
  for (int c = 0; c < 3; ++c)
    lp->xc[c] = m[1 + c] / (m[0] > 0.0 ? m[0] : 1.0);
  for (int c = 0; c < 3; ++c) {
    lp_block *b = &lp->blk[c];
    for (size_t i = 0; i < b->n; ++i) {
      size_t B = b->pt[i];
      for (int j = 0; j < 6; ++j) {
        double h = 0.0;
        for (size_t k = lp->roff[B]; k < lp->roff[B + 1]; ++k) {
          size_t a = lp->ridx[k];
          double e[3];
          global_dir(j, xm + 3 * a, lp->xc, e);
          h += lp->V[a] * lp->rw[k] * e[c];
        }
        b->H[i * 6 + j] = h;
      }
    }
    sph_domain_sum_long(lp->dom, b->H, 6 * b->n, lp->work, LP_CHUNK);
    memcpy(b->Y, b->H, 6 * b->n * sizeof *b->Y);
    for (int j = 0; j < 6; ++j)
      chol_solve(b->chol, b->n, b->Y + j, 6);
  }
  double *S = lp->Schol;
  memset(S, 0, sizeof lp->Schol);
  for (size_t a = 0; a < lp->n; ++a) {
    double e[6][3];
    for (int j = 0; j < 6; ++j)
      global_dir(j, xm + 3 * a, lp->xc, e[j]);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j)
        S[i * 6 + j] += lp->V[a] * sph_vec3_dot(e[i], e[j]);
  }
  sph_domain_sum_long(lp->dom, S, 36, lp->work, LP_CHUNK);
  for (int c = 0; c < 3; ++c) {
    lp_block *b = &lp->blk[c];
    for (size_t k = 0; k < b->n; ++k)
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
          S[i * 6 + j] -= b->H[k * 6 + i] * b->Y[k * 6 + j];
  }
  return cholesky(S, 6, err);
}

/* Interpolated value of component c of f (3 per particle) at point B
 * (this rank's share over MPI ranks). */
static double interp(const lagrange_projection *lp, size_t B, int c,
                     const double *f) {
  double v = 0.0;
  for (size_t k = lp->roff[B]; k < lp->roff[B + 1]; ++k) {
    size_t a = lp->ridx[k];
    v += lp->V[a] * lp->rw[k] * f[3 * a + c];
  }
  return v;
}

/* Projects f (rates when `rates`, else the state) onto the constraints. */
static sph_status lp_project(lagrange_projection *lp, double t,
                             const double *xm, double *f, int rates,
                             sph_error *err) {
  lp_targets(lp, t);
  if (!lp->have_cache ||
      memcmp(lp->cached, lp->mask, lp->nb * sizeof *lp->mask))
    SPH_TRY(lp_factorise(lp, err));
  if (lp->global)
    SPH_TRY(lp_schur(lp, xm, err));
  double g[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  for (int c = 0; c < 3; ++c) {
    lp_block *b = &lp->blk[c];
    double *gam = lp->gam + c * lp->nb;
    for (size_t i = 0; i < b->n; ++i)
      gam[i] = interp(lp, b->pt[i], c, f);
    sph_domain_sum_long(lp->dom, gam, b->n, lp->work, LP_CHUNK);
    for (size_t i = 0; i < b->n; ++i)
      gam[i] = (rates ? 0.0 : lp->target[3 * b->pt[i] + c]) - gam[i];
    chol_solve(b->chol, b->n, gam, 1);
    if (lp->global)
      for (size_t i = 0; i < b->n; ++i)
        for (int j = 0; j < 6; ++j)
          g[j] -= b->H[i * 6 + j] * gam[i];
  }
  if (lp->global) {
    chol_solve(lp->Schol, 6, g, 1);
    for (int c = 0; c < 3; ++c) {
      lp_block *b = &lp->blk[c];
      double *gam = lp->gam + c * lp->nb;
      for (size_t i = 0; i < b->n; ++i)
        for (int j = 0; j < 6; ++j)
          gam[i] -= b->Y[i * 6 + j] * g[j];
    }
    for (size_t a = 0; a < lp->n; ++a)
      for (int j = 0; j < 6; ++j) {
        double e[3];
        global_dir(j, xm + 3 * a, lp->xc, e);
        for (int c = 0; c < 3; ++c)
          f[3 * a + c] += g[j] * e[c];
      }
  }
  /* p^_a += sum_B W~_a(X_B) gamma_B (B.4), serial for a fixed sum order */
  for (int c = 0; c < 3; ++c) {
    lp_block *b = &lp->blk[c];
    const double *gam = lp->gam + c * lp->nb;
    for (size_t i = 0; i < b->n; ++i) {
      size_t B = b->pt[i];
      for (size_t k = lp->roff[B]; k < lp->roff[B + 1]; ++k)
        f[3 * lp->ridx[k] + c] += lp->rw[k] * gam[i];
    }
  }
  return SPH_OK;
}

static sph_status lp_rates(sph_term *term, sph_sim *sim, sph_stage *stage,
                           sph_error *err) {
  const double *xm = stage->x_moment ? stage->x_moment : stage->x;
  return lp_project(term->data, stage->t, xm, stage->dp, 1, err);
}

static sph_status lp_constrain(sph_term *term, sph_sim *sim, sph_stage *state,
                               sph_error *err) {
  /* the state is writable here: the method passes its own arrays */
  return lp_project(term->data, state->t, state->x, (double *)state->p, 0, err);
}

static void lp_destroy(sph_term *term) {
  lagrange_projection *lp = term->data;
  if (!lp)
    return;
  for (int c = 0; c < 3; ++c) {
    free(lp->blk[c].pt);
    free(lp->blk[c].chol);
    free(lp->blk[c].H);
    free(lp->blk[c].Y);
  }
  free(lp->w);
  free(lp->wself);
  free(lp->work);
  free(lp->roff);
  free(lp->ridx);
  free(lp->rw);
  free(lp->rho0);
  free(lp->member);
  free(lp->K);
  free(lp->target);
  free(lp->mask);
  free(lp->cached);
  free(lp->gam);
  free(lp->tmp);
  free(lp);
}

const sph_term_ops lagrange_projection_term_ops = {
    .name = "lagrange_projection",
    .reference = "seed 000 App. B eq. B.1-B.6",
    .rates = lp_rates,
    .constrain = lp_constrain,
    .destroy = lp_destroy,
    .distributed = 1,
};

/* K_BB' = sum_a V_a W~_a(X_B) W~_a(X_B'), through a dense scatter of row B
 * (this rank's share, then added over the ranks). */
static void lp_build_K(lagrange_projection *lp) {
  size_t nb = lp->nb;
  double *row = lp->tmp;
  for (size_t B = 0; B < nb; ++B) {
    for (size_t k = lp->roff[B]; k < lp->roff[B + 1]; ++k)
      row[lp->ridx[k]] = lp->rw[k];
    for (size_t B2 = 0; B2 < nb; ++B2) {
      double s = 0.0;
      for (size_t k = lp->roff[B2]; k < lp->roff[B2 + 1]; ++k) {
        size_t a = lp->ridx[k];
        s += lp->V[a] * row[a] * lp->rw[k];
      }
      lp->K[B * nb + B2] = s;
    }
    for (size_t k = lp->roff[B]; k < lp->roff[B + 1]; ++k)
      row[lp->ridx[k]] = 0.0;
  }
  sph_domain_sum_long(lp->dom, lp->K, nb * nb, lp->work, LP_CHUNK);
}

/* Which constraints select owned particle a (bit k: boundary k). */
static uint32_t lp_member(const lagrange_projection *lp, const sph_sim *sim,
                          size_t a) {
  const sph_scene *s = lp->scene;
  uint32_t m = 0;
  for (size_t k = 0; k < s->nboundaries; ++k)
    if (is_constraint(&s->boundaries[k]) &&
        sph_selection_contains(s, &s->boundaries[k].select, sim->ps->body[a],
                               lp->X + 3 * a))
      m |= 1u << k;
  return m;
}

static sph_status lp_too_many(size_t nb, sph_error *err) {
  return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                       "essential_bc: lagrange factorises a dense matrix "
                       "over the boundary points; %zu points exceed the "
                       "limit of %d (use essential_bc: direct)",
                       nb, LP_MAX_POINTS);
}

/* Rows arrays for nb points and len entries. */
static sph_status lp_alloc_rows(lagrange_projection *lp, size_t nb, size_t len,
                                sph_error *err) {
  lp->member = calloc(nb + 1, sizeof *lp->member);
  lp->rho0 = calloc(nb + 1, sizeof *lp->rho0);
  lp->roff = calloc(nb + 2, sizeof *lp->roff);
  lp->ridx = malloc((len + 1) * sizeof *lp->ridx);
  lp->rw = malloc((len + 1) * sizeof *lp->rw);
  if (!lp->member || !lp->rho0 || !lp->roff || !lp->ridx || !lp->rw)
    return sph_error_set(err, SPH_ERR_NOMEM, "lagrange projection");
  return SPH_OK;
}

/* Boundary points of a serial run: every particle a constraint selects, in
 * storage order, each with its row. */
static sph_status lp_points_serial(lagrange_projection *lp, sph_sim *sim,
                                   const sph_neighbors *nl, const double *rho0,
                                   sph_error *err) {
  size_t *pt = malloc((lp->n + 1) * sizeof *pt), len = 0;
  uint32_t *mem = malloc((lp->n + 1) * sizeof *mem);
  sph_status st = SPH_OK;
  if (!pt || !mem) {
    st = sph_error_set(err, SPH_ERR_NOMEM, "lagrange projection");
    goto done;
  }
  for (size_t a = 0; a < lp->n; ++a)
    if ((mem[lp->nb] = lp_member(lp, sim, a))) {
      len += 1 + nl->offset[a + 1] - nl->offset[a];
      pt[lp->nb++] = a;
    }
  if (lp->nb > LP_MAX_POINTS) {
    st = lp_too_many(lp->nb, err);
    goto done;
  }
  if ((st = lp_alloc_rows(lp, lp->nb, len, err)) != SPH_OK)
    goto done;
  for (size_t B = 0; B < lp->nb; ++B) {
    size_t P = pt[B], r = lp->roff[B];
    lp->member[B] = mem[B];
    lp->rho0[B] = rho0[P];
    lp->ridx[r] = P;
    lp->rw[r++] = lp->wself[P];
    for (size_t k = nl->offset[P]; k < nl->offset[P + 1]; ++k) {
      lp->ridx[r] = (size_t)nl->index[k];
      lp->rw[r++] = lp->w[k];
    }
    lp->roff[B + 1] = r;
  }
done:
  free(pt);
  free(mem);
  return st;
}

/* This rank's owned particle of storage index g (n when another's). */
static size_t lp_owned(const int64_t *gidx, size_t n, int64_t g) {
  size_t lo = 0, hi = n;
  while (lo < hi) {
    size_t mid = lo + (hi - lo) / 2;
    if (gidx[mid] < g)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo < n && gidx[lo] == g ? lo : n;
}

/* (storage index, selection bits) pairs by storage index */
static int cmp_point(const void *pa, const void *pb) {
  const int64_t *a = pa, *b = pb;
  return (a[0] > b[0]) - (a[0] < b[0]);
}

/* Boundary points over MPI ranks: each rank's selected points (storage
 * index, selection bits) gathered on every rank and put in storage order;
 * their densities and rows (storage indices of the row's particles) are
 * added over the ranks, each slot written by one rank only; a rank keeps
 * the entries of its owned particles. */

static sph_status lp_points_distributed(lagrange_projection *lp,
                                        const sph_neighbors *nl, sph_sim *sim,
                                        const double *rho0, sph_error *err) {
  sph_domain *d = lp->dom;
  const int64_t *gidx = sph_domain_storage_index(d);
  size_t n = lp->n, nb = 0, len = 0, mine = 0;
  for (size_t a = 0; a < n; ++a)
    mine += lp_member(lp, sim, a) != 0;
  double total = (double)mine;
  sph_domain_sum(d, &total, 1);
  if (total > LP_MAX_POINTS)
    return lp_too_many((size_t)total, err);
  int64_t *own = malloc((2 * mine + 1) * sizeof *own), *sel = NULL;
  double *buf = NULL;
  sph_status st =
      own ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "lagrange projection");
  for (size_t a = 0, k = 0; own && a < n; ++a) {
    uint32_t m = lp_member(lp, sim, a);
    if (m) {
      own[2 * k] = gidx[a];
      own[2 * k++ + 1] = (int64_t)m;
    }
  }
  st = sph_domain_agree(d, st, err);
  if (st == SPH_OK)
    st = sph_domain_allgather_i64(d, own, 2 * mine, &sel, &nb, NULL, err);
  if (st != SPH_OK)
    goto done;
  nb /= 2;
  qsort(sel, nb, 2 * sizeof *sel, cmp_point);
  /* per point: row length and density */
  buf = calloc(2 * nb + 1, sizeof *buf);
  st = buf ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "lagrange projection");
  if ((st = sph_domain_agree(d, st, err)) != SPH_OK)
    goto done;
  for (size_t B = 0; B < nb; ++B) {
    size_t P = lp_owned(gidx, n, sel[2 * B]);
    if (P < n) {
      buf[B] = (double)(1 + nl->offset[P + 1] - nl->offset[P]);
      buf[nb + B] = rho0[P];
    }
  }
  sph_domain_sum_long(d, buf, 2 * nb, lp->work, LP_CHUNK);
  for (size_t B = 0; B < nb; ++B)
    len += (size_t)buf[B];
  st = lp_alloc_rows(lp, nb, len, err);
  if ((st = sph_domain_agree(d, st, err)) != SPH_OK)
    goto done;
  lp->nb = nb;
  for (size_t B = 0; B < nb; ++B) {
    lp->member[B] = (uint32_t)sel[2 * B + 1];
    lp->rho0[B] = buf[nb + B];
    lp->roff[B + 1] = lp->roff[B] + (size_t)buf[B];
  }
  /* the rows: storage index then W~_a(X_B) of each entry */
  free(buf);
  buf = calloc(2 * len + 1, sizeof *buf);
  st = buf ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "lagrange projection");
  if ((st = sph_domain_agree(d, st, err)) != SPH_OK)
    goto done;
  for (size_t B = 0; B < nb; ++B) {
    size_t P = lp_owned(gidx, n, sel[2 * B]), r = lp->roff[B];
    if (P == n)
      continue;
    buf[2 * r] = (double)gidx[P];
    buf[2 * r++ + 1] = lp->wself[P];
    for (size_t k = nl->offset[P]; k < nl->offset[P + 1]; ++k) {
      buf[2 * r] = (double)gidx[nl->index[k]];
      buf[2 * r++ + 1] = lp->w[k];
    }
  }
  sph_domain_sum_long(d, buf, 2 * len, lp->work, LP_CHUNK);
  size_t r = 0, start = 0;
  for (size_t B = 0; B < nb; ++B) {
    size_t end = lp->roff[B + 1];
    lp->roff[B] = r;
    for (size_t q = start; q < end; ++q) {
      size_t a = lp_owned(gidx, n, (int64_t)buf[2 * q]);
      if (a < n) {
        lp->ridx[r] = a;
        lp->rw[r++] = buf[2 * q + 1];
      }
    }
    start = end;
  }
  lp->roff[nb] = r;
done:
  free(own);
  free(sel);
  free(buf);
  return st;
}

sph_status lagrange_projection_create(sph_sim *sim, const sph_cloud *cloud,
                                      const double *rho0, int global,
                                      sph_error *err) {
  const sph_scene *s = sim->scene;
  size_t n = cloud->n;
  if (s->nboundaries > 32)
    return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                         "essential_bc: lagrange handles at most 32 "
                         "boundaries, the scene has %zu",
                         s->nboundaries);
  /* the blocks are per coordinate component: normals along an axis only */
  for (size_t k = 0; k < s->nboundaries; ++k) {
    const sph_boundary *bc = &s->boundaries[k];
    char key[48];
    snprintf(key, sizeof key, "boundaries[%zu]", k);
    if (is_constraint(bc) && bc->kind != SPH_BC_CLAMP &&
        bc->kind != SPH_BC_VELOCITY && bc->axis < 0)
      return sph_error_at(err, SPH_ERR_UNSUPPORTED, s->path, bc->line, bc->col,
                          key,
                          "boundary '%s': essential_bc: lagrange needs a "
                          "normal along x, y or z (use essential_bc: direct "
                          "for an oblique plane)",
                          bc->name);
  }
  lagrange_projection *lp = calloc(1, sizeof *lp);
  if (!lp)
    return sph_error_set(err, SPH_ERR_NOMEM, "lagrange projection");
  sph_term t = {.data = lp};
  sph_status st = SPH_OK;
  lp->n = n;
  lp->X = cloud->x;
  lp->V = cloud->volume;
  lp->scene = s;
  lp->dom = sim->domain;
  lp->global = global;
  lp->w = malloc((cloud->nl->count + 1) * sizeof *lp->w);
  lp->wself = malloc((n + 1) * sizeof *lp->wself);
  lp->tmp = calloc(n + 1, sizeof *lp->tmp);
  if (lp->dom)
    lp->work =
        malloc((size_t)sph_domain_size(lp->dom) * LP_CHUNK * sizeof *lp->work);
  if (!lp->w || !lp->wself || !lp->tmp || (lp->dom && !lp->work)) {
    st = sph_error_set(err, SPH_ERR_NOMEM, "lagrange projection");
    goto fail;
  }
  if ((st = sph_correction_kernel(cloud, 1, lp->w, lp->wself, err)) != SPH_OK)
    goto fail;
  /* boundary points: every particle a constraint selects */
  st = lp->dom ? lp_points_distributed(lp, cloud->nl, sim, rho0, err)
               : lp_points_serial(lp, sim, cloud->nl, rho0, err);
  if (st != SPH_OK)
    goto fail;
  size_t nb = lp->nb ? lp->nb : 1;
  lp->K = malloc(nb * nb * sizeof *lp->K);
  lp->target = malloc(3 * nb * sizeof *lp->target);
  lp->mask = calloc(nb, sizeof *lp->mask);
  lp->cached = calloc(nb, sizeof *lp->cached);
  lp->gam = malloc(3 * nb * sizeof *lp->gam);
  if (!lp->K || !lp->target || !lp->mask || !lp->cached || !lp->gam) {
    st = sph_error_set(err, SPH_ERR_NOMEM, "lagrange projection");
    goto fail;
  }
  for (int c = 0; c < 3; ++c) {
    lp_block *b = &lp->blk[c];
    b->pt = malloc(nb * sizeof *b->pt);
    b->chol = malloc(nb * nb * sizeof *b->chol);
    b->H = malloc(6 * nb * sizeof *b->H);
    b->Y = malloc(6 * nb * sizeof *b->Y);
    if (!b->pt || !b->chol || !b->H || !b->Y) {
      st = sph_error_set(err, SPH_ERR_NOMEM, "lagrange projection");
      goto fail;
    }
  }
  lp_build_K(lp);
  if ((st = sph_sim_add_term(sim, &lagrange_projection_term_ops, lp, err)) ==
      SPH_OK)
    return SPH_OK;
fail:
  lp_destroy(&t);
  return st;
}
