/* Kernel corrections on uniform and jittered lattices in 2D and 3D with
 * boundaries and corners: linear reproduction of the corrected gradients
 * (and its failure without correction), the corrected Laplacian on linear
 * and quadratic fields, W~0 and W~1 consistency, singular detection. */
#include "test_util.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sph/corrections.h"

typedef struct cloud_data {
  size_t n;
  int dim;
  double *x, *v;
  sph_neighbors *nl;
  sph_kernel k;
  sph_cloud c;
  int interior_only_ok; /* lattice is uniform */
  double *dist_to_boundary;
} cloud_data;

static uint64_t rng = 1;
static double urand(void) {
  uint64_t z = (rng += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

/* n^dim particles on the faces of [0, 1]^dim, tributary volumes */
static void make_into(cloud_data *out, int dim, int n1, double jitter,
                      sph_kernel_type kt) {
  cloud_data d;
  memset(&d, 0, sizeof d);
  d.dim = dim;
  d.n = (size_t)pow(n1, dim);
  d.x = calloc(3 * d.n, sizeof *d.x);
  d.v = calloc(d.n, sizeof *d.v);
  d.dist_to_boundary = calloc(d.n, sizeof *d.dist_to_boundary);
  double dp = 1.0 / (n1 - 1);
  rng = 17 + (uint64_t)dim;
  for (size_t i = 0; i < d.n; ++i) {
    size_t r = i;
    double vol = 1.0, db = INFINITY;
    for (int c = 0; c < dim; ++c) {
      int idx = (int)(r % (size_t)n1);
      r /= (size_t)n1;
      double X = idx * dp;
      int face = idx == 0 || idx == n1 - 1;
      /* jitter interior coordinates only, so faces stay on the box */
      if (!face)
        X += jitter * dp * (2 * urand() - 1);
      d.x[3 * i + c] = X;
      vol *= face ? 0.5 * dp : dp;
      db = fmin(db, fmin(X, 1.0 - X));
    }
    d.v[i] = vol;
    d.dist_to_boundary[i] = db;
  }
  sph_kernel_create(&d.k, kt, dim, 1.3 * dp, NULL);
  sph_neighbors_create(&d.nl, NULL);
  sph_neighbors_build(d.nl, d.x, d.n, dim, d.k.support, NULL, SPH_PAIRS_ALL,
                      NULL);
  d.c = (sph_cloud){.n = d.n, .dim = dim, .x = d.x, .volume = d.v, .nl = d.nl};
  *out = d;
  out->c.kernel = &out->k; /* points into the caller's struct */
}

static void release(cloud_data *d) {
  free(d->x);
  free(d->v);
  free(d->dist_to_boundary);
  sph_neighbors_destroy(d->nl);
}

static const double G[3][3] = {
    {1.3, -0.7, 0.4}, {0.2, 2.1, -1.1}, {-0.6, 0.5, 0.9}};

static void linear_field(const double *x, double f[3]) {
  for (int i = 0; i < 3; ++i)
    f[i] = 0.3 + G[i][0] * x[0] + G[i][1] * x[1] + G[i][2] * x[2];
}

/* worst |grad f - G| / |G| over particles (at the given kind) */
static double gradient_error(cloud_data *d, sph_gradient_kind kind,
                             double *boundary_error) {
  double *g = calloc(3 * d->nl->count + 3, sizeof *g);
  double *gs = calloc(3 * d->n, sizeof *gs);
  ck_assert_int_eq(sph_correction_gradient(&d->c, kind, g, gs, NULL, NULL),
                   SPH_OK);
  double worst = 0.0, gn = 0.0;
  *boundary_error = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < d->dim; ++j)
      gn += G[i][j] * G[i][j];
  gn = sqrt(gn);
  for (size_t a = 0; a < d->n; ++a) {
    double fa[3], D[9] = {0};
    linear_field(d->x + 3 * a, fa);
    for (size_t s = d->nl->offset[a]; s < d->nl->offset[a + 1]; ++s) {
      size_t b = (size_t)d->nl->index[s];
      double fb[3];
      linear_field(d->x + 3 * b, fb);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          D[3 * i + j] += d->v[b] *
                          (kind == SPH_GRAD_W1 ? fb[i] : fb[i] - fa[i]) *
                          g[3 * s + j];
    }
    if (kind == SPH_GRAD_W1)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          D[3 * i + j] += d->v[a] * fa[i] * gs[3 * a + j];
    double e = 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < d->dim; ++j)
        e += pow(D[3 * i + j] - G[i][j], 2);
    e = sqrt(e) / gn;
    worst = fmax(worst, e);
    if (d->dist_to_boundary[a] < 1e-12)
      *boundary_error = fmax(*boundary_error, e);
  }
  free(g);
  free(gs);
  return worst;
}

START_TEST(corrected_gradients_reproduce_linear_fields) {
  sph_kernel_type kinds[] = {SPH_KERNEL_CUBIC, SPH_KERNEL_WENDLAND_C2,
                             SPH_KERNEL_QUINTIC};
  for (int dim = 2; dim <= 3; ++dim)
    for (int kk = 0; kk < 3; ++kk)
      for (int jit = 0; jit < 2; ++jit) {
        cloud_data d;
        make_into(&d, dim, dim == 2 ? 13 : 8, jit ? 0.3 : 0.0, kinds[kk]);
        double be;
        sph_gradient_kind ks[] = {SPH_GRAD_CORRECTED, SPH_GRAD_CORRECTED_W0,
                                  SPH_GRAD_W1};
        for (int q = 0; q < 3; ++q) {
          double e = gradient_error(&d, ks[q], &be);
          ck_assert_msg(e <= 1e-10, "dim %d kernel %d jitter %d kind %d: %g",
                        dim, kk, jit, q, e);
        }
        /* the uncorrected gradient is wrong at the boundary */
        gradient_error(&d, SPH_GRAD_UNCORRECTED, &be);
        ck_assert_msg(be > 0.1, "uncorrected boundary error only %g", be);
        release(&d);
      }
}
END_TEST

/* Laplacian of f at every particle: sum_b V_b (f_b - f_a) lap_ab */
static void laplacian_errors(cloud_data *d, double (*f)(const double *),
                             double exact, double *worst_all,
                             double *worst_interior) {
  double *lap = calloc(d->nl->count + 1, sizeof *lap);
  ck_assert_int_eq(sph_correction_laplacian(&d->c, lap, NULL), SPH_OK);
  *worst_all = *worst_interior = 0.0;
  double support = d->k.support;
  for (size_t a = 0; a < d->n; ++a) {
    double s = 0.0, fa = f(d->x + 3 * a);
    for (size_t k = d->nl->offset[a]; k < d->nl->offset[a + 1]; ++k) {
      size_t b = (size_t)d->nl->index[k];
      s += d->v[b] * (f(d->x + 3 * b) - fa) * lap[k];
    }
    double e = fabs(s - exact);
    *worst_all = fmax(*worst_all, e);
    if (d->dist_to_boundary[a] > support)
      *worst_interior = fmax(*worst_interior, e);
  }
  free(lap);
}

static double f_linear(const double *x) {
  return 0.7 - 1.2 * x[0] + 0.4 * x[1] + 2.0 * x[2];
}
static double f_radial(const double *x) {
  return pow(x[0] - 0.3, 2) + pow(x[1] + 0.1, 2) + pow(x[2] - 0.2, 2);
}
static double f_quadratic(const double *x) {
  return x[0] * x[0] + 3 * x[0] * x[1] - x[1] * x[1] + 0.5 * x[2] * x[2];
}

START_TEST(corrected_laplacian) {
  for (int dim = 2; dim <= 3; ++dim)
    for (int jit = 0; jit < 2; ++jit) {
      cloud_data d;
      make_into(&d, dim, dim == 2 ? 15 : 9, jit ? 0.3 : 0.0, SPH_KERNEL_CUBIC);
      double all, in;
      /* Laplacian magnitudes here are O(1/dp^2): round-off ~ 1e-13/dp^2 */
      double tol = 1e-9;
      laplacian_errors(&d, f_linear, 0.0, &all, &in);
      ck_assert_msg(all < tol, "dim %d jit %d linear: %g", dim, jit, all);
      /* exact for the isotropic quadratic that A.4 imposes (Lap = 2d) */
      laplacian_errors(&d, f_radial, 2.0 * dim, &all, &in);
      ck_assert_msg(all < tol, "dim %d jit %d radial: %g", dim, jit, all);
      /* a general quadratic (Lap = 2 - 2 + (dim == 3)) is exact only where
       * the lattice is symmetric: the uniform interior */
      double exact = dim == 3 ? 1.0 : 0.0;
      laplacian_errors(&d, f_quadratic, exact, &all, &in);
      if (!jit)
        ck_assert_msg(in < tol, "dim %d uniform interior quadratic: %g", dim,
                      in);
      else
        printf("corrected Laplacian of x^2+3xy-y^2%s, %dD jittered 0.3 dp: "
               "worst error %.3g (interior %.3g)\n",
               dim == 3 ? "+z^2/2" : "", dim, all, in);
      release(&d);
    }
}
END_TEST

START_TEST(corrected_kernels) {
  for (int dim = 2; dim <= 3; ++dim) {
    cloud_data d;
    make_into(&d, dim, dim == 2 ? 12 : 7, 0.25, SPH_KERNEL_WENDLAND_C2);
    double *w = calloc(d.nl->count + 1, sizeof *w);
    double *ws = calloc(d.n, sizeof *ws);
    for (int order = 0; order <= 1; ++order) {
      ck_assert_int_eq(sph_correction_kernel(&d.c, order, w, ws, NULL), SPH_OK);
      double worst0 = 0.0, worst1 = 0.0;
      for (size_t a = 0; a < d.n; ++a) {
        double s = d.v[a] * ws[a], lin[3];
        for (int c = 0; c < 3; ++c)
          lin[c] = d.v[a] * ws[a] * d.x[3 * a + c];
        for (size_t k = d.nl->offset[a]; k < d.nl->offset[a + 1]; ++k) {
          size_t b = (size_t)d.nl->index[k];
          s += d.v[b] * w[k];
          for (int c = 0; c < 3; ++c)
            lin[c] += d.v[b] * w[k] * d.x[3 * b + c];
        }
        worst0 = fmax(worst0, fabs(s - 1.0));
        for (int c = 0; c < dim; ++c)
          worst1 = fmax(worst1, fabs(lin[c] - d.x[3 * a + c]));
      }
      ck_assert_msg(worst0 < 1e-13, "order %d partition of unity %g", order,
                    worst0);
      if (order == 1)
        ck_assert_msg(worst1 < 1e-13, "W~1 linear reproduction %g", worst1);
      else
        ck_assert_msg(worst1 > 1e-4, "W~0 should not reproduce x at the "
                                     "boundary");
    }
    free(w);
    free(ws);
    release(&d);
  }
}
END_TEST

START_TEST(singular_clouds_are_reported) {
  for (int dim = 2; dim <= 3; ++dim) {
    /* a line of particles along x, plus a lone particle far away */
    size_t n = 12;
    double *x = calloc(3 * n, sizeof *x), *v = calloc(n, sizeof *v);
    int64_t *id = calloc(n, sizeof *id);
    for (size_t i = 0; i < n; ++i) {
      x[3 * i] = 0.1 * (double)i;
      v[i] = 0.001;
      id[i] = 100 + (int64_t)i;
    }
    sph_kernel k;
    sph_kernel_create(&k, SPH_KERNEL_CUBIC, dim, 0.13, NULL);
    sph_neighbors *nl;
    sph_neighbors_create(&nl, NULL);
    sph_neighbors_build(nl, x, n, dim, k.support, NULL, SPH_PAIRS_ALL, NULL);
    sph_cloud c = {.n = n,
                   .dim = dim,
                   .x = x,
                   .volume = v,
                   .id = id,
                   .nl = nl,
                   .kernel = &k};
    double *g = calloc(3 * nl->count + 3, sizeof *g), *w = calloc(n, sizeof *w);
    sph_error err;
    sph_gradient_kind kinds[] = {SPH_GRAD_CORRECTED, SPH_GRAD_CORRECTED_W0,
                                 SPH_GRAD_W1};
    for (int q = 0; q < 3; ++q) {
      ck_assert_int_eq(
          sph_correction_gradient(&c, kinds[q], g, NULL, NULL, &err),
          SPH_ERR_SINGULAR);
      ck_assert_ptr_nonnull(strstr(err.message, "particle 100"));
    }
    ck_assert_int_eq(sph_correction_laplacian(&c, g, &err), SPH_ERR_SINGULAR);
    ck_assert_int_eq(sph_correction_kernel(&c, 1, g, w, &err),
                     SPH_ERR_SINGULAR);
    /* a lone particle */
    sph_neighbors_build(nl, x, 1, dim, k.support, NULL, SPH_PAIRS_ALL, NULL);
    c.n = 1;
    ck_assert_int_eq(
        sph_correction_gradient(&c, SPH_GRAD_CORRECTED, g, NULL, NULL, &err),
        SPH_ERR_SINGULAR);
    ck_assert_ptr_nonnull(strstr(err.message, "0 neighbours"));
    free(g);
    free(w);
    free(x);
    free(v);
    free(id);
    sph_neighbors_destroy(nl);
  }
}
END_TEST

int main(void) {
  Suite *s = suite_create("corrections");
  TCase *tc = tcase_create("corrections");
  tcase_set_timeout(tc, 60);
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, corrected_gradients_reproduce_linear_fields);
  tcase_add_test(tc, corrected_laplacian);
  tcase_add_test(tc, corrected_kernels);
  tcase_add_test(tc, singular_clouds_are_reported);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
