/* Tensor helpers: determinant, inverse, cofactor = det A^-T = 1/2 A x A,
 * identities of the tensor cross product of seed 000. */
#include "test_util.h"

#include <math.h>
#include <stdint.h>

#include "sph/tensor.h"

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

START_TEST(inverse_cofactor_and_cross) {
  double worst_inv = 0, worst_cof = 0, worst_cross = 0, worst_sym = 0;
  for (int t = 0; t < 200; ++t) {
    double A[9], B[9], C[9], Ainv[9], I[9], P[9], H[9], X[9];
    random_mat(A);
    random_mat(B);
    random_mat(C);
    double det = sph_mat3_inverse(A, Ainv);
    if (fabs(det) < 1e-3)
      continue;
    sph_mat3_mul(A, Ainv, P);
    sph_mat3_identity(I);
    worst_inv = fmax(worst_inv, max_diff(P, I, 9));
    /* H = det(A) A^-T = 1/2 A x A */
    sph_mat3_cofactor(A, H);
    double AinvT[9];
    sph_mat3_transpose(Ainv, AinvT);
    for (int k = 0; k < 9; ++k)
      AinvT[k] *= det;
    worst_cof = fmax(worst_cof, max_diff(H, AinvT, 9));
    sph_mat3_tensor_cross(A, A, X);
    for (int k = 0; k < 9; ++k)
      X[k] *= 0.5;
    worst_cross = fmax(worst_cross, max_diff(H, X, 9));
    /* (A x B) : C is symmetric in its three arguments, and
     * (A x A) : A = 6 det A */
    double ab[9], bc[9];
    sph_mat3_tensor_cross(A, B, ab);
    sph_mat3_tensor_cross(B, C, bc);
    worst_sym =
        fmax(worst_sym, fabs(sph_mat3_ddot(ab, C) - sph_mat3_ddot(bc, A)));
    sph_mat3_tensor_cross(A, A, X);
    worst_sym = fmax(worst_sym, fabs(sph_mat3_ddot(X, A) - 6 * det));
  }
  ck_assert_msg(worst_inv < 1e-11, "A A^-1 - I: %g", worst_inv);
  ck_assert_msg(worst_cof < 1e-12, "cof - det A^-T: %g", worst_cof);
  ck_assert_msg(worst_cross < 1e-14, "cof - A x A / 2: %g", worst_cross);
  ck_assert_msg(worst_sym < 1e-12, "cross product symmetry: %g", worst_sym);
}
END_TEST

START_TEST(cross_with_identity) {
  /* A x I = (tr A) I - A^T */
  double A[9], I[9], X[9], E[9];
  random_mat(A);
  sph_mat3_identity(I);
  sph_mat3_tensor_cross(A, I, X);
  sph_mat3_transpose(A, E);
  for (int k = 0; k < 9; ++k)
    E[k] = (k % 4 == 0) * sph_mat3_trace(A) - E[k];
  ck_assert(max_diff(X, E, 9) < 1e-14);
}
END_TEST

START_TEST(small_helpers) {
  double a[3] = {1, 2, 3}, b[3] = {-2, 0.5, 4}, c[3];
  sph_vec3_cross(a, b, c);
  ck_assert(fabs(sph_vec3_dot(c, a)) < 1e-15 &&
            fabs(sph_vec3_dot(c, b)) < 1e-15);
  ck_assert(fabs(sph_vec3_norm(a) - sqrt(14.0)) < 1e-15);
  double M[9] = {0}, v[3];
  sph_mat3_add_outer(M, a, b);
  sph_mat3_vec(M, a, v); /* (a (x) b) a = a (b . a) */
  for (int i = 0; i < 3; ++i)
    ck_assert(fabs(v[i] - a[i] * sph_vec3_dot(b, a)) < 1e-14);
  double S[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, Sinv[9];
  ck_assert(sph_mat3_inverse(S, Sinv) == 0.0);
  ck_assert(sph_mat3_norm1(M) > 0.0);
}
END_TEST

int main(void) {
  Suite *s = suite_create("tensor");
  TCase *tc = tcase_create("tensor");
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, inverse_cofactor_and_cross);
  tcase_add_test(tc, cross_with_identity);
  tcase_add_test(tc, small_helpers);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
