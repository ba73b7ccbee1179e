/* Particle storage (src/core/particles.c): fields allocated on demand,
 * zeroed, idempotent; append and capacity; byte count; field names,
 * components and units; the Morton reorder. */
#include "test_util.h"

#include <string.h>

#include "core/particles.h"

START_TEST(fields_on_demand) {
  sph_particles *ps;
  sph_error err;
  ck_assert_int_eq(sph_particles_create(&ps, 4, 3, &err), SPH_OK);
  ck_assert_uint_eq(ps->n, 0);
  ck_assert_uint_eq(ps->capacity, 4);
  ck_assert_int_eq(ps->dim, 3);
  /* positions and volumes come with the set, nothing else */
  for (int f = 0; f < SPH_FIELD_COUNT; ++f)
    ck_assert_int_eq(sph_particles_has(ps, (sph_field)f),
                     f == SPH_FIELD_POSITION0 || f == SPH_FIELD_VOLUME0);
  size_t attr = 4 * (sizeof(int64_t) + sizeof(int32_t) + sizeof(uint32_t));
  ck_assert_uint_eq(sph_particles_bytes(ps),
                    attr + 4 * (3 + 1) * sizeof(double));
  size_t before = sph_particles_bytes(ps);
  ck_assert_int_eq(sph_particles_require(ps, SPH_FIELD_DEFGRAD, &err), SPH_OK);
  double *F = ps->field[SPH_FIELD_DEFGRAD];
  for (int k = 0; k < 36; ++k)
    ck_assert(F[k] == 0.0);
  ck_assert_uint_eq(sph_particles_bytes(ps), before + 4 * 9 * sizeof(double));
  /* requiring again keeps the array and its contents */
  F[5] = 2.5;
  ck_assert_int_eq(sph_particles_require(ps, SPH_FIELD_DEFGRAD, &err), SPH_OK);
  ck_assert_ptr_eq(ps->field[SPH_FIELD_DEFGRAD], F);
  ck_assert(F[5] == 2.5);
  ck_assert_uint_eq(sph_particles_bytes(ps), before + 4 * 9 * sizeof(double));
  ck_assert_int_eq(sph_particles_require(ps, (sph_field)SPH_FIELD_COUNT, &err),
                   SPH_ERR_ARG);
  ck_assert_int_eq(err.code, SPH_ERR_ARG);
  ck_assert_int_eq(sph_particles_require(ps, (sph_field)-1, &err), SPH_ERR_ARG);
  sph_particles_destroy(ps);
}
END_TEST

START_TEST(append_until_full) {
  sph_particles *ps;
  sph_error err;
  ck_assert_int_eq(sph_particles_create(&ps, 4, 2, &err), SPH_OK);
  for (int i = 0; i < 4; ++i) {
    double X[3] = {1.0 + i, 2.0, 0.0};
    ck_assert_int_eq(sph_particles_append(ps, X, 0.5 * (i + 1), i % 2, &err),
                     SPH_OK);
  }
  double X[3] = {9, 9, 9};
  ck_assert_int_eq(sph_particles_append(ps, X, 0.5, 1, &err), SPH_ERR_ARG);
  ck_assert_ptr_nonnull(strstr(err.message, "full"));
  ck_assert_uint_eq(ps->n, 4);
  for (int i = 0; i < 4; ++i) {
    ck_assert_int_eq(ps->id[i], i);
    ck_assert_int_eq(ps->body[i], i % 2);
    ck_assert_uint_eq(ps->flags[i], 0);
    ck_assert(ps->field[SPH_FIELD_POSITION0][3 * i] == 1.0 + i);
    ck_assert(ps->field[SPH_FIELD_POSITION0][3 * i + 1] == 2.0);
    ck_assert(ps->field[SPH_FIELD_VOLUME0][i] == 0.5 * (i + 1));
  }
  sph_particles_destroy(ps);
  /* an empty set takes nothing */
  ck_assert_int_eq(sph_particles_create(&ps, 0, 3, &err), SPH_OK);
  ck_assert_int_eq(sph_particles_append(ps, X, 0.5, 0, &err), SPH_ERR_ARG);
  sph_particles_destroy(ps);
  sph_particles_destroy(NULL);
  /* bad dimensions */
  ck_assert_int_eq(sph_particles_create(&ps, 4, 5, &err), SPH_ERR_ARG);
  ck_assert_ptr_null(ps);
  ck_assert_int_eq(sph_particles_create(&ps, 4, 0, &err), SPH_ERR_ARG);
}
END_TEST

START_TEST(field_table) {
  ck_assert_str_eq(sph_field_name(SPH_FIELD_PRESSURE), "pressure");
  ck_assert_int_eq(sph_field_components(SPH_FIELD_STRESS), 9);
  ck_assert_int_eq(sph_field_components(SPH_FIELD_POSITION), 3);
  ck_assert_int_eq(sph_field_components(SPH_FIELD_JACOBIAN), 1);
  ck_assert_str_eq(sph_field_unit(SPH_FIELD_VELOCITY), "m/s");
  ck_assert_str_eq(sph_field_unit(SPH_FIELD_PK1), "Pa");
  ck_assert_int_eq(sph_field_from_name("von_mises"), SPH_FIELD_VON_MISES);
  ck_assert_int_eq(sph_field_from_name("J"), SPH_FIELD_JACOBIAN);
  ck_assert_int_eq(sph_field_from_name("nonsense"), -1);
  ck_assert_int_eq(sph_field_from_name(""), -1);
  for (int f = 0; f < SPH_FIELD_COUNT; ++f) {
    ck_assert_int_eq(sph_field_from_name(sph_field_name((sph_field)f)), f);
    int nc = sph_field_components((sph_field)f);
    ck_assert(nc == 1 || nc == 3 || nc == 9);
    ck_assert(strlen(sph_field_unit((sph_field)f)) > 0);
  }
}
END_TEST

/* A 12 x 10 x 8 lattice created x fastest, reordered in cells of 2 x 2 x 2
 * points: every field, id, body and flag moves together, slot finds each
 * particle again, the cells come in Morton order (cell (i,j,k) before
 * (i+1,j,k) before (i,j+1,k) within a 2 x 2 x 2 block of cells) and a
 * cell's particles are contiguous and keep their creation order. */
START_TEST(morton_order) {
  enum { NX = 12, NY = 10, NZ = 8, N = NX * NY * NZ };
  sph_particles *ps;
  sph_error err;
  ck_assert_int_eq(sph_particles_create(&ps, N, 3, &err), SPH_OK);
  ck_assert_int_eq(sph_particles_require(ps, SPH_FIELD_DEFGRAD, &err), SPH_OK);
  for (int k = 0; k < NZ; ++k)
    for (int j = 0; j < NY; ++j)
      for (int i = 0; i < NX; ++i) {
        double X[3] = {0.1 * i, 0.1 * j, 0.1 * k};
        size_t a = ps->n;
        ck_assert_int_eq(sph_particles_append(ps, X, 1.0 + (double)a,
                                              (int32_t)(a % 3), &err),
                         SPH_OK);
        ps->flags[a] = (uint32_t)(a % 5);
        for (int c = 0; c < 9; ++c)
          ps->field[SPH_FIELD_DEFGRAD][9 * a + c] = 10.0 * (double)a + c;
      }
  size_t before = sph_particles_bytes(ps);
  ck_assert_int_eq(sph_particles_sort_morton(ps, 0.2, &err), SPH_OK);
  ck_assert_ptr_nonnull(ps->slot);
  ck_assert_uint_eq(sph_particles_bytes(ps), before + N * sizeof(int64_t));
  long moved = 0, prev_cell = -1, prev_id = -1;
  for (size_t s = 0; s < N; ++s) {
    long a = (long)ps->id[s];
    moved += a != (long)s;
    ck_assert_uint_eq(sph_particles_slot(ps, (size_t)a), s);
    const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * s;
    ck_assert(X[0] == 0.1 * (a % NX) && X[1] == 0.1 * (a / NX % NY) &&
              X[2] == 0.1 * (a / (NX * NY)));
    ck_assert(ps->field[SPH_FIELD_VOLUME0][s] == 1.0 + (double)a);
    ck_assert_int_eq(ps->body[s], a % 3);
    ck_assert_uint_eq(ps->flags[s], (uint32_t)(a % 5));
    for (int c = 0; c < 9; ++c)
      ck_assert(ps->field[SPH_FIELD_DEFGRAD][9 * s + c] == 10.0 * a + c);
    /* Morton index of the cell, bits interleaved x, y, z */
    long ci = a % NX / 2, cj = a / NX % NY / 2, ck = a / (NX * NY) / 2,
         cell = 0;
    for (int b = 0; b < 4; ++b)
      cell |= (ci >> b & 1) << (3 * b) | (cj >> b & 1) << (3 * b + 1) |
              (ck >> b & 1) << (3 * b + 2);
    ck_assert(cell > prev_cell || (cell == prev_cell && a > prev_id));
    prev_cell = cell;
    prev_id = a;
  }
  ck_assert_int_gt(moved, N / 2);
  /* an empty or single set is left alone */
  sph_particles *one;
  ck_assert_int_eq(sph_particles_create(&one, 1, 3, &err), SPH_OK);
  ck_assert_int_eq(sph_particles_sort_morton(one, 0.2, &err), SPH_OK);
  ck_assert_ptr_null(one->slot);
  ck_assert_uint_eq(sph_particles_slot(one, 0), 0);
  sph_particles_destroy(one);
  sph_particles_destroy(ps);
}
END_TEST

int main(void) {
  Suite *s = suite_create("particles");
  TCase *tc = tcase_create("particles");
  tcase_add_test(tc, fields_on_demand);
  tcase_add_test(tc, append_until_full);
  tcase_add_test(tc, field_table);
  tcase_add_test(tc, morton_order);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
