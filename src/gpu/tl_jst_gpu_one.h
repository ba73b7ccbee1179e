/* The tl-jst pF time step (seed 000 Algorithm 1 with the conservative force
 * of eq. 42, TVD-RK2 eq. 43 or SSP-RK3 of seed 004 eq. 30, clamped
 * particles held at zero momentum) as one function per particle over plain
 * arrays: a CUDA kernel (tl_jst_gpu.cu) calls each for its thread's index,
 * the host twin (tl_jst_twin.c, compiled as C in every build) in a plain
 * loop, so the device algorithm is checked on a machine without a GPU. The
 * pair physics is methods/common/pair_iact.h's and the stress
 * materials/neo_hookean_law.h's, in the CPU method's order of operations
 * (methods/tl_jst/tl_jst.c), with the JST dissipation on p of eq. 35-38
 * (terms/jst_dissipation.c, without the projection of eq. 49): the twin
 * equals the CPU step to the bit. */
#ifndef SPH_TL_JST_GPU_ONE_H
#define SPH_TL_JST_GPU_ONE_H

#include <stddef.h>
#include <stdint.h>

#include "core/hd.h"
#include "core/tensor.h"
#include "materials/neo_hookean_law.h"
#include "methods/common/pair_iact.h"
#include "terms/momentum_projection.h"

/* Plain arrays of the step, host or device memory alike: the reference
 * configuration (fixed for a total-Lagrangian method: the neighbour lists
 * are built once, at set-up), the state, its RK copies and rates. */
typedef struct sph_gpu_tl_jst {
  size_t n;             /* particles */
  const size_t *offset; /* n + 1 */
  const int32_t *index; /* neighbour slots */
  const double *w;      /* V_b W'(r_ab) / r_ab per slot */
  const double *lap;    /* V_b Lap W~_b(X_a) per slot, NULL without JST */
  const double *X, *L, *s, *rho0; /* 3n, 9n, 3n, n */
  const double *mu, *kappa;       /* neo-Hookean moduli per particle */
  const unsigned char *fixed;     /* per particle, bit c: p_c held at 0 */
  double *x, *p, *F;              /* state */
  double *x0, *p0, *F0;           /* the step's start */
  double *dx, *dp, *dF;           /* rates */
  double *Qt;                     /* (P L)^T per particle (9n) */
  double *lu;    /* L[p] for the JST term (3n), NULL without it */
  double c2, c4; /* JST: eps2 c_p h and eps4 c_p h^3 (seed 000 eq. 35) */
  /* the momentum projections of eq. 45-49: of the force (amp) and of the
   * JST term (d, its D(p), 3n, NULL without); about X^chi of eq. 45 (xm,
   * 3n: x^n + dt / (2 rho0) (p^n + p*) in TVD-RK2's second stage when
   * xmom, else x) */
  int amp, xmom;
  double *d, *xm;
  const double *V;     /* reference volumes (n) */
  const int32_t *body; /* body per particle (n) */
  int nbodies;
  double *part; /* SPH_PROJ_BLOCKS x 12 block sums */
  double *coef; /* a body's sums and coefficients (SPH_GPU_COEF) */
} sph_gpu_tl_jst;

/* coef: 7 sums with the centroid, 12 sums, lambda, mu, and a flag (the
 * body has volume) */
enum { SPH_GPU_COEF = 26 };

/* Q_a = P_a L_a, transposed, of the stress of F_a (compute_stress) */
SPH_HD static inline void sph_gpu_stress_one(size_t a,
                                             const sph_gpu_tl_jst *g) {
  const double *Fa = g->F + 9 * a;
  double Ha[9], P[9], Q[9];
  sph_mat3_cofactor(Fa, Ha);
  double Ja = sph_mat3_det(Fa);
  sph_neo_hookean_law(g->mu[a], g->kappa[a], Fa, Ha, Ja, P);
  sph_mat3_mul(P, g->L + 9 * a, Q);
  sph_mat3_transpose(Q, g->Qt + 9 * a);
}

/* The rates of particle a (sweep_conservative, particle_rates): the pair
 * sums of the momentum gradient and the force in slot order, then
 * dF = G L^T / rho0, dp = f + Q_a s_a, dx = p / rho0; with lap, L[p] */
SPH_HD static inline void sph_gpu_rates_one(size_t a, const sph_gpu_tl_jst *g) {
  const double *Xa = g->X + 3 * a, *pa = g->p + 3 * a;
  double G[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, f[3] = {0, 0, 0};
  double l[3] = {0, 0, 0};
  for (size_t k = g->offset[a]; k < g->offset[a + 1]; ++k) {
    size_t b = (size_t)g->index[k];
    const double *Xb = g->X + 3 * b, *pb = g->p + 3 * b;
    double r[3] = {Xa[0] - Xb[0], Xa[1] - Xb[1], Xa[2] - Xb[2]};
    ref_iact_gradient(G, g->w[k], pa, pb, r);
    if (g->lap)
      ref_iact_laplacian(l, g->lap[k], pa, pb);
    ref_iact_force(f, g->w[k], g->Qt + 9 * b, r);
  }
  double self[3];
  ref_iact_force_self(g->Qt + 9 * a, g->s + 3 * a, self);
  for (int c = 0; c < 3; ++c)
    f[c] += self[c];
  double inv_rho0 = 1.0 / g->rho0[a];
  ref_iact_gradient_correct(G, g->L + 9 * a);
  for (int k = 0; k < 9; ++k)
    g->dF[9 * a + k] = G[k] * inv_rho0;
  /* with projections or JST the clamp comes after them
   * (sph_gpu_finish_one) */
  unsigned fix = g->fixed && !g->lu && !g->amp ? g->fixed[a] : 0u;
  for (int c = 0; c < 3; ++c) {
    g->dp[3 * a + c] = (fix & (1u << c)) ? 0.0 : f[c];
    g->dx[3 * a + c] = pa[c] * inv_rho0;
  }
  if (g->lu)
    for (int c = 0; c < 3; ++c)
      g->lu[3 * a + c] = l[c];
}

/* The JST term of particle a, once every L[p] is in (jst_rates):
 * D = c2 L[p] - c4 L[L[p]] (D = c2 L[p] when c4 = 0), into d for the
 * projection, else added to dp */
SPH_HD static inline void sph_gpu_jst_one(size_t a, const sph_gpu_tl_jst *g) {
  const double *la = g->lu + 3 * a;
  double d[3];
  if (g->c4 != 0.0) {
    double s[3] = {0.0, 0.0, 0.0};
    for (size_t k = g->offset[a]; k < g->offset[a + 1]; ++k) {
      const double *lb = g->lu + 3 * (size_t)g->index[k];
      s[0] += g->lap[k] * (lb[0] - la[0]);
      s[1] += g->lap[k] * (lb[1] - la[1]);
      s[2] += g->lap[k] * (lb[2] - la[2]);
    }
    for (int c = 0; c < 3; ++c)
      d[c] = g->c2 * la[c] + -g->c4 * s[c];
  } else {
    for (int c = 0; c < 3; ++c)
      d[c] = g->c2 * la[c];
  }
  for (int c = 0; c < 3; ++c) {
    if (g->d)
      g->d[3 * a + c] = d[c];
    else
      g->dp[3 * a + c] += d[c];
  }
}

/* After the projections and JST: dp += D (projected), then the clamp */
SPH_HD static inline void sph_gpu_finish_one(size_t a,
                                             const sph_gpu_tl_jst *g) {
  unsigned fix = g->fixed ? g->fixed[a] : 0u;
  for (int c = 0; c < 3; ++c) {
    if (g->d)
      g->dp[3 * a + c] += g->d[3 * a + c];
    if (fix & (1u << c))
      g->dp[3 * a + c] = 0.0;
  }
}

/* X^chi of eq. 45 in TVD-RK2's second stage (tl_jst_rhs) */
SPH_HD static inline void sph_gpu_xmoment_one(size_t a, const sph_gpu_tl_jst *g,
                                              double dt) {
  for (int c = 0; c < 3; ++c)
    g->xm[3 * a + c] =
        g->x0[3 * a + c] +
        0.5 * dt * (g->p0[3 * a + c] + g->p[3 * a + c]) / g->rho0[a];
}

/* Block k's sums of body b for the projection of w about X: 7 (xc NULL) or
 * 12 (about the centroid in coef + 1) */
SPH_HD static inline void sph_gpu_proj_block_one(int k, const sph_gpu_tl_jst *g,
                                                 const double *X,
                                                 const double *w, int b,
                                                 int second) {
  double *s = g->part + 12 * k;
  for (int c = 0; c < 12; ++c)
    s[c] = 0.0;
  if (second && !g->coef[25])
    return;
  size_t lo, hi;
  sph_proj_block_range(g->n, k, &lo, &hi);
  if (lo < hi)
    sph_proj_block_sums(lo, hi, g->V, X, g->body, b, w,
                        second ? g->coef + 1 : NULL, s);
}

/* the blocks added in order: the centroid (first), or lambda and mu
 * (second) */
SPH_HD static inline void sph_gpu_proj_finish(const sph_gpu_tl_jst *g,
                                              int second) {
  double *q = g->coef;
  if (!second) {
    sph_proj_add_blocks(g->part, 7, q);
    q[25] = sph_proj_centroid(q);
  } else if (q[25]) {
    sph_proj_add_blocks(g->part, 12, q + 7);
    sph_proj_coefficients(q, q + 7, q + 19, q + 22);
  }
}

/* w_a corrected, for a particle of body b when the body has volume */
SPH_HD static inline void sph_gpu_proj_apply_one(size_t a,
                                                 const sph_gpu_tl_jst *g,
                                                 const double *X, double *w,
                                                 int b) {
  const double *q = g->coef;
  if (q[25] && g->body[a] == b)
    sph_proj_apply_one(a, X, q + 1, q + 19, q + 22, w);
}

/* y0 = y for particle a's x, p and F */
SPH_HD static inline void sph_gpu_save_one(size_t a, const sph_gpu_tl_jst *g) {
  for (int c = 0; c < 3; ++c) {
    g->x0[3 * a + c] = g->x[3 * a + c];
    g->p0[3 * a + c] = g->p[3 * a + c];
  }
  for (int k = 0; k < 9; ++k)
    g->F0[9 * a + k] = g->F[9 * a + k];
}

/* one Runge-Kutta stage's combination y = ca y0 + cb (y + dt rate) for
 * particle a (integrators/runge_kutta.c), then the clamp on p */
SPH_HD static inline void sph_gpu_combine_one(size_t a, const sph_gpu_tl_jst *g,
                                              double ca, double cb, double dt) {
  for (int c = 0; c < 3; ++c) {
    size_t i = 3 * a + c;
    g->x[i] = ca * g->x0[i] + cb * (g->x[i] + dt * g->dx[i]);
    g->p[i] = ca * g->p0[i] + cb * (g->p[i] + dt * g->dp[i]);
  }
  for (int k = 0; k < 9; ++k) {
    size_t i = 9 * a + k;
    g->F[i] = ca * g->F0[i] + cb * (g->F[i] + dt * g->dF[i]);
  }
  unsigned fix = g->fixed ? g->fixed[a] : 0u;
  for (int c = 0; c < 3; ++c)
    if (fix & (1u << c))
      g->p[3 * a + c] = 0.0;
}

/* The stages' coefficients (ca, cb) of the integrators: TVD-RK2 (2 stages)
 * and SSP-RK3 (3 stages) */
SPH_HD static inline void sph_gpu_rk_coefficients(int stages, int k, double *ca,
                                                  double *cb) {
  if (stages == 2) {
    *ca = k == 0 ? 0.0 : 0.5;
    *cb = k == 0 ? 1.0 : 0.5;
  } else {
    *ca = k == 0 ? 0.0 : k == 1 ? 0.75 : 1.0 / 3.0;
    *cb = k == 0 ? 1.0 : k == 1 ? 0.25 : 2.0 / 3.0;
  }
}

#endif
