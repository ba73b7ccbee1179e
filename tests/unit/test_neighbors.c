/* Neighbour search: the cell-list build equals the O(N^2) reference on
 * random, clustered, degenerate and multi-body point sets. */
#include "test_util.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/neighbors.h"

static uint64_t rng_state;
static double urand(void) {
  rng_state += 0x9e3779b97f4a7c15ull;
  uint64_t z = rng_state;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return (double)(z >> 11) * 0x1.0p-53;
}

/* Check writes to a pipe on every assertion: count in C, assert once. */
static void assert_same(const sph_neighbors *a, const sph_neighbors *b) {
  ck_assert_uint_eq(a->n, b->n);
  ck_assert_uint_eq(a->count, b->count);
  size_t bad = 0;
  for (size_t i = 0; i <= a->n; ++i)
    bad += a->offset[i] != b->offset[i];
  for (size_t k = 0; k < a->count; ++k)
    bad += a->index[k] != b->index[k];
  ck_assert_uint_eq(bad, 0);
}

static void compare(const double *x, size_t n, int dim, double radius,
                    const int32_t *body, sph_pair_filter filter) {
  sph_neighbors *fast, *brute;
  sph_error err;
  ck_assert_int_eq(sph_neighbors_create(&fast, &err), SPH_OK);
  ck_assert_int_eq(sph_neighbors_create(&brute, &err), SPH_OK);
  ck_assert_int_eq(
      sph_neighbors_build(fast, x, n, dim, radius, body, filter, &err), SPH_OK);
  ck_assert_int_eq(
      sph_neighbors_build_brute(brute, x, n, dim, radius, body, filter, &err),
      SPH_OK);
  assert_same(fast, brute);
  /* a rebuild into the same object gives the same lists */
  ck_assert_int_eq(
      sph_neighbors_build(fast, x, n, dim, radius, body, filter, &err), SPH_OK);
  assert_same(fast, brute);
  sph_neighbors_destroy(fast);
  sph_neighbors_destroy(brute);
}

START_TEST(random_sets_match_brute_force) {
  for (int dim = 1; dim <= 3; ++dim) {
    rng_state = 42u + (uint64_t)dim;
    size_t n = 1500;
    double *x = calloc(3 * n, sizeof *x);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < dim; ++c)
        x[3 * i + c] = -2.0 + 4.0 * urand();
    compare(x, n, dim, 0.37, NULL, SPH_PAIRS_ALL);
    compare(x, n, dim, 3.0, NULL, SPH_PAIRS_ALL); /* one cell per axis */
    free(x);
  }
}
END_TEST

START_TEST(lattice_with_points_on_cell_edges) {
  /* exact lattice spacing equal to the radius: pairs at distance == radius
   * are excluded (strict), those at 1.3 dp included */
  size_t n1 = 9, n = n1 * n1 * n1;
  double *x = calloc(3 * n, sizeof *x);
  size_t k = 0;
  for (size_t i = 0; i < n1; ++i)
    for (size_t j = 0; j < n1; ++j)
      for (size_t l = 0; l < n1; ++l, ++k) {
        x[3 * k] = 0.1 * (double)i;
        x[3 * k + 1] = 0.1 * (double)j;
        x[3 * k + 2] = 0.1 * (double)l;
      }
  compare(x, n, 3, 0.26, NULL, SPH_PAIRS_ALL);
  compare(x, n, 3, 0.1, NULL, SPH_PAIRS_ALL);
  free(x);
}
END_TEST

START_TEST(clustered_and_sparse_sets) {
  /* a dense cluster plus far outliers exercises the cell-size cap */
  rng_state = 7;
  size_t n = 800;
  double *x = calloc(3 * n, sizeof *x);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      x[3 * i + c] = (i % 50 == 0) ? 1e4 * urand() : 0.01 * urand();
  compare(x, n, 3, 0.002, NULL, SPH_PAIRS_ALL);
  /* all points coincident */
  memset(x, 0, 3 * n * sizeof *x);
  compare(x, 50, 3, 1.0, NULL, SPH_PAIRS_ALL);
  free(x);
}
END_TEST

START_TEST(points_too_far_apart_for_a_long_grid) {
  /* 1e19 m over 1 mm cells is 1e22 cells along x: the grid coarsens
   * instead of overflowing (a crash under UBSan before) */
  double x[12] = {0, 0, 0, 0.0005, 0, 0, 1e19, 0, 0, 1e19, 0.0005, 0};
  compare(x, 4, 3, 0.001, NULL, SPH_PAIRS_ALL);
  compare(x, 4, 2, 0.001, NULL, SPH_PAIRS_ALL);
}
END_TEST

START_TEST(non_finite_positions_are_refused) {
  sph_neighbors *nl;
  sph_error err;
  double x[6] = {0, 0, 0, INFINITY, 0, 0};
  ck_assert_int_eq(sph_neighbors_create(&nl, &err), SPH_OK);
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, 2, 3, 1.0, NULL, SPH_PAIRS_ALL, &err),
      SPH_ERR_NUMERIC);
  x[3] = -1.7e308; /* finite, but the span overflows */
  x[0] = 1.7e308;
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, 2, 3, 1.0, NULL, SPH_PAIRS_ALL, &err),
      SPH_ERR_NUMERIC);
  sph_neighbors_destroy(nl);
}
END_TEST

START_TEST(same_body_filter) {
  rng_state = 99;
  size_t n = 1000;
  double *x = calloc(3 * n, sizeof *x);
  int32_t *body = calloc(n, sizeof *body);
  for (size_t i = 0; i < n; ++i) {
    x[3 * i] = urand();
    x[3 * i + 1] = urand();
    body[i] = (int32_t)(i % 3);
  }
  compare(x, n, 2, 0.08, body, SPH_PAIRS_SAME_BODY);
  compare(x, n, 2, 0.08, body, SPH_PAIRS_OTHER_BODY);
  compare(x, n, 2, 0.08, body, SPH_PAIRS_ALL);
  sph_neighbors *nl;
  sph_error err;
  ck_assert_int_eq(sph_neighbors_create(&nl, &err), SPH_OK);
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, n, 2, 0.08, body, SPH_PAIRS_SAME_BODY, &err),
      SPH_OK);
  size_t cross = 0, same = 0, pairs = nl->count;
  for (size_t a = 0; a < n; ++a)
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k)
      cross += body[nl->index[k]] != body[a];
  ck_assert_uint_eq(cross, 0);
  /* the contact filter keeps exactly the other pairs */
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, n, 2, 0.08, body, SPH_PAIRS_OTHER_BODY, &err),
      SPH_OK);
  for (size_t a = 0; a < n; ++a)
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k)
      same += body[nl->index[k]] == body[a];
  ck_assert_uint_eq(same, 0);
  size_t others = nl->count;
  ck_assert_uint_gt(others, 0);
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, n, 2, 0.08, NULL, SPH_PAIRS_ALL, &err),
      SPH_OK);
  ck_assert_uint_eq(nl->count, pairs + others);
  sph_neighbors_destroy(nl);
  free(x);
  free(body);
}
END_TEST

START_TEST(lists_are_symmetric_and_sorted) {
  rng_state = 5;
  size_t n = 600;
  double *x = calloc(3 * n, sizeof *x);
  for (size_t i = 0; i < 3 * n; ++i)
    x[i] = urand();
  sph_neighbors *nl;
  sph_error err;
  ck_assert_int_eq(sph_neighbors_create(&nl, &err), SPH_OK);
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, n, 3, 0.15, NULL, SPH_PAIRS_ALL, &err),
      SPH_OK);
  size_t self = 0, unsorted = 0, asymmetric = 0;
  for (size_t a = 0; a < n; ++a)
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      self += a == b;
      unsorted += k > nl->offset[a] && nl->index[k - 1] >= nl->index[k];
      int found = 0;
      for (size_t m = nl->offset[b]; m < nl->offset[b + 1]; ++m)
        found |= (size_t)nl->index[m] == a;
      asymmetric += !found;
    }
  ck_assert_uint_gt(nl->count, n); /* the set is dense enough to test */
  ck_assert_uint_eq(self, 0);
  ck_assert_uint_eq(unsorted, 0);
  ck_assert_uint_eq(asymmetric, 0);
  sph_neighbors_destroy(nl);
  free(x);
}
END_TEST

START_TEST(rejects_bad_arguments) {
  sph_neighbors *nl;
  sph_error err;
  double x[6] = {0};
  ck_assert_int_eq(sph_neighbors_create(&nl, &err), SPH_OK);
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, 2, 3, 0.0, NULL, SPH_PAIRS_ALL, &err),
      SPH_ERR_ARG);
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, 2, 4, 1.0, NULL, SPH_PAIRS_ALL, &err),
      SPH_ERR_ARG);
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, 2, 3, 1.0, NULL, SPH_PAIRS_SAME_BODY, &err),
      SPH_ERR_ARG);
  ck_assert_int_eq(
      sph_neighbors_build(nl, x, 0, 3, 1.0, NULL, SPH_PAIRS_ALL, &err), SPH_OK);
  ck_assert_uint_eq(nl->count, 0);
  sph_neighbors_destroy(nl);
}
END_TEST

int main(void) {
  Suite *s = suite_create("neighbors");
  TCase *tc = tcase_create("build");
  tcase_add_checked_fixture(tc, sph_test_enable_fp_traps, NULL);
  tcase_add_test(tc, random_sets_match_brute_force);
  tcase_add_test(tc, lattice_with_points_on_cell_edges);
  tcase_add_test(tc, clustered_and_sparse_sets);
  tcase_add_test(tc, same_body_filter);
  tcase_add_test(tc, lists_are_symmetric_and_sorted);
  tcase_add_test(tc, rejects_bad_arguments);
  tcase_add_test(tc, points_too_far_apart_for_a_long_grid);
  suite_add_tcase(s, tc);
  /* without floating-point traps: infinities are the input */
  tc = tcase_create("non-finite");
  tcase_add_test(tc, non_finite_positions_are_refused);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
