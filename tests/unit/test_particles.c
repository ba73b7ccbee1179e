/* Particle storage: fields allocated on demand, zeroed, idempotent; append
 * and capacity; field names, components and units. */
#include "test_util.h"

#include <string.h>

#include "sph/particles.h"

START_TEST(fields_on_demand) {
  sph_particles *ps;
  sph_error err;
  ck_assert_int_eq(sph_particles_create(&ps, 4, 3, &err), SPH_OK);
  ck_assert(sph_particles_has(ps, SPH_FIELD_POSITION0));
  ck_assert(sph_particles_has(ps, SPH_FIELD_VOLUME0));
  ck_assert(!sph_particles_has(ps, SPH_FIELD_DEFGRAD));
  size_t before = sph_particles_bytes(ps);
  ck_assert_int_eq(sph_particles_require(ps, SPH_FIELD_DEFGRAD, &err), SPH_OK);
  double *F = ps->field[SPH_FIELD_DEFGRAD];
  for (int k = 0; k < 36; ++k)
    ck_assert(F[k] == 0.0);
  ck_assert_uint_eq(sph_particles_bytes(ps), before + 4 * 9 * sizeof(double));
  ck_assert_int_eq(sph_particles_require(ps, SPH_FIELD_DEFGRAD, &err), SPH_OK);
  ck_assert_ptr_eq(ps->field[SPH_FIELD_DEFGRAD], F);
  double X[3] = {1, 2, 3};
  for (int i = 0; i < 4; ++i)
    ck_assert_int_eq(sph_particles_append(ps, X, 0.5, 1, &err), SPH_OK);
  ck_assert_int_eq(sph_particles_append(ps, X, 0.5, 1, &err), SPH_ERR_ARG);
  ck_assert_uint_eq(ps->n, 4);
  ck_assert_int_eq(ps->id[3], 3);
  ck_assert_int_eq(ps->body[2], 1);
  ck_assert(ps->field[SPH_FIELD_POSITION0][3 * 3 + 2] == 3.0);
  sph_particles_destroy(ps);
  ck_assert_int_eq(sph_particles_create(&ps, 4, 5, &err), SPH_ERR_ARG);
}
END_TEST

START_TEST(field_table) {
  ck_assert_str_eq(sph_field_name(SPH_FIELD_PRESSURE), "pressure");
  ck_assert_int_eq(sph_field_components(SPH_FIELD_STRESS), 9);
  ck_assert_str_eq(sph_field_unit(SPH_FIELD_VELOCITY), "m/s");
  ck_assert_int_eq(sph_field_from_name("von_mises"), SPH_FIELD_VON_MISES);
  ck_assert_int_eq(sph_field_from_name("J"), SPH_FIELD_JACOBIAN);
  ck_assert_int_eq(sph_field_from_name("nonsense"), -1);
  for (int f = 0; f < SPH_FIELD_COUNT; ++f)
    ck_assert_int_eq(sph_field_from_name(sph_field_name((sph_field)f)), f);
}
END_TEST

int main(void) {
  Suite *s = suite_create("particles");
  TCase *tc = tcase_create("particles");
  tcase_add_test(tc, fields_on_demand);
  tcase_add_test(tc, field_table);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
