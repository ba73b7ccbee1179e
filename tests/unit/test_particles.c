/* Particle storage (src/core/particles.c): fields allocated on demand,
 * zeroed, idempotent; append and capacity; byte count; field names,
 * components and units. */
#include "test_util.h"

#include <string.h>

#include "sph/particles.h"

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

int main(void) {
  Suite *s = suite_create("particles");
  TCase *tc = tcase_create("particles");
  tcase_add_test(tc, fields_on_demand);
  tcase_add_test(tc, append_until_full);
  tcase_add_test(tc, field_table);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
