/* Kernel corrections on a particle cloud, per directed pair in CSR order:
 * gradient correction matrix L (seed 001 eq. 8, seed 000 eq. 21), zeroth-
 * order corrected kernel W~0 and its corrected gradient (seed 004
 * eq. 10-14), first-order corrected kernel W~1 and its exact gradient
 * (seed 004 eq. 6-8, App. A eq. A.1-A.6), and the corrected Laplacian of
 * seed 000 App. A (eq. A.2-A.5) with the quadratic condition sum V |r|^2
 * Lap W~ = 2d in d dimensions. */
#include "sph/corrections.h"

#include <math.h>
#include <string.h>

#include "sph/tensor.h"

#define RCOND_DEFAULT 1e-10

static double rcond_min(const sph_cloud *c) {
  return c->rcond_min > 0.0 ? c->rcond_min : RCOND_DEFAULT;
}

/* Inverts the dim x dim block of A (unused diagonal padded with the mean
 * used diagonal); returns the reciprocal 1-norm condition number (0 when
 * singular). The unused block of Ainv is the identity. */
static double invert_block(const double A[9], int dim, double Ainv[9]) {
  double P[9] = {0};
  double diag = 0.0;
  for (int i = 0; i < dim; ++i)
    diag += fabs(A[4 * i]) / dim;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      P[3 * i + j] = (i < dim && j < dim) ? A[3 * i + j] : (i == j ? diag : 0);
  if (!(diag > 0.0) || !isfinite(diag))
    return 0.0;
  double det = sph_mat3_inverse(P, Ainv);
  if (det == 0.0 || !isfinite(det))
    return 0.0;
  double rc = 1.0 / (sph_mat3_norm1(P) * sph_mat3_norm1(Ainv));
  for (int i = dim; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      Ainv[3 * i + j] = Ainv[3 * j + i] = (i == j);
  return rc;
}

/* Records the smallest failing particle index (deterministic). */
static void mark_bad(long *bad, long a) {
#pragma omp critical(sph_corrections_bad)
  if (a < *bad)
    *bad = a;
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

static inline void pair_vector(const sph_cloud *c, size_t a, size_t b,
                               double rab[3], double *r) {
  for (int k = 0; k < 3; ++k)
    rab[k] = c->x[3 * a + k] - c->x[3 * b + k]; /* x_a - x_b */
  *r = sqrt(sph_vec3_dot(rab, rab));
}

/* Shepard sum S = sum_b V_b W_b(x_a) including a, and gamma of eq. 14 */
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

/* First-order corrected kernel coefficients at a (seed 004 eq. A.2-A.3) and
 * their gradients (A.5-A.6). */
typedef struct w1_coef {
  double alpha, beta[3];
  double dalpha[3], dbeta[3][3]; /* dbeta[k][i] = d beta_i / d x_k */
} w1_coef;

static int w1_coefficients(const sph_cloud *c, size_t a, w1_coef *w) {
  const sph_neighbors *nl = c->nl;
  int dim = c->dim;
  double W0 = sph_kernel_eval(c->kernel, 0.0) * c->volume[a];
  double phi = W0, vphi[3] = {0}, Phi[9] = {0};
  double dphi[3] = {0}, dvphi[3][3] = {{0}}, dPhi[3][9] = {{0}};
  /* the self term contributes W(0) to phi and I W(0) to d vphi */
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
  if (invert_block(Phi, dim, Pinv) < rcond_min(c))
    return -1;
  for (int i = dim; i < 3; ++i)
    Pinv[4 * i] = 0.0; /* unused directions carry no correction */
  double t[3];
  sph_mat3_vec(Pinv, vphi, t);
  for (int i = 0; i < 3; ++i)
    w->beta[i] = -t[i];
  w->alpha = 1.0 / (phi + sph_vec3_dot(w->beta, vphi));
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

sph_status sph_correction_gradient(const sph_cloud *c, sph_gradient_kind kind,
                                   double *grad, double *grad_self, double *L,
                                   sph_error *err) {
  const sph_neighbors *nl = c->nl;
  int dim = c->dim;
  long n = (long)c->n, bad = n;
  double rmin = rcond_min(c);
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double La[9], gam[3] = {0, 0, 0}, S = 1.0;
    sph_mat3_identity(La);
    if (grad_self)
      grad_self[3 * a] = grad_self[3 * a + 1] = grad_self[3 * a + 2] = 0.0;
    if (kind == SPH_GRAD_W1) {
      w1_coef w;
      if (w1_coefficients(c, (size_t)a, &w)) {
        mark_bad(&bad, a);
        continue;
      }
      double W0 = sph_kernel_eval(c->kernel, 0.0);
      /* d/dx of alpha (1 + beta.(x - x_a)) W(x - x_a) at x = x_a */
      if (grad_self)
        for (int k = 0; k < 3; ++k)
          grad_self[3 * a + k] =
              (w.dalpha[k] + (k < dim ? w.alpha * w.beta[k] : 0.0)) * W0;
      for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s) {
        double rab[3], r, g[3];
        pair_vector(c, (size_t)a, (size_t)nl->index[s], rab, &r);
        double Wb = sph_kernel_eval(c->kernel, r);
        sph_kernel_gradient(c->kernel, rab, r, g);
        double lin = 1.0 + sph_vec3_dot(w.beta, rab);
        for (int k = 0; k < 3; ++k)
          grad[3 * s + k] = w.dalpha[k] * lin * Wb +
                            w.alpha *
                                (sph_vec3_dot(w.dbeta[k], rab) +
                                 (k < dim ? w.beta[k] : 0.0)) *
                                Wb +
                            w.alpha * lin * g[k];
      }
    } else {
      if (kind == SPH_GRAD_CORRECTED_W0)
        shepard(c, (size_t)a, &S, gam);
      /* raw (or W~0) gradients and the moment M = sum V g (x) (x_b - x_a) */
      double M[9] = {0};
      for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s) {
        size_t b = (size_t)nl->index[s];
        double rab[3], r, g[3];
        pair_vector(c, (size_t)a, b, rab, &r);
        sph_kernel_gradient(c->kernel, rab, r, g);
        for (int k = 0; k < 3; ++k) {
          g[k] = (g[k] - gam[k]) / S;
          grad[3 * s + k] = g[k];
        }
        double mr[3] = {-rab[0], -rab[1], -rab[2]};
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            M[3 * i + j] += c->volume[b] * g[i] * mr[j];
      }
      if (kind != SPH_GRAD_UNCORRECTED) {
        if (invert_block(M, dim, La) < rmin) {
          mark_bad(&bad, a);
          continue;
        }
        for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s)
          sph_mat3_vec(La, grad + 3 * s, grad + 3 * s);
      }
    }
    if (L)
      memcpy(L + 9 * a, La, sizeof La);
  }
  if (bad < n)
    return singular(c, bad, "gradient moment matrix", err);
  return SPH_OK;
}

sph_status sph_correction_kernel(const sph_cloud *c, int order, double *w,
                                 double *wself, sph_error *err) {
  const sph_neighbors *nl = c->nl;
  long n = (long)c->n, bad = n;
  if (order != 0 && order != 1)
    return sph_error_set(err, SPH_ERR_ARG,
                         "kernel correction order %d is not "
                         "0 or 1",
                         order);
  double W0 = sph_kernel_eval(c->kernel, 0.0);
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    double alpha, beta[3] = {0, 0, 0};
    if (order == 0) {
      double S, gam[3];
      shepard(c, (size_t)a, &S, gam);
      alpha = 1.0 / S;
    } else {
      w1_coef co;
      if (w1_coefficients(c, (size_t)a, &co)) {
        mark_bad(&bad, a);
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
  if (bad < n)
    return singular(c, bad, "kernel moment matrix", err);
  return SPH_OK;
}

/* Solves the m x m system A x = b (m <= 4) by Gaussian elimination with
 * partial pivoting after symmetric diagonal scaling; returns the ratio of
 * the smallest to the largest pivot (0 when singular). */
static double solve_small(int m, double A[4][4], double b[4], double x[4]) {
  double s[4];
  for (int i = 0; i < m; ++i)
    s[i] = A[i][i] > 0.0 ? 1.0 / sqrt(A[i][i]) : 1.0;
  for (int i = 0; i < m; ++i) {
    b[i] *= s[i];
    for (int j = 0; j < m; ++j)
      A[i][j] *= s[i] * s[j];
  }
  double pmin = INFINITY, pmax = 0.0;
  for (int col = 0; col < m; ++col) {
    int piv = col;
    for (int i = col + 1; i < m; ++i)
      if (fabs(A[i][col]) > fabs(A[piv][col]))
        piv = i;
    if (piv != col) {
      for (int j = 0; j < m; ++j) {
        double t = A[col][j];
        A[col][j] = A[piv][j];
        A[piv][j] = t;
      }
      double t = b[col];
      b[col] = b[piv];
      b[piv] = t;
    }
    double p = fabs(A[col][col]);
    pmin = p < pmin ? p : pmin;
    pmax = p > pmax ? p : pmax;
    if (p == 0.0)
      return 0.0;
    for (int i = col + 1; i < m; ++i) {
      double f = A[i][col] / A[col][col];
      for (int j = col; j < m; ++j)
        A[i][j] -= f * A[col][j];
      b[i] -= f * b[col];
    }
  }
  for (int i = m - 1; i >= 0; --i) {
    double t = b[i];
    for (int j = i + 1; j < m; ++j)
      t -= A[i][j] * x[j];
    x[i] = t / A[i][i];
  }
  for (int i = 0; i < m; ++i)
    x[i] *= s[i];
  return pmax > 0.0 ? pmin / pmax : 0.0;
}

sph_status sph_correction_laplacian(const sph_cloud *c, double *lap,
                                    sph_error *err) {
  const sph_neighbors *nl = c->nl;
  int d = c->dim, m = d + 1;
  long n = (long)c->n, bad = n;
  double rmin = rcond_min(c);
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    /* system A.5 with r_ab = X_b - X_a */
    double A[4][4] = {{0}}, rhs[4] = {0}, sol[4] = {0};
    rhs[d] = 2.0 * d;
    for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s) {
      size_t b = (size_t)nl->index[s];
      double rab[3], r;
      pair_vector(c, (size_t)a, b, rab, &r);
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
    /* pivot ratios are squared condition measures of the scaled system */
    if (solve_small(m, A, rhs, sol) < sqrt(rmin)) {
      mark_bad(&bad, a);
      continue;
    }
    for (size_t s = nl->offset[a]; s < nl->offset[a + 1]; ++s) {
      double rab[3], r;
      pair_vector(c, (size_t)a, (size_t)nl->index[s], rab, &r);
      double dot = 0.0;
      for (int i = 0; i < d; ++i)
        dot -= sol[i] * rab[i];
      lap[s] = sph_kernel_laplacian(c->kernel, r) + dot + sol[d] * r * r;
    }
  }
  if (bad < n)
    return singular(c, bad, "Laplacian moment matrix", err);
  return SPH_OK;
}
