/* The partition by counting bisection (sph_domain_rcb_counted, issue 20)
 * against sph_domain_rcb of the whole set: each rank holds a share of the
 * particles picked by index (uneven, interleaved), and every particle gets
 * the owner the whole set's RCB gives it, and the cut tree (axis, plane
 * of every cut) is the whole set's on every rank, with the caller's work
 * room or its own. Lattices with many equal coordinates (ties by index,
 * cuts between equal coordinates), signed zeros, a 2D set, random points.
 * Also: waiting ranks yield (issue 36): sph_domain_init sets
 * OMPI_MCA_mpi_yield_when_idle=1 only when unset, and OpenMPI has it.
 * Run under mpirun (ctest: 2, 3 and 4 ranks). */
#include "parallel/domain_impl.h"

#include <check.h>
#include <math.h>
#include <mpi.h>
#include <stdlib.h>
#include <string.h>

#include "mpi_check.h"

/* particles of the whole set whose owners disagree and cuts of the tree
 * that differ, over all ranks (owners only with work, else the tree too) */
static long mismatches_with(const double *X, size_t N, int dim, int work) {
  int rank = sph_domain_world_rank(), R = sph_domain_world_size();
  rcb_key *k = malloc(N * sizeof *k);
  int *whole = malloc(N * sizeof *whole);
  double *x = malloc(3 * N * sizeof *x);
  int64_t *t = malloc(N * sizeof *t);
  int *owner = malloc(N * sizeof *owner);
  uint64_t *room = malloc(2 * N * sizeof *room);
  int axis[2][5] = {{-1, -1, -1, -1, -1}, {-1, -1, -1, -1, -1}};
  double cut[2][5] = {{NAN, NAN, NAN, NAN, NAN}, {NAN, NAN, NAN, NAN, NAN}};
  ck_assert(k && whole && x && t && owner && room && R <= 4);
  for (size_t i = 0; i < N; ++i)
    k[i] = (rcb_key){0.0, (int64_t)i};
  sph_domain_rcb(X, dim, k, N, 0, R, whole, axis[0], cut[0]);
  /* this rank's share: uneven, not in index order */
  size_t m = 0;
  for (size_t j = 0; j < N; ++j) {
    size_t i = N - 1 - j;
    if ((i * 7 + i / 5) % (size_t)(R + 1) % (size_t)R == (size_t)rank) {
      for (int c = 0; c < 3; ++c)
        x[3 * m + c] = X[3 * i + c];
      t[m++] = (int64_t)i;
    }
  }
  if (work)
    sph_domain_rcb_counted(x, t, m, dim, owner, NULL, NULL, room);
  else
    sph_domain_rcb_counted(x, t, m, dim, owner, axis[1], cut[1], NULL);
  long bad = 0, all = 0;
  for (size_t j = 0; j < m; ++j)
    bad += owner[j] != whole[t[j]];
  /* the planes compare equal (-0 == +0); only cuts 1 .. R - 1 are made */
  for (int s = 1; !work && s < R; ++s)
    bad += axis[1][s] != axis[0][s] || !(cut[1][s] == cut[0][s]);
  bad += !work && (axis[1][0] != -1 || axis[1][R] != -1);
  MPI_Allreduce(&bad, &all, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  free(k);
  free(whole);
  free(x);
  free(t);
  free(owner);
  free(room);
  return all;
}

static long mismatches(const double *X, size_t N, int dim) {
  return mismatches_with(X, N, dim, 0) + mismatches_with(X, N, dim, 1);
}

/* cuts whose plane lies on particles (equal coordinates on both sides of
 * the cut: decided by the storage index), over the whole set's RCB */
static int tied_cuts(const double *X, size_t N, int dim) {
  int R = sph_domain_world_size(), axis[5], tied = 0;
  double cut[5];
  rcb_key *k = malloc(N * sizeof *k);
  int *whole = malloc(N * sizeof *whole);
  ck_assert(k && whole);
  for (size_t i = 0; i < N; ++i)
    k[i] = (rcb_key){0.0, (int64_t)i};
  sph_domain_rcb(X, dim, k, N, 0, R, whole, axis, cut);
  for (int s = 1; s < R; ++s)
    for (size_t i = 0; i < N; ++i)
      if (X[3 * i + axis[s]] == cut[s]) {
        tied += 1;
        break;
      }
  free(k);
  free(whole);
  return tied;
}

/* an nx x ny x nz lattice of spacing h from `at`, in a scrambled order */
static double *lattice(int nx, int ny, int nz, double h, const double at[3],
                       size_t *n) {
  *n = (size_t)nx * (size_t)ny * (size_t)nz;
  double *X = calloc(3 * *n, sizeof *X);
  ck_assert(X);
  for (size_t p = 0; p < *n; ++p) {
    size_t q =
        (p * 7919) % *n; /* 7919 prime: a permutation unless it divides */
    size_t i = q % (size_t)nx, j = q / (size_t)nx % (size_t)ny,
           l = q / ((size_t)nx * (size_t)ny);
    X[3 * p] = at[0] + h * (double)i;
    X[3 * p + 1] = at[1] + h * (double)j;
    X[3 * p + 2] = nz > 1 ? at[2] + h * (double)l : 0.0;
  }
  return X;
}

START_TEST(test_column_lattice) {
  size_t n;
  double *X = lattice(7, 37, 7, 1.0 / 6.0, (double[]){-0.5, 0.0, -0.5}, &n);
  ck_assert_int_gt(tied_cuts(X, n, 3), 0); /* the case the tree must hold */
  ck_assert_int_eq(mismatches(X, n, 3), 0);
  free(X);
}
END_TEST

START_TEST(test_signed_zeros_and_cube) {
  size_t n;
  double *X = lattice(9, 9, 9, 0.25, (double[]){-1.0, -1.0, -1.0}, &n);
  for (size_t i = 0; i < 3 * n; i += 2) /* -0 and +0 are the same place */
    if (X[i] == 0.0)
      X[i] = -0.0;
  ck_assert_int_eq(mismatches(X, n, 3), 0);
  free(X);
}
END_TEST

START_TEST(test_plane) {
  size_t n;
  double *X = lattice(41, 13, 1, 0.01, (double[]){-0.2, 0.0, 0.0}, &n);
  ck_assert_int_eq(mismatches(X, n, 2), 0);
  free(X);
}
END_TEST

START_TEST(test_random_points) {
  size_t n = 5000;
  double *X = malloc(3 * n * sizeof *X);
  ck_assert(X);
  unsigned long s = 12345;
  for (size_t i = 0; i < 3 * n; ++i) {
    s = s * 6364136223846793005ul + 1442695040888963407ul;
    X[i] = (double)(s >> 11) / 9007199254740992.0 * (i % 3 == 1 ? 4.0 : 1.0);
  }
  ck_assert_int_eq(mismatches(X, n, 3), 0);
  ck_assert_int_eq(mismatches(X, 3, 3), 0); /* fewer particles than ranks */
  free(X);
}
END_TEST

/* OpenMPI's mpi_yield_when_idle as MPI_T reads it (-1: not found) */
static int yield_when_idle(void) {
  int provided, n = 0, on = -1;
  MPI_T_init_thread(MPI_THREAD_SINGLE, &provided);
  MPI_T_cvar_get_num(&n);
  for (int i = 0; i < n; ++i) {
    char name[256], desc[256];
    int nl = sizeof name, dl = sizeof desc, verb, bind, scope;
    MPI_Datatype type;
    MPI_T_enum en;
    if (MPI_T_cvar_get_info(i, name, &nl, &verb, &type, &en, desc, &dl, &bind,
                            &scope) != MPI_SUCCESS ||
        strcmp(name, "mpi_yield_when_idle"))
      continue;
    MPI_T_cvar_handle h;
    int count;
    unsigned char v[16] = {0}; /* a bool: any non-zero byte */
    MPI_T_cvar_handle_alloc(i, NULL, &h, &count);
    MPI_T_cvar_read(h, v);
    MPI_T_cvar_handle_free(&h);
    on = 0;
    for (size_t b = 0; b < sizeof v; ++b)
      on |= v[b] != 0;
  }
  MPI_T_finalize();
  return on;
}

START_TEST(test_waiting_ranks_yield) {
  /* set by sph_domain_init before MPI_Init (ctest leaves it unset; mpirun
   * sets it itself when oversubscribed), and OpenMPI read it */
  ck_assert_str_eq(getenv("OMPI_MCA_mpi_yield_when_idle"), "1");
  ck_assert_int_eq(yield_when_idle(), 1);
  /* the user's choice is kept */
  ck_assert_int_eq(setenv("OMPI_MCA_mpi_yield_when_idle", "0", 1), 0);
  ck_assert_int_eq(sph_domain_idle_defaults(), 0);
  ck_assert_str_eq(getenv("OMPI_MCA_mpi_yield_when_idle"), "0");
  ck_assert_int_eq(unsetenv("OMPI_MCA_mpi_yield_when_idle"), 0);
  ck_assert_int_eq(sph_domain_idle_defaults(), 1);
  ck_assert_str_eq(getenv("OMPI_MCA_mpi_yield_when_idle"), "1");
}
END_TEST

int main(int argc, char **argv) {
  sph_error err;
  if (sph_domain_init(&argc, &argv, &err) != SPH_OK)
    return EXIT_FAILURE;
  Suite *s = suite_create("rcb_counted");
  TCase *tc = tcase_create("rcb_counted");
  tcase_add_test(tc, test_column_lattice);
  tcase_add_test(tc, test_signed_zeros_and_cube);
  tcase_add_test(tc, test_plane);
  tcase_add_test(tc, test_random_points);
  tcase_add_test(tc, test_waiting_ranks_yield);
  suite_add_tcase(s, tc);
  return sph_mpi_check_run(s);
}
