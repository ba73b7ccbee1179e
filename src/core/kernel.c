/* Smoothing kernels with 1D/2D/3D normalisation: cubic B-spline
 * (Monaghan & Lattanzio 1985, support 2h), quintic spline (Morris 1996,
 * support 3h), Wendland C2 and C4 (Wendland 1995; Dehnen & Aly 2012,
 * support 2h, as SPHinXsys uses them, seed 002 sec. 6). In 1D the Wendland
 * functions of the matching smoothness for d = 1 are used. */
#include "core/kernel.h"

#include "core/check.h"

#include <math.h>
#include <string.h>

static const char *const kernel_names[] = {
#define K_NAME(e, name) name,
    SPH_KERNEL_LIST(K_NAME)
#undef K_NAME
};

int sph_kernel_type_from_name(const char *name) {
  for (int k = 0; k < SPH_KERNEL_COUNT; ++k)
    if (strcmp(kernel_names[k], name) == 0)
      return k;
  return -1;
}

const char *sph_kernel_type_name(sph_kernel_type type) {
  return (int)type >= 0 && type < SPH_KERNEL_COUNT ? kernel_names[type]
                                                   : "unknown";
}

/* sigma_d for q = r/h: W = sigma_d / h^d f(q) */
static double kernel_sigma(sph_kernel_type type, int dim) {
  switch (type) {
  case SPH_KERNEL_CUBIC: {
    static const double s[4] = {0, 2.0 / 3.0, 10.0 / (7.0 * M_PI), 1.0 / M_PI};
    return s[dim];
  }
  case SPH_KERNEL_QUINTIC: {
    static const double s[4] = {0, 1.0 / 120.0, 7.0 / (478.0 * M_PI),
                                1.0 / (120.0 * M_PI)};
    return s[dim];
  }
  case SPH_KERNEL_WENDLAND_C2: {
    static const double s[4] = {0, 5.0 / 8.0, 7.0 / (4.0 * M_PI),
                                21.0 / (16.0 * M_PI)};
    return s[dim];
  }
  case SPH_KERNEL_WENDLAND_C4: {
    static const double s[4] = {0, 3.0 / 4.0, 9.0 / (4.0 * M_PI),
                                495.0 / (256.0 * M_PI)};
    return s[dim];
  }
  default:
    return 0.0;
  }
}

/* f(q), f'(q), f''(q) of each kernel */
static void kernel_shape(sph_kernel_type type, int dim, double q, double *f,
                         double *df, double *d2f) {
  *f = *df = *d2f = 0.0;
  switch (type) {
  case SPH_KERNEL_CUBIC:
    if (q < 1.0) {
      *f = 1.0 - 1.5 * q * q + 0.75 * q * q * q;
      *df = -3.0 * q + 2.25 * q * q;
      *d2f = -3.0 + 4.5 * q;
    } else if (q < 2.0) {
      double t = 2.0 - q;
      *f = 0.25 * t * t * t;
      *df = -0.75 * t * t;
      *d2f = 1.5 * t;
    }
    return;
  case SPH_KERNEL_QUINTIC: {
    /* (3-q)^5 - 6 (2-q)^5 + 15 (1-q)^5 on the pieces */
    static const double c[3] = {1.0, -6.0, 15.0};
    for (int k = 0; k < 3; ++k) {
      double t = 3.0 - q - (double)k;
      if (t <= 0.0)
        continue;
      double t2 = t * t;
      *f += c[k] * t2 * t2 * t;
      *df -= 5.0 * c[k] * t2 * t2;
      *d2f += 20.0 * c[k] * t2 * t;
    }
    return;
  }
  case SPH_KERNEL_WENDLAND_C2:
    if (q < 2.0) {
      double t = 1.0 - 0.5 * q;
      if (dim == 1) { /* (1 - q/2)^3 (1.5 q + 1) */
        *f = t * t * t * (1.5 * q + 1.0);
        *df = -1.5 * t * t * (1.5 * q + 1.0) + 1.5 * t * t * t;
        *d2f = 1.5 * t * (1.5 * q + 1.0) - 4.5 * t * t;
      } else { /* (1 - q/2)^4 (2 q + 1) */
        double t3 = t * t * t;
        *f = t3 * t * (2.0 * q + 1.0);
        *df = -5.0 * q * t3;
        *d2f = -5.0 * t3 + 7.5 * q * t * t;
      }
    }
    return;
  case SPH_KERNEL_WENDLAND_C4:
    if (q < 2.0) {
      double t = 1.0 - 0.5 * q;
      if (dim == 1) { /* (1 - q/2)^5 (2 q^2 + 2.5 q + 1) */
        double t4 = t * t * t * t, p = 2.0 * q * q + 2.5 * q + 1.0;
        double dp = 4.0 * q + 2.5;
        *f = t4 * t * p;
        *df = -2.5 * t4 * p + t4 * t * dp;
        *d2f = 5.0 * t * t * t * p - 5.0 * t4 * dp + 4.0 * t4 * t;
      } else { /* (1 - q/2)^6 (35/12 q^2 + 3 q + 1) */
        double t5 = t * t * t * t * t;
        double p = 35.0 / 12.0 * q * q + 3.0 * q + 1.0;
        double dp = 35.0 / 6.0 * q + 3.0;
        *f = t5 * t * p;
        *df = -3.0 * t5 * p + t5 * t * dp;
        *d2f = 7.5 * t * t * t * t * p - 6.0 * t5 * dp + 35.0 / 6.0 * t5 * t;
      }
    }
    return;
  default:
    return;
  }
}

sph_status sph_kernel_create(sph_kernel *k, sph_kernel_type type, int dim,
                             double h, sph_error *err) {
  if ((int)type < 0 || type >= SPH_KERNEL_COUNT)
    return sph_error_set(err, SPH_ERR_ARG, "unknown kernel type %d", (int)type);
  if (dim < 1 || dim > 3)
    return sph_error_set(err, SPH_ERR_ARG, "dimension %d is not 1, 2 or 3",
                         dim);
  if (!isfinite(h) || !(h > 0.0))
    return sph_error_set(err, SPH_ERR_ARG,
                         "smoothing length %g is not "
                         "positive",
                         h);
  k->type = type;
  k->dim = dim;
  k->h = h;
  k->kappa = type == SPH_KERNEL_QUINTIC ? 3.0 : 2.0;
  k->support = k->kappa * h;
  k->norm = kernel_sigma(type, dim) / pow(h, dim);
  SPH_CHECK(k->support > 0.0 && isfinite(k->support) && k->norm > 0.0 &&
                isfinite(k->norm),
            err, "%s kernel of h = %g: support %g, normalisation %g",
            kernel_names[type], h, k->support, k->norm);
  return SPH_OK;
}

double sph_kernel_eval(const sph_kernel *k, double r) {
  double f, df, d2f;
  kernel_shape(k->type, k->dim, r / k->h, &f, &df, &d2f);
  return k->norm * f;
}

double sph_kernel_dwdr(const sph_kernel *k, double r) {
  double f, df, d2f;
  kernel_shape(k->type, k->dim, r / k->h, &f, &df, &d2f);
  return k->norm * df / k->h;
}

double sph_kernel_d2wdr2(const sph_kernel *k, double r) {
  double f, df, d2f;
  kernel_shape(k->type, k->dim, r / k->h, &f, &df, &d2f);
  return k->norm * d2f / (k->h * k->h);
}

void sph_kernel_gradient(const sph_kernel *k, const double rab[3], double r,
                         double grad[3]) {
  if (r <= 0.0) {
    grad[0] = grad[1] = grad[2] = 0.0;
    return;
  }
  double s = sph_kernel_dwdr(k, r) / r;
  grad[0] = s * rab[0];
  grad[1] = s * rab[1];
  grad[2] = s * rab[2];
}

double sph_kernel_laplacian(const sph_kernel *k, double r) {
  double f, df, d2f, q = r / k->h;
  kernel_shape(k->type, k->dim, q, &f, &df, &d2f);
  /* W'/r -> W''(0) as r -> 0 (f'(0) = 0 for every kernel here) */
  double df_over_q = q > 1e-12 ? df / q : d2f;
  return k->norm / (k->h * k->h) * (d2f + (double)(k->dim - 1) * df_over_q);
}
