/* Tensor helpers (include/sph/tensor.h): determinant, inverse, cofactor =
 * det A^-T = 1/2 A x A, identities of the tensor cross product of seed 000
 * (eq. 1c, 12), products, double contraction, outer product. Random
 * matrices have O(1) entries, so sums of k products of m factors carry
 * round-off below ~k m eps; tolerances are set from that. */
#include "test_util.h"

#include <float.h>
#include <math.h>
#include <stdint.h>

#include "core/tensor.h"

static uint64_t rng = 3;
static double urand(void) {
  uint64_t z = (rng += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

static void random_mat(double A[9]) {
  for (int k = 0; k < 9; ++k)
    A[k] = (k % 4 == 0) + (2 * urand() - 1);
}

static double max_diff(const double *a, const double *b, int n) {
  double m = 0.0;
  for (int k = 0; k < n; ++k)
    m = fmax(m, fabs(a[k] - b[k]));
  return m;
}

/* reference product by index loops */
static void mul_ref(const double A[9], const double B[9], double C[9]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      C[3 * i + j] = 0.0;
      for (int k = 0; k < 3; ++k)
        C[3 * i + j] += A[3 * i + k] * B[3 * k + j];
    }
}

/* reference tensor cross product from the permutation symbol */
static int eps3(int i, int j, int k) { return (i - j) * (j - k) * (k - i) / 2; }
static void cross_ref(const double A[9], const double B[9], double C[9]) {
  for (int i = 0; i < 3; ++i)
    for (int I = 0; I < 3; ++I) {
      double s = 0.0;
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          for (int J = 0; J < 3; ++J)
            for (int K = 0; K < 3; ++K)
              s += eps3(i, j, k) * eps3(I, J, K) * A[3 * j + J] * B[3 * k + K];
      C[3 * i + I] = s;
    }
}

START_TEST(determinant) {
  double A[9] = {2, -1, 0, 1, 3, 4, 0, 5, -2};
  /* 2 (-6 - 20) + 1 (-2 - 0) + 0 = -54 */
  ck_assert(sph_mat3_det(A) == -54.0);
  double worst = 0.0;
  for (int t = 0; t < 200; ++t) {
    double B[9], C[9], AB[9], At[9];
    random_mat(A);
    random_mat(B);
    sph_mat3_mul(A, B, AB);
    sph_mat3_transpose(A, At);
    worst =
        fmax(worst, fabs(sph_mat3_det(AB) - sph_mat3_det(A) * sph_mat3_det(B)));
    worst = fmax(worst, fabs(sph_mat3_det(At) - sph_mat3_det(A)));
    /* a repeated row gives zero to round-off, a zero row exactly */
    for (int k = 0; k < 9; ++k)
      C[k] = A[k];
    for (int k = 0; k < 3; ++k)
      C[6 + k] = C[k];
    worst = fmax(worst, fabs(sph_mat3_det(C)));
    for (int k = 0; k < 3; ++k)
      C[3 + k] = 0.0;
    ck_assert(sph_mat3_det(C) == 0.0);
  }
  /* entries of AB are O(3), det a sum of 6 triple products: 1e-13 */
  ck_assert_msg(worst < 1e-13, "det identities: %g", worst);
}
END_TEST

START_TEST(inverse_cofactor_and_cross) {
  double worst_inv = 0, worst_cof = 0, worst_cross = 0, worst_sym = 0;
  int tested = 0;
  for (int t = 0; t < 200; ++t) {
    double A[9], B[9], C[9], Ainv[9] = {0}, I[9], P[9], H[9], X[9], R[9];
    random_mat(A);
    random_mat(B);
    random_mat(C);
    double det = sph_mat3_inverse(A, Ainv);
    ck_assert(det == sph_mat3_det(A));
    if (fabs(det) < 1e-2)
      continue;
    ++tested;
    /* A A^-1 = A^-1 A = I; the error grows with cond(A) <~ ||A|| ||H|| /
     * |det| <~ 1e3 here */
    double cond = sph_mat3_norm1(A) * sph_mat3_norm1(Ainv);
    sph_mat3_identity(I);
    sph_mat3_mul(A, Ainv, P);
    worst_inv = fmax(worst_inv, max_diff(P, I, 9) / (cond * DBL_EPSILON));
    sph_mat3_mul(Ainv, A, P);
    worst_inv = fmax(worst_inv, max_diff(P, I, 9) / (cond * DBL_EPSILON));
    /* H = det(A) A^-T = 1/2 A x A */
    sph_mat3_cofactor(A, H);
    double AinvT[9];
    sph_mat3_transpose(Ainv, AinvT);
    for (int k = 0; k < 9; ++k)
      AinvT[k] *= det;
    worst_cof = fmax(worst_cof, max_diff(H, AinvT, 9) / (cond * DBL_EPSILON));
    sph_mat3_tensor_cross(A, A, X);
    for (int k = 0; k < 9; ++k)
      X[k] *= 0.5;
    worst_cross = fmax(worst_cross, max_diff(H, X, 9));
    /* against the permutation-symbol definition; A x B = B x A */
    sph_mat3_tensor_cross(A, B, X);
    cross_ref(A, B, R);
    worst_cross = fmax(worst_cross, max_diff(X, R, 9));
    sph_mat3_tensor_cross(B, A, R);
    worst_cross = fmax(worst_cross, max_diff(X, R, 9));
    /* (A x B) : C is symmetric in its three arguments, (A x A) : A =
     * 6 det A */
    double ab[9], bc[9], ca[9];
    sph_mat3_tensor_cross(A, B, ab);
    sph_mat3_tensor_cross(B, C, bc);
    sph_mat3_tensor_cross(C, A, ca);
    double s1 = sph_mat3_ddot(ab, C), s2 = sph_mat3_ddot(bc, A),
           s3 = sph_mat3_ddot(ca, B);
    worst_sym = fmax(worst_sym, fmax(fabs(s1 - s2), fabs(s1 - s3)));
    sph_mat3_tensor_cross(A, A, X);
    worst_sym = fmax(worst_sym, fabs(sph_mat3_ddot(X, A) - 6 * det));
    /* cof(A B) = cof(A) cof(B) */
    double AB[9], HAB[9], HB[9], HAHB[9];
    sph_mat3_mul(A, B, AB);
    sph_mat3_cofactor(AB, HAB);
    sph_mat3_cofactor(B, HB);
    sph_mat3_mul(H, HB, HAHB);
    worst_cof = fmax(worst_cof, max_diff(HAB, HAHB, 9) / (cond * DBL_EPSILON));
  }
  ck_assert(tested > 150);
  ck_assert_msg(worst_inv < 20, "A A^-1 - I: %g cond eps", worst_inv);
  ck_assert_msg(worst_cof < 200, "cofactor identities: %g cond eps", worst_cof);
  ck_assert_msg(worst_cross < 1e-14, "cross product: %g", worst_cross);
  ck_assert_msg(worst_sym < 1e-13, "cross product symmetry: %g", worst_sym);
}
END_TEST

START_TEST(cross_with_identity) {
  /* A x I = (tr A) I - A^T, I x I = 2 I */
  double worst = 0.0;
  for (int t = 0; t < 20; ++t) {
    double A[9], I[9], X[9], E[9];
    random_mat(A);
    sph_mat3_identity(I);
    sph_mat3_tensor_cross(A, I, X);
    sph_mat3_transpose(A, E);
    for (int k = 0; k < 9; ++k)
      E[k] = (k % 4 == 0) * sph_mat3_trace(A) - E[k];
    worst = fmax(worst, max_diff(X, E, 9));
    sph_mat3_tensor_cross(I, I, X);
    for (int k = 0; k < 9; ++k)
      ck_assert(X[k] == 2.0 * I[k]);
  }
  ck_assert(worst < 1e-14);
}
END_TEST

START_TEST(products_and_small_helpers) {
  double A[9], B[9], C[9], R[9];
  random_mat(A);
  random_mat(B);
  /* product against index loops, also in place */
  sph_mat3_mul(A, B, C);
  mul_ref(A, B, R);
  ck_assert(max_diff(C, R, 9) < 1e-15);
  double Ac[9];
  for (int k = 0; k < 9; ++k)
    Ac[k] = A[k];
  sph_mat3_mul(Ac, B, Ac);
  ck_assert(max_diff(Ac, R, 9) < 1e-15);
  /* A : B = tr(A^T B) */
  double At[9], AtB[9];
  sph_mat3_transpose(A, At);
  sph_mat3_mul(At, B, AtB);
  ck_assert(fabs(sph_mat3_ddot(A, B) - sph_mat3_trace(AtB)) < 1e-14);
  /* transpose in place */
  sph_mat3_transpose(At, At);
  ck_assert(max_diff(At, A, 9) == 0.0);
  /* y = A x, in place */
  double x[3] = {0.3, -1.2, 2.0}, y[3];
  sph_mat3_vec(A, x, y);
  for (int i = 0; i < 3; ++i)
    ck_assert(fabs(y[i] - (A[3 * i] * x[0] + A[3 * i + 1] * x[1] +
                           A[3 * i + 2] * x[2])) < 1e-15);
  sph_mat3_vec(A, x, x);
  ck_assert(max_diff(x, y, 3) == 0.0);
  /* vectors */
  double a[3] = {1, 2, 3}, b[3] = {-2, 0.5, 4}, c[3];
  sph_vec3_cross(a, b, c);
  ck_assert(fabs(sph_vec3_dot(c, a)) < 1e-15 &&
            fabs(sph_vec3_dot(c, b)) < 1e-15);
  ck_assert(c[0] == 2 * 4 - 3 * 0.5 && c[1] == 3 * -2 - 1 * 4 &&
            c[2] == 1 * 0.5 - 2 * -2);
  ck_assert(fabs(sph_vec3_norm(a) - sqrt(14.0)) < 1e-15);
  /* outer product: M_ij = a_i b_j, (a (x) b) a = a (b . a) */
  double M[9] = {0}, v[3];
  sph_mat3_add_outer(M, a, b);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      ck_assert(M[3 * i + j] == a[i] * b[j]);
  sph_mat3_vec(M, a, v);
  for (int i = 0; i < 3; ++i)
    ck_assert(fabs(v[i] - a[i] * sph_vec3_dot(b, a)) < 1e-14);
  /* 1-norm: largest absolute column sum */
  ck_assert(sph_mat3_norm1(M) == fabs(b[2]) * (1 + 2 + 3));
  /* singular matrices: inverse returns 0 and leaves the output alone */
  double S[9] = {0}, Sinv[9] = {7, 7, 7, 7, 7, 7, 7, 7, 7};
  ck_assert(sph_mat3_inverse(S, Sinv) == 0.0);
  for (int k = 0; k < 9; ++k)
    ck_assert(Sinv[k] == 7.0);
  double I[9];
  sph_mat3_identity(I);
  ck_assert(sph_mat3_trace(I) == 3.0 && sph_mat3_det(I) == 1.0);
  sph_mat3_zero(I);
  ck_assert(sph_mat3_norm1(I) == 0.0);
}
END_TEST

/* Jacobi eigen-decomposition: Q diag(w) Q^T = A, Q orthonormal, also for
 * repeated and already diagonal cases */
START_TEST(symmetric_eigen) {
  const double cases[3][9] = {{2, 1, 0.5, 1, 3, -0.2, 0.5, -0.2, -1},
                              {5, 2, 0, 2, -1, 0, 0, 0, -3},
                              {4, 0, 0, 0, 4, 0, 0, 0, 1}};
  for (int k = 0; k < 3; ++k) {
    const double *A = cases[k];
    double w[3], Q[9];
    sph_mat3_sym_eigen(A, w, Q);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        double a = 0.0, q = 0.0;
        for (int i = 0; i < 3; ++i) {
          a += Q[3 * r + i] * w[i] * Q[3 * c + i];
          q += Q[3 * i + r] * Q[3 * i + c];
        }
        ck_assert_double_eq_tol(a, A[3 * r + c], 1e-13);
        ck_assert_double_eq_tol(q, r == c, 1e-14);
      }
  }
}
END_TEST

int main(void) {
  Suite *s = suite_create("tensor");
  TCase *tc = tcase_create("tensor");
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, determinant);
  tcase_add_test(tc, inverse_cofactor_and_cross);
  tcase_add_test(tc, cross_with_identity);
  tcase_add_test(tc, products_and_small_helpers);
  tcase_add_test(tc, symmetric_eigen);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
