/* Seed 004's error norms (sec. 5.1 eq. 44-45) by Gauss quadrature of the
 * first-order corrected kernel interpolant (eq. 6-8) and its gradient
 * (App. A.4-A.6); see solver/reference_gauss.h. With r_j = X - X_j,
 * w_j = V_j W(r_j) and the moments phi = sum w_j, ph = sum w_j r_j,
 * Ph = sum w_j r_j (x) r_j (A.3), beta = -Ph^-1 ph and
 * alpha = 1 / (phi - ph . Ph^-1 ph) (A.2), so
 *   u_h = alpha (S0 + S1^T beta),  S0 = sum w_j u_j,  S1 = sum w_j r_j (x) u_j
 * and its derivative along X_k follows from those of the sums (A.5-A.6):
 *   d_k beta = -Ph^-1 d_k ph + Ph^-1 d_k Ph Ph^-1 ph,
 *   d_k alpha = -alpha^2 (d_k phi - 2 c . d_k ph + c . d_k Ph c), c = Ph^-1 ph.
 * In 2D the third row and column of Ph are the identity's (r_3 = 0). */
#include "solver/reference_gauss.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"

struct sph_gauss_norm {
  sph_kernel k;
  int dim, tiles, points;
  double lo[3], hi[3];
  size_t n;
  double *table; /* n rows of SPH_GAUSS_ROW */
  double c0[3];  /* the bins' corner: lo less one support */
  int nc[3];     /* bins a side (1 beyond dim) */
  size_t *start; /* first item of each bin, ncells + 1 */
  size_t *item;  /* particles by bin */
  double gx[5], gw[5];
};

int sph_gauss_legendre(int n, double x[], double w[]) {
  static const double x5a = 0.5384693101056831, x5b = 0.9061798459386640;
  static const double w5a = 0.4786286704993665, w5b = 0.2369268850561891;
  static const double x3 = 0.7745966692414834;
  static const double x4a = 0.3399810435848563, x4b = 0.8611363115940526;
  static const double w4a = 0.6521451548625461, w4b = 0.3478548451374538;
  switch (n) {
  case 1:
    x[0] = 0.0, w[0] = 2.0;
    return 1;
  case 2:
    x[0] = -1.0 / sqrt(3.0), x[1] = -x[0], w[0] = w[1] = 1.0;
    return 1;
  case 3:
    x[0] = -x3, x[1] = 0.0, x[2] = x3;
    w[0] = w[2] = 5.0 / 9.0, w[1] = 8.0 / 9.0;
    return 1;
  case 4:
    x[0] = -x4b, x[1] = -x4a, x[2] = x4a, x[3] = x4b;
    w[0] = w[3] = w4b, w[1] = w[2] = w4a;
    return 1;
  case 5:
    x[0] = -x5b, x[1] = -x5a, x[2] = 0.0, x[3] = x5a, x[4] = x5b;
    w[0] = w[4] = w5b, w[1] = w[3] = w5a, w[2] = 128.0 / 225.0;
    return 1;
  default:
    return 0;
  }
}

sph_status sph_gauss_norm_create(sph_gauss_norm **out, const sph_kernel *k,
                                 const double lo[3], const double hi[3],
                                 int tiles, int points, size_t n,
                                 sph_error *err) {
  *out = NULL;
  sph_gauss_norm *g = calloc(1, sizeof *g);
  if (!g)
    return sph_error_set(err, SPH_ERR_NOMEM, "gauss norm");
  g->k = *k;
  g->dim = k->dim;
  g->tiles = tiles;
  g->points = points;
  g->n = n;
  size_t ncells = 1;
  for (int c = 0; c < 3; ++c) {
    g->lo[c] = lo[c];
    g->hi[c] = hi[c];
    g->c0[c] = lo[c] - k->support;
    g->nc[c] = c < g->dim ? (int)((hi[c] - lo[c]) / k->support) + 3 : 1;
    ncells *= (size_t)g->nc[c];
  }
  if (tiles < 1 || !sph_gauss_legendre(points, g->gx, g->gw)) {
    free(g);
    return sph_error_set(err, SPH_ERR_ARG, "gauss norm: %d tiles, %d points",
                         tiles, points);
  }
  g->table = malloc((n ? n : 1) * SPH_GAUSS_ROW * sizeof *g->table);
  g->start = calloc(ncells + 1, sizeof *g->start);
  g->item = malloc((n ? n : 1) * sizeof *g->item);
  if (!g->table || !g->start || !g->item) {
    sph_gauss_norm_destroy(g);
    return sph_error_set(err, SPH_ERR_NOMEM, "gauss norm");
  }
  *out = g;
  return SPH_OK;
}

void sph_gauss_norm_destroy(sph_gauss_norm *g) {
  if (!g)
    return;
  free(g->table);
  free(g->start);
  free(g->item);
  free(g);
}

double *sph_gauss_norm_table(sph_gauss_norm *g) { return g->table; }

/* a position's bin index along c, clamped to the bins */
static int bin_of(const sph_gauss_norm *g, int c, double x) {
  if (c >= g->dim)
    return 0;
  double b = floor((x - g->c0[c]) / g->k.support);
  return b < 0.0 ? 0 : b >= g->nc[c] ? g->nc[c] - 1 : (int)b;
}

static size_t cell_of(const sph_gauss_norm *g, const double *X) {
  return ((size_t)bin_of(g, 2, X[2]) * (size_t)g->nc[1] +
          (size_t)bin_of(g, 1, X[1])) *
             (size_t)g->nc[0] +
         (size_t)bin_of(g, 0, X[0]);
}

void sph_gauss_norm_bin(sph_gauss_norm *g) {
  size_t ncells = (size_t)g->nc[0] * (size_t)g->nc[1] * (size_t)g->nc[2];
  memset(g->start, 0, (ncells + 1) * sizeof *g->start);
  for (size_t j = 0; j < g->n; ++j)
    ++g->start[cell_of(g, g->table + SPH_GAUSS_ROW * j) + 1];
  for (size_t c = 0; c < ncells; ++c)
    g->start[c + 1] += g->start[c];
  /* counting sort, the bins' starts restored after */
  for (size_t j = 0; j < g->n; ++j)
    g->item[g->start[cell_of(g, g->table + SPH_GAUSS_ROW * j)]++] = j;
  for (size_t c = ncells; c > 0; --c)
    g->start[c] = g->start[c - 1];
  g->start[0] = 0;
}

/* the sums over the support of X (App. A.3, A.6 and S0, S1) */
typedef struct {
  double phi, ph[3], Ph[9], dphi[3], dph[3][3], dPh[3][9];
  double S0[3], S1[9], dS0[3][3], dS1[3][9]; /* S1[3 m + i] = r_m u_i */
} moments;

static void add_particle(const sph_gauss_norm *g, const double X[3],
                         const double *row, moments *m) {
  double r[3], rr = 0.0;
  for (int c = 0; c < 3; ++c) {
    r[c] = X[c] - row[SPH_GAUSS_X + c];
    rr += r[c] * r[c];
  }
  double d = sqrt(rr);
  if (d >= g->k.support)
    return;
  const double V = row[SPH_GAUSS_V], *u = row + SPH_GAUSS_U;
  double w = V * sph_kernel_eval(&g->k, d), dw[3];
  sph_kernel_gradient(&g->k, r, d, dw);
  m->phi += w;
  for (int a = 0; a < 3; ++a) {
    m->ph[a] += w * r[a];
    m->S0[a] += w * u[a];
    for (int b = 0; b < 3; ++b) {
      m->Ph[3 * a + b] += w * r[a] * r[b];
      m->S1[3 * a + b] += w * r[a] * u[b];
    }
  }
  for (int k = 0; k < g->dim; ++k) {
    double wk = V * dw[k];
    m->dphi[k] += wk;
    for (int a = 0; a < 3; ++a) {
      m->dph[k][a] += wk * r[a] + (a == k) * w;
      m->dS0[k][a] += wk * u[a];
      for (int b = 0; b < 3; ++b) {
        m->dPh[k][3 * a + b] +=
            wk * r[a] * r[b] + ((a == k) * r[b] + (b == k) * r[a]) * w;
        m->dS1[k][3 * a + b] += (wk * r[a] + (a == k) * w) * u[b];
      }
    }
  }
}

static void gather(const sph_gauss_norm *g, const double X[3], moments *m) {
  memset(m, 0, sizeof *m);
  int b0[3], b1[3];
  for (int c = 0; c < 3; ++c) {
    int b = bin_of(g, c, X[c]);
    b0[c] = c < g->dim && b > 0 ? b - 1 : b;
    b1[c] = c < g->dim && b + 1 < g->nc[c] ? b + 1 : b;
  }
  for (int z = b0[2]; z <= b1[2]; ++z)
    for (int y = b0[1]; y <= b1[1]; ++y)
      for (int x = b0[0]; x <= b1[0]; ++x) {
        size_t c =
            ((size_t)z * (size_t)g->nc[1] + (size_t)y) * (size_t)g->nc[0] +
            (size_t)x;
        for (size_t i = g->start[c]; i < g->start[c + 1]; ++i)
          add_particle(g, X, g->table + SPH_GAUSS_ROW * g->item[i], m);
      }
}

static void mat_vec(const double A[9], const double x[3], double y[3]) {
  for (int a = 0; a < 3; ++a)
    y[a] = A[3 * a] * x[0] + A[3 * a + 1] * x[1] + A[3 * a + 2] * x[2];
}

sph_status sph_gauss_norm_interpolate(const sph_gauss_norm *g,
                                      const double X[3], double u[3],
                                      double G[9], sph_error *err) {
  moments m;
  gather(g, X, &m);
  for (int c = g->dim; c < 3; ++c)
    m.Ph[4 * c] = 1.0;
  double Pi[9] = {0}, cv[3], beta[3];
  double det = sph_mat3_inverse(m.Ph, Pi);
  mat_vec(Pi, m.ph, cv);
  double den = m.phi - (cv[0] * m.ph[0] + cv[1] * m.ph[1] + cv[2] * m.ph[2]);
  if (!(fabs(det) > 0.0) || !(den > 0.0) || !isfinite(den))
    return sph_error_set(err, SPH_ERR_RANGE,
                         "gauss norm: too few particles in the kernel's "
                         "support at (%g, %g, %g)",
                         X[0], X[1], X[2]);
  const double alpha = 1.0 / den;
  for (int a = 0; a < 3; ++a)
    beta[a] = -cv[a];
  double sum[3]; /* S0 + S1^T beta */
  for (int i = 0; i < 3; ++i) {
    sum[i] = m.S0[i];
    for (int a = 0; a < 3; ++a)
      sum[i] += beta[a] * m.S1[3 * a + i];
    u[i] = alpha * sum[i];
  }
  memset(G, 0, 9 * sizeof *G);
  for (int k = 0; k < g->dim; ++k) {
    double t[3], Pc[3], dbeta[3];
    /* d_k beta = Ph^-1 (d_k Ph c - d_k ph) */
    mat_vec(m.dPh[k], cv, Pc);
    for (int a = 0; a < 3; ++a)
      t[a] = Pc[a] - m.dph[k][a];
    mat_vec(Pi, t, dbeta);
    double q = m.dphi[k];
    for (int a = 0; a < 3; ++a)
      q += -2.0 * cv[a] * m.dph[k][a] + cv[a] * Pc[a];
    const double dalpha = -alpha * alpha * q;
    for (int i = 0; i < 3; ++i) {
      double s = m.dS0[k][i];
      for (int a = 0; a < 3; ++a)
        s += dbeta[a] * m.S1[3 * a + i] + beta[a] * m.dS1[k][3 * a + i];
      G[3 * i + k] = dalpha * sum[i] + alpha * s;
    }
  }
  return SPH_OK;
}

sph_status sph_gauss_norm_errors(const sph_gauss_norm *g,
                                 sph_gauss_exact *exact, const void *ctx,
                                 double e[2], sph_error *err) {
  const int d = g->dim, p = g->points;
  double tile[3], s0 = 0.0, s1 = 0.0;
  long tiles = 1, pts = 1;
  for (int c = 0; c < d; ++c) {
    tile[c] = (g->hi[c] - g->lo[c]) / g->tiles;
    tiles *= g->tiles;
    pts *= p;
  }
  for (long t = 0; t < tiles; ++t)
    for (long q = 0; q < pts; ++q) {
      double X[3] = {0.0, 0.0, 0.0}, w = 1.0;
      long tt = t, qq = q;
      for (int c = 0; c < d; ++c, tt /= g->tiles, qq /= p) {
        int it = (int)(tt % g->tiles), iq = (int)(qq % p);
        X[c] = g->lo[c] + tile[c] * (it + 0.5 * (1.0 + g->gx[iq]));
        w *= 0.5 * tile[c] * g->gw[iq];
      }
      double uh[3], Gh[9], ue[3], Ge[9];
      SPH_TRY(sph_gauss_norm_interpolate(g, X, uh, Gh, err));
      exact(ctx, X, ue, Ge);
      for (int i = 0; i < 3; ++i)
        s0 += w * (ue[i] - uh[i]) * (ue[i] - uh[i]);
      for (int i = 0; i < 9; ++i)
        s1 += w * (Ge[i] - Gh[i]) * (Ge[i] - Gh[i]);
    }
  e[0] = sqrt(s0);
  e[1] = sqrt(s1);
  return SPH_OK;
}
