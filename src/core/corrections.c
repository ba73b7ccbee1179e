/* Kernel corrections on a particle cloud, per directed pair in CSR order:
 * gradient correction matrix L (seed 001 eq. 8, seed 000 eq. 21), zeroth-
 * order corrected kernel W~0 and its corrected gradient (seed 004
 * eq. 10-14), first-order corrected kernel W~1 and its exact gradient
 * (seed 004 eq. 6-8, App. A eq. A.1-A.6), and the corrected Laplacian of
 * seed 000 App. A (eq. A.2-A.5) with the quadratic condition sum V |r|^2
 * Lap W~ = 2d in d dimensions.
 *
 * The gradient of W~0 is the exact derivative of eq. 10,
 * (grad W_b - W_b gamma) / S; eq. 13 as printed drops the factor W_b. */
#include "core/corrections.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "core/check.h"
#include "core/tensor.h"

#define RCOND_DEFAULT 1e-10

static double rcond_min(const sph_cloud *c) {
  return c->rcond_min > 0.0 ? c->rcond_min : RCOND_DEFAULT;
}

/* 1-norm of the leading dim x dim block */
static double block_norm1(const double A[9], int dim) {
  double best = 0.0;
  for (int j = 0; j < dim; ++j) {
    double s = 0.0;
    for (int i = 0; i < dim; ++i)
      s += fabs(A[3 * i + j]);
    best = s > best ? s : best;
  }
  return best;
}

/* Whether Ainv A is the identity in the leading dim x dim block to within
 * the round-off the reciprocal condition number rc allows. */
static int inverse_ok(const double A[9], const double Ainv[9], int dim,
                      double rc) {
  double tol = 1e3 * DBL_EPSILON / rc;
  for (int i = 0; i < dim; ++i)
    for (int j = 0; j < dim; ++j) {
      double s = 0.0;
      for (int k = 0; k < dim; ++k)
        s += Ainv[3 * i + k] * A[3 * k + j];
      if (!(fabs(s - (i == j)) <= tol))
        return 0;
    }
  return 1;
}

/* Inverts the leading dim x dim block of A; the rest of Ainv is the
 * identity. Returns the reciprocal 1-norm condition number of the block,
 * computed from the adjugate so that nothing is divided by a vanishing
 * determinant; Ainv is written only when the result is >= rmin. With
 * SPH_DEBUG_CHECKS, -1 when Ainv A is not the identity (inverse_ok). */
static double invert_block(const double A[9], int dim, double rmin,
                           double Ainv[9]) {
  double P[9], H[9];
  sph_mat3_identity(P);
  for (int i = 0; i < dim; ++i)
    for (int j = 0; j < dim; ++j)
      P[3 * i + j] = A[3 * i + j];
  /* adj(P) = H^T; its leading block is the adjugate of A's block */
  sph_mat3_cofactor(P, H);
  double det = P[0] * H[0] + P[1] * H[1] + P[2] * H[2];
  double adj[9];
  sph_mat3_transpose(H, adj);
  double denom = block_norm1(P, dim) * block_norm1(adj, dim);
  if (det == 0.0 || !isfinite(det) || !(denom > 0.0) || !isfinite(denom))
    return 0.0;
  double rc = fabs(det) / denom;
  if (!(rc >= rmin))
    return rc;
  for (int k = 0; k < 9; ++k)
    Ainv[k] = adj[k] / det;
  for (int i = dim; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      Ainv[3 * i + j] = Ainv[3 * j + i] = (i == j);
  if (SPH_DEBUG_CHECKS_ON && !inverse_ok(A, Ainv, dim, rc))
    return -1.0;
  return rc;
}

/* Records the smallest failing particle index (deterministic). */
static void mark_bad(long *bad, long a) {
#pragma omp critical(sph_corrections_bad)
  if (a < *bad)
    *bad = a;
}

/* mark_bad into bad for a singular matrix (r -1), into wrong for an
 * inverse that a debug check found wrong (r -2) */
static void mark_failed(long *bad, long *wrong, long a, int r) {
  mark_bad(r < -1 ? wrong : bad, a);
}

/* The cloud the corrections read: lists for (at least) its points and a
 * kernel of positive support. */
static sph_status check_cloud(const sph_cloud *c, sph_error *err) {
  SPH_CHECK(c->nl && c->nl->n >= c->n && c->x && c->volume, err,
            "correction cloud of %zu points with lists of %zu", c->n,
            c->nl ? c->nl->n : 0);
  SPH_CHECK(c->kernel && c->kernel->support > 0.0 && c->dim >= 1 && c->dim <= 3,
            err, "correction cloud: kernel support %g, dimension %d",
            c->kernel ? c->kernel->support : 0.0, c->dim);
  return SPH_OK;
}

/* SPH_DEBUG_CHECKS: `wrong` (n: none) is the first particle whose moment
 * matrix times its computed inverse is not the identity */
static sph_status check_inverse(const sph_cloud *c, long wrong,
                                sph_error *err) {
  SPH_CHECK(wrong == (long)c->n, err,
            "moment matrix of particle %lld: its inverse times it is not "
            "the identity",
            c->id && wrong < (long)c->n ? (long long)c->id[wrong]
                                        : (long long)wrong);
  return SPH_OK;
}

static sph_status singular(const sph_cloud *c, long a, const char *what,
                           sph_error *err) {
  const double *x = c->x + 3 * a;
  long long id = c->id ? (long long)c->id[a] : (long long)a;
  size_t nb = c->nl->offset[a + 1] - c->nl->offset[a];
  return sph_error_set(err, SPH_ERR_SINGULAR,
                       "singular %s at particle %lld (%g, %g, %g) with %zu "
                       "neighbours: too few or collinear neighbours",
                       what, id, x[0], x[1], x[2], nb);
}

/* Whether point a is partial (sph_cloud.partial): its stride values per
 * slot, from v, become NaN. */
static int partial_point(const sph_cloud *c, size_t a, int stride, double *v) {
  if (!c->partial || !c->partial[a])
    return 0;
  for (size_t k = c->nl->offset[a] * (size_t)stride;
       v && k < c->nl->offset[a + 1] * (size_t)stride; ++k)
    v[k] = NAN;
  return 1;
}

/* NaN to the w values of point a from v (when not NULL) */
static void nan_values(double *v, size_t a, size_t w) {
  for (size_t k = 0; v && k < w; ++k)
    v[w * a + k] = NAN;
}

/* Zeroes the slots of a particle whose correction failed. */
static void clear_slots(const sph_neighbors *nl, size_t a, int stride,
                        double *v) {
  size_t lo = nl->offset[a], hi = nl->offset[a + 1];
  if (hi > lo)
    memset(v + (size_t)stride * lo, 0, (size_t)stride * (hi - lo) * sizeof *v);
}

/* rab = x_a - x_b in the first dim components (the rest are zero) */
static inline void pair_vector(const sph_cloud *c, size_t a, size_t b,
                               double rab[3], double *r) {
  for (int k = 0; k < 3; ++k)
    rab[k] = k < c->dim ? c->x[3 * a + k] - c->x[3 * b + k] : 0.0;
  *r = sqrt(sph_vec3_dot(rab, rab));
}

/* Shepard sum S = sum_b V_b W_b(x_a) including a, and gamma = grad S / S
 * (seed 004 eq. 14) */
static void shepard(const sph_cloud *c, size_t a, double *S, double gam[3]) {
  const sph_neighbors *nl = c->nl;
  *S = c->volume[a] * sph_kernel_eval(c->kernel, 0.0);
  gam[0] = gam[1] = gam[2] = 0.0;
  for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
    size_t b = (size_t)nl->index[k];
    double rab[3], r, g[3];
    pair_vector(c, a, b, rab, &r);
    *S += c->volume[b] * sph_kernel_eval(c->kernel, r);
    sph_kernel_gradient(c->kernel, rab, r, g);
    for (int i = 0; i < 3; ++i)
      gam[i] += c->volume[b] * g[i];
  }
  for (int i = 0; i < 3; ++i)
    gam[i] /= *S;
}

/* First-order corrected kernel coefficients at a (seed 004 eq. 7-8, A.2-A.3)
 * and their gradients (A.5-A.6), with the moments of the evaluation point x
 *   phi = sum V W, vphi = sum V (x - x_b) W, Phi = sum V (x - x_b)(x) (x - x_b)
 * W over b including a (which adds V_a W(0) to phi and V_a W(0) I to grad
 * vphi).
 */
typedef struct w1_coef {
  double alpha, beta[3];
  double dalpha[3], dbeta[3][3]; /* dbeta[k][i] = d beta_i / d x_k */
} w1_coef;

static int w1_coefficients(const sph_cloud *c, size_t a, double rmin,
                           w1_coef *w) {
  const sph_neighbors *nl = c->nl;
  int dim = c->dim;
  double W0 = sph_kernel_eval(c->kernel, 0.0) * c->volume[a];
  double phi = W0, vphi[3] = {0}, Phi[9] = {0};
  double dphi[3] = {0}, dvphi[3][3] = {{0}}, dPhi[3][9] = {{0}};
  for (int k = 0; k < dim; ++k)
    dvphi[k][k] += W0;
  for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s) {
    size_t b = (size_t)nl->index[s];
    double rab[3], r, g[3];
    pair_vector(c, a, b, rab, &r);
    double V = c->volume[b], Wb = sph_kernel_eval(c->kernel, r);
    sph_kernel_gradient(c->kernel, rab, r, g);
    phi += V * Wb;
    for (int i = 0; i < 3; ++i) {
      vphi[i] += V * rab[i] * Wb;
      dphi[i] += V * g[i];
      for (int j = 0; j < 3; ++j)
        Phi[3 * i + j] += V * rab[i] * rab[j] * Wb;
    }
    for (int k = 0; k < dim; ++k) {
      dvphi[k][k] += V * Wb;
      for (int i = 0; i < 3; ++i) {
        dvphi[k][i] += V * rab[i] * g[k];
        for (int j = 0; j < 3; ++j)
          dPhi[k][3 * i + j] += V * rab[i] * rab[j] * g[k];
        dPhi[k][3 * i + k] += V * rab[i] * Wb;
        dPhi[k][3 * k + i] += V * rab[i] * Wb;
      }
    }
  }
  double Pinv[9];
  double rc = invert_block(Phi, dim, rmin, Pinv);
  if (rc < rmin)
    return rc < 0.0 ? -2 : -1;
  for (int i = dim; i < 3; ++i)
    Pinv[4 * i] = 0.0; /* unused directions carry no correction */
  /* beta = -Phi^-1 vphi (eq. 7), alpha = 1 / (phi + beta . vphi) (eq. 8) */
  double t[3];
  sph_mat3_vec(Pinv, vphi, t);
  for (int i = 0; i < 3; ++i)
    w->beta[i] = -t[i];
  double den = phi + sph_vec3_dot(w->beta, vphi);
  if (!(fabs(den) > DBL_EPSILON * phi))
    return -1;
  w->alpha = 1.0 / den;
  for (int k = 0; k < 3; ++k) {
    if (k >= dim) {
      w->dalpha[k] = 0.0;
      memset(w->dbeta[k], 0, sizeof w->dbeta[k]);
      continue;
    }
    /* d beta = Phi^-1 (-d vphi - d Phi beta) */
    double rhs[3], dPb[3];
    sph_mat3_vec(dPhi[k], w->beta, dPb);
    for (int i = 0; i < 3; ++i)
      rhs[i] = -dvphi[k][i] - dPb[i];
    sph_mat3_vec(Pinv, rhs, w->dbeta[k]);
    /* d alpha = -alpha^2 d(phi + beta . vphi) */
    double dden = dphi[k] + sph_vec3_dot(w->dbeta[k], vphi) +
                  sph_vec3_dot(w->beta, dvphi[k]);
    w->dalpha[k] = -w->alpha * w->alpha * dden;
  }
  return 0;
}

/* grad W~1_b(x_a) of slot (a -> b) from a's coefficients */
static inline void w1_slot(const sph_cloud *c, const w1_coef *w, size_t a,
                           size_t b, double out[3]) {
  double rab[3], r, g[3];
  pair_vector(c, a, b, rab, &r);
  double Wb = sph_kernel_eval(c->kernel, r);
  sph_kernel_gradient(c->kernel, rab, r, g);
  double lin = 1.0 + sph_vec3_dot(w->beta, rab);
  for (int k = 0; k < 3; ++k)
    out[k] = w->dalpha[k] * lin * Wb +
             w->alpha * (sph_vec3_dot(w->dbeta[k], rab) + w->beta[k]) * Wb +
             w->alpha * lin * g[k];
}

/* The raw or W~0 gradients of a's slots (into grad when not NULL, before
 * the correction), the self gradient gs and the correction La (identity
 * for UNCORRECTED) of the moment M = sum V g (x) (x_b - x_a); S and gam the
 * Shepard sum and grad S / S when not NULL (W~0). -1 when M is singular.
 * The slots, when given, end corrected: La g. */
static int corrected_point(const sph_cloud *c, sph_gradient_kind kind, size_t a,
                           double rmin, double *grad, double gs[3],
                           double La[9], double *S_out, double gam_out[3]) {
  const sph_neighbors *nl = c->nl;
  double S = 1.0, gam[3] = {0, 0, 0}, M[9] = {0};
  int w0 = kind == SPH_GRAD_CORRECTED_W0;
  sph_mat3_identity(La);
  gs[0] = gs[1] = gs[2] = 0.0;
  if (w0) {
    shepard(c, a, &S, gam);
    /* W~0_a(x) = W(x - x_a) / S(x): at x_a only S varies */
    for (int k = 0; k < 3; ++k)
      gs[k] = -sph_kernel_eval(c->kernel, 0.0) * gam[k] / S;
  }
  if (S_out) {
    *S_out = S;
    memcpy(gam_out, gam, sizeof gam);
  }
  for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s) {
    size_t b = (size_t)nl->index[s];
    double rab[3], r, g[3];
    pair_vector(c, a, b, rab, &r);
    sph_kernel_gradient(c->kernel, rab, r, g);
    if (w0) {
      double Wb = sph_kernel_eval(c->kernel, r);
      for (int k = 0; k < 3; ++k)
        g[k] = (g[k] - Wb * gam[k]) / S;
    }
    if (grad)
      memcpy(grad + 3 * s, g, sizeof g);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        M[3 * i + j] -= c->volume[b] * g[i] * rab[j];
  }
  if (kind == SPH_GRAD_UNCORRECTED)
    return 0;
  double rc = invert_block(M, c->dim, rmin, La);
  if (rc < rmin)
    return rc < 0.0 ? -2 : -1;
  for (size_t s = nl->offset[a]; grad && s < nl->offset[a + 1]; ++s)
    sph_mat3_vec(La, grad + 3 * s, grad + 3 * s);
  sph_mat3_vec(La, gs, gs);
  return 0;
}

/* corrected grad W~0_b(x_a) of slot (a -> b) from a's S, gamma and L */
static inline void w0_slot(const sph_cloud *c, const double *co, size_t a,
                           size_t b, double out[3]) {
  double rab[3], r, g[3];
  pair_vector(c, a, b, rab, &r);
  sph_kernel_gradient(c->kernel, rab, r, g);
  double Wb = sph_kernel_eval(c->kernel, r);
  for (int k = 0; k < 3; ++k)
    g[k] = (g[k] - Wb * co[1 + k]) / co[0];
  sph_mat3_vec(co + 4, g, out);
}

sph_status sph_correction_gradient(const sph_cloud *c, sph_gradient_kind kind,
                                   double *grad, double *grad_self, double *L,
                                   sph_error *err) {
  const sph_neighbors *nl = c->nl;
  long n = (long)c->n, bad = n, wrong = n;
  double rmin = rcond_min(c);
  SPH_TRY(check_cloud(c, err));
  if ((int)kind < SPH_GRAD_UNCORRECTED || kind > SPH_GRAD_W1)
    return sph_error_set(err, SPH_ERR_ARG, "unknown gradient kind %d",
                         (int)kind);
  if (!grad && kind == SPH_GRAD_W1)
    return sph_error_set(err, SPH_ERR_ARG, "W~1 gradients need slots");
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double La[9], gs[3] = {0, 0, 0};
    int r;
    if (partial_point(c, (size_t)a, 3, grad)) {
      nan_values(grad_self, (size_t)a, 3);
      nan_values(L, (size_t)a, 9);
      continue;
    }
    sph_mat3_identity(La);
    if (kind == SPH_GRAD_W1) {
      w1_coef w;
      if ((r = w1_coefficients(c, (size_t)a, rmin, &w)) != 0) {
        mark_failed(&bad, &wrong, a, r);
        clear_slots(nl, (size_t)a, 3, grad);
        if (grad_self)
          memset(grad_self + 3 * a, 0, 3 * sizeof *grad_self);
        continue;
      }
      /* grad of alpha(x) (1 + beta(x).(x - x_b)) W(x - x_b) at x = x_a */
      double W0 = sph_kernel_eval(c->kernel, 0.0);
      for (int k = 0; k < 3; ++k)
        gs[k] = (w.dalpha[k] + w.alpha * w.beta[k]) * W0;
      for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s)
        w1_slot(c, &w, (size_t)a, (size_t)nl->index[s], grad + 3 * s);
    } else if ((r = corrected_point(c, kind, (size_t)a, rmin, grad, gs, La,
                                    NULL, NULL)) != 0) {
      mark_failed(&bad, &wrong, a, r);
      if (grad)
        clear_slots(nl, (size_t)a, 3, grad);
      if (grad_self)
        memset(grad_self + 3 * a, 0, 3 * sizeof *grad_self);
      continue;
    }
    if (grad_self)
      memcpy(grad_self + 3 * a, gs, sizeof gs);
    if (L)
      memcpy(L + 9 * a, La, sizeof La);
  }
  SPH_DEBUG_TRY(check_inverse(c, wrong, err));
  if (bad < n)
    return singular(c, bad, "gradient moment matrix", err);
  return SPH_OK;
}

sph_status sph_correction_kernel(const sph_cloud *c, int order, double *w,
                                 double *wself, sph_error *err) {
  const sph_neighbors *nl = c->nl;
  long n = (long)c->n, bad = n, wrong = n;
  double rmin = rcond_min(c);
  SPH_TRY(check_cloud(c, err));
  if (order != 0 && order != 1)
    return sph_error_set(err, SPH_ERR_ARG,
                         "kernel correction order %d is not 0 or 1", order);
  double W0 = sph_kernel_eval(c->kernel, 0.0);
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double alpha, beta[3] = {0, 0, 0};
    if (partial_point(c, (size_t)a, 1, w)) {
      nan_values(wself, (size_t)a, 1);
      continue;
    }
    if (order == 0) {
      double S, gam[3];
      shepard(c, (size_t)a, &S, gam);
      alpha = 1.0 / S;
    } else {
      w1_coef co;
      int r = w1_coefficients(c, (size_t)a, rmin, &co);
      if (r) {
        mark_failed(&bad, &wrong, a, r);
        clear_slots(nl, (size_t)a, 1, w);
        wself[a] = 0.0;
        continue;
      }
      alpha = co.alpha;
      memcpy(beta, co.beta, sizeof beta);
    }
    wself[a] = alpha * W0;
    for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s) {
      double rab[3], r;
      pair_vector(c, (size_t)a, (size_t)nl->index[s], rab, &r);
      w[s] = alpha * (1.0 + sph_vec3_dot(beta, rab)) *
             sph_kernel_eval(c->kernel, r);
    }
  }
  SPH_DEBUG_TRY(check_inverse(c, wrong, err));
  if (bad < n)
    return singular(c, bad, "kernel moment matrix", err);
  return SPH_OK;
}

/* Solves the m x m system A x = b (m <= 4) by Gaussian elimination with
 * partial pivoting, on the matrix S A S made dimensionless by the diagonal
 * scaling s. Returns the reciprocal 1-norm condition number of S A S (from
 * its explicit inverse); a pivot below DBL_EPSILON ||S A S|| counts as
 * singular (0). x is written only when the result is >= rmin. */
static double solve_small(int m, double A[4][4], double b[4], const double s[4],
                          double rmin, double x[4]) {
  double LU[4][4], inv[4][4];
  int perm[4];
  double anorm = 0.0;
  for (int j = 0; j < m; ++j) {
    double col = 0.0;
    for (int i = 0; i < m; ++i) {
      LU[i][j] = A[i][j] * s[i] * s[j];
      col += fabs(LU[i][j]);
    }
    anorm = col > anorm ? col : anorm;
  }
  if (!(anorm > 0.0) || !isfinite(anorm))
    return 0.0;
  for (int i = 0; i < m; ++i)
    perm[i] = i;
  /* factorise P A = L U in place */
  for (int k = 0; k < m; ++k) {
    int piv = k;
    for (int i = k + 1; i < m; ++i)
      if (fabs(LU[i][k]) > fabs(LU[piv][k]))
        piv = i;
    if (!(fabs(LU[piv][k]) > DBL_EPSILON * anorm))
      return 0.0;
    if (piv != k) {
      for (int j = 0; j < m; ++j) {
        double t = LU[k][j];
        LU[k][j] = LU[piv][j];
        LU[piv][j] = t;
      }
      int t = perm[k];
      perm[k] = perm[piv];
      perm[piv] = t;
    }
    for (int i = k + 1; i < m; ++i) {
      LU[i][k] /= LU[k][k];
      for (int j = k + 1; j < m; ++j)
        LU[i][j] -= LU[i][k] * LU[k][j];
    }
  }
  /* inverse column by column: solve L U x = P e_j */
  double inorm = 0.0;
  for (int j = 0; j < m; ++j) {
    double y[4];
    for (int i = 0; i < m; ++i) {
      y[i] = perm[i] == j ? 1.0 : 0.0;
      for (int l = 0; l < i; ++l)
        y[i] -= LU[i][l] * y[l];
    }
    double col = 0.0;
    for (int i = m - 1; i >= 0; --i) {
      for (int l = i + 1; l < m; ++l)
        y[i] -= LU[i][l] * inv[l][j];
      inv[i][j] = y[i] / LU[i][i];
      col += fabs(inv[i][j]);
    }
    inorm = col > inorm ? col : inorm;
  }
  double rc = 1.0 / (anorm * inorm);
  if (!(rc >= rmin))
    return rc;
  /* x = S inv S b */
  for (int i = 0; i < m; ++i) {
    double t = 0.0;
    for (int j = 0; j < m; ++j)
      t += inv[i][j] * s[j] * b[j];
    x[i] = s[i] * t;
  }
  return rc;
}

/* the coefficients alpha (sol[0..d-1]) and beta (sol[d]) of a's corrected
 * Laplacian (A.2), -1 when its system is singular */
static int laplacian_solution(const sph_cloud *c, size_t a, double rmin,
                              double sol[4]) {
  const sph_neighbors *nl = c->nl;
  int d = c->dim, m = d + 1;
  double h = c->kernel->h;
  /* system A.5 with r_ab = X_b - X_a and right-hand side 2d (A.4) */
  double A[4][4] = {{0}}, rhs[4] = {0};
  rhs[d] = 2.0 * d;
  for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s) {
    size_t b = (size_t)nl->index[s];
    double rab[3], r;
    pair_vector(c, a, b, rab, &r);
    for (int k = 0; k < 3; ++k)
      rab[k] = -rab[k];
    double V = c->volume[b], r2 = r * r;
    double lw = sph_kernel_laplacian(c->kernel, r);
    for (int i = 0; i < d; ++i) {
      for (int j = 0; j < d; ++j)
        A[i][j] += V * rab[i] * rab[j];
      A[i][d] += V * r2 * rab[i];
      A[d][i] += V * r2 * rab[i];
      rhs[i] -= V * rab[i] * lw;
    }
    A[d][d] += V * r2 * r2;
    rhs[d] -= V * r2 * lw;
  }
  /* lengths in units of h make the system dimensionless */
  double sc[4] = {1.0 / h, 1.0 / h, 1.0 / h, 1.0 / h};
  sc[d] = 1.0 / (h * h);
  return solve_small(m, A, rhs, sc, rmin, sol) < rmin ? -1 : 0;
}

/* Lap W~_b(X_a) = Lap W + alpha . r_ab + beta |r_ab|^2 (A.2) of slot
 * (a -> b) from a's coefficients */
static inline double laplacian_slot(const sph_cloud *c, const double sol[4],
                                    size_t a, size_t b) {
  double rab[3], r;
  pair_vector(c, a, b, rab, &r);
  double dot = 0.0;
  for (int i = 0; i < c->dim; ++i)
    dot -= sol[i] * rab[i];
  return sph_kernel_laplacian(c->kernel, r) + dot + sol[c->dim] * r * r;
}

sph_status sph_correction_laplacian(const sph_cloud *c, double *lap,
                                    sph_error *err) {
  const sph_neighbors *nl = c->nl;
  long n = (long)c->n, bad = n;
  double rmin = rcond_min(c);
  SPH_TRY(check_cloud(c, err));
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double sol[4] = {0};
    if (partial_point(c, (size_t)a, 1, lap))
      continue;
    if (laplacian_solution(c, (size_t)a, rmin, sol)) {
      mark_bad(&bad, a);
      clear_slots(nl, (size_t)a, 1, lap);
      continue;
    }
    for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s)
      lap[s] = laplacian_slot(c, sol, (size_t)a, (size_t)nl->index[s]);
  }
  if (bad < n)
    return singular(c, bad, "Laplacian moment matrix", err);
  return SPH_OK;
}

sph_status sph_correction_coefficients(const sph_cloud *c,
                                       sph_gradient_kind kind, int laplacian,
                                       double *coef, sph_error *err) {
  long n = (long)c->n, bad = n, inv_bad = n;
  double rmin = rcond_min(c);
  int lap_bad = 0;
  SPH_TRY(check_cloud(c, err));
  if (kind != SPH_GRAD_W1 && kind != SPH_GRAD_CORRECTED_W0)
    return sph_error_set(err, SPH_ERR_ARG,
                         "slot coefficients of gradient kind %d", (int)kind);
#pragma omp parallel for schedule(static) reduction(| : lap_bad)
  for (long a = 0; a < n; ++a) {
    double *co = coef + SPH_CORRECTION_COEFS * a;
    int wrong, r;
    if (partial_point(c, (size_t)a, 0, NULL)) {
      nan_values(coef, (size_t)a, SPH_CORRECTION_COEFS);
      continue;
    }
    if (kind == SPH_GRAD_W1) {
      w1_coef w;
      wrong = (r = w1_coefficients(c, (size_t)a, rmin, &w)) != 0;
      memcpy(co, &w, sizeof w);
    } else { /* S, gamma, L: 13 */
      double gs[3];
      r = corrected_point(c, kind, (size_t)a, rmin, NULL, gs, co + 4, co,
                          co + 1);
      wrong = r != 0;
    }
    double sol[4] = {0};
    if (laplacian && laplacian_solution(c, (size_t)a, rmin, sol)) {
      wrong = 1;
      lap_bad |= 1;
    }
    memcpy(co + 16, sol, sizeof sol);
    if (wrong)
      mark_failed(&bad, &inv_bad, a, r);
  }
  SPH_DEBUG_TRY(check_inverse(c, inv_bad, err));
  if (bad < n)
    return singular(c, bad,
                    lap_bad ? "kernel or Laplacian moment matrix"
                            : "kernel moment matrix",
                    err);
  return SPH_OK;
}

void sph_correction_slot(const sph_cloud *c, sph_gradient_kind kind,
                         const double *coef, size_t a, size_t b, double grad[3],
                         double *lap) {
  if (kind == SPH_GRAD_W1) {
    w1_coef w;
    memcpy(&w, coef, sizeof w);
    w1_slot(c, &w, a, b, grad);
  } else {
    w0_slot(c, coef, a, b, grad);
  }
  *lap = laplacian_slot(c, coef + 16, a, b);
}
