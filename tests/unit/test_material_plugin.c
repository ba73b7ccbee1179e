/* Adding a material is one registry line plus its file: the registry
 * (src/materials/registry.c) compiled with
 * -DSPH_MATERIAL_LIST_EXTRA(X)=X(toy, "toy") and tests/unit/toy_material.c
 * make the toy model known to the scene loader, which parses its own key,
 * lets the model check it with errors at file:line:col, and lists it in
 * every "known: ..." and "allowed: ..." message. */
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "materials/material_impl.h"
#include "scene/scene.h"

static const char *const head = "name: toy\n"              /* 1 */
                                "dimension: 2\n"           /* 2 */
                                "method: {name: tl-jst}\n" /* 3 */
                                "materials:\n";            /* 4 */
static const char *const tail =                            /* 6 */
    "bodies:\n"
    "  - {name: plate, material: m, shape: {box: {min: [0, 0], max: [1, 1]}}, "
    "particles: {count: [3, 3]}}\n"
    "time: {end: 0.1}\n";

/* a scene whose line 5 is the material `m` given by `mat` */
static sph_status load(const char *mat, sph_scene **s, sph_error *err) {
  char path[64], text[2048];
  snprintf(text, sizeof text, "%s  m: %s\n%s", head, mat, tail);
  snprintf(path, sizeof path, "/tmp/sph_toy_XXXXXX");
  int fd = mkstemp(path);
  ck_assert_int_ge(fd, 0);
  FILE *f = fdopen(fd, "w");
  fputs(text, f);
  fclose(f);
  sph_status st = sph_scene_load(s, path, NULL, 0, err);
  unlink(path);
  return st;
}

START_TEST(registered) {
  int found = 0;
  for (const char *const *n = sph_material_models(); *n; ++n) {
    const sph_material_ops *o = sph_material_find(*n);
    ck_assert_ptr_nonnull(o);
    ck_assert_str_eq(o->name, *n); /* the list's name is the model's */
    found += !strcmp(*n, "toy");
  }
  ck_assert_int_eq(found, 1);
  ck_assert_ptr_eq(sph_material_find("toy"), &sph_toy_ops);
  ck_assert_str_eq(sph_material_known(),
                   "linear-elastic, neo-hookean, mooney-rivlin, toy");
}
END_TEST

START_TEST(loads_with_its_key) {
  sph_scene *s;
  sph_error err;
  sph_status st = load("{model: toy, density: 1000, youngs_modulus: 1e6, "
                       "poisson_ratio: 0.3, stiffening: 2.5}",
                       &s, &err);
  ck_assert_msg(st == SPH_OK, "%s", err.message);
  ck_assert_ptr_eq(s->materials[0].ops, &sph_toy_ops);
  ck_assert(s->materials[0].own[0] == 2.5);
  double F[9] = {1.01, 0, 0, 0, 1, 0, 0, 0, 1}, H[9] = {0}, P[9];
  sph_material_stress(&s->materials[0], F, H, 1.0, P);
  ck_assert(P[0] > 0.0);
  sph_scene_destroy(s);
  /* the default */
  st = load("{model: toy, density: 1000, youngs_modulus: 1e6, "
            "poisson_ratio: 0.3}",
            &s, &err);
  ck_assert_int_eq(st, SPH_OK);
  ck_assert(s->materials[0].own[0] == 1.0);
  sph_scene_destroy(s);
}
END_TEST

START_TEST(refusals) {
  sph_scene *s;
  sph_error err;
  /* an unknown key: the allowed list holds the toy's own */
  ck_assert_int_eq(load("{model: toy, density: 1000, youngs_modulus: 1e6, "
                        "poisson_ratio: 0.3, sharpness: 2}",
                        &s, &err),
                   SPH_ERR_UNKNOWN_KEY);
  ck_assert_str_eq(err.key, "materials.m.sharpness");
  ck_assert_str_eq(err.message,
                   "unknown key 'sharpness' (allowed: model, density, "
                   "youngs_modulus, poisson_ratio, shear_modulus, "
                   "bulk_modulus, xi, stiffening)");
  /* an unknown model: the known list holds the toy */
  ck_assert_int_eq(load("{model: zzz, density: 1000, youngs_modulus: 1e6, "
                        "poisson_ratio: 0.3}",
                        &s, &err),
                   SPH_ERR_RANGE);
  ck_assert_str_eq(err.message, "unknown model 'zzz' (known: linear-elastic, "
                                "neo-hookean, mooney-rivlin, toy)");
  ck_assert_int_eq(load("{model: tyo, density: 1000, youngs_modulus: 1e6, "
                        "poisson_ratio: 0.3}",
                        &s, &err),
                   SPH_ERR_RANGE);
  ck_assert_str_eq(err.message, "unknown model 'tyo'; did you mean 'toy'?");
  /* the model's check, at its key: line 5, column 75 */
  ck_assert_int_eq(load("{model: toy, density: 1000, youngs_modulus: 1e6, "
                        "poisson_ratio: 0.3, stiffening: 0.5}",
                        &s, &err),
                   SPH_ERR_RANGE);
  ck_assert_int_eq(err.line, 5);
  ck_assert_int_eq(err.col, 75);
  ck_assert_str_eq(err.key, "materials.m.stiffening");
  ck_assert_str_eq(err.message, "stiffening must be >= 1, got 0.5");
  /* a value that is not a number */
  ck_assert_int_eq(load("{model: toy, density: 1000, youngs_modulus: 1e6, "
                        "poisson_ratio: 0.3, stiffening: hard}",
                        &s, &err),
                   SPH_ERR_TYPE);
  ck_assert_str_eq(err.key, "materials.m.stiffening");
  /* the toy's key on another model, another model's key on the toy */
  ck_assert_int_eq(load("{model: neo-hookean, density: 1000, "
                        "youngs_modulus: 1e6, poisson_ratio: 0.3, "
                        "stiffening: 2}",
                        &s, &err),
                   SPH_ERR_ARG);
  ck_assert_str_eq(err.message, "stiffening applies to toy only, not "
                                "neo-hookean");
  ck_assert_int_eq(load("{model: toy, density: 1000, youngs_modulus: 1e6, "
                        "poisson_ratio: 0.3, xi: 0}",
                        &s, &err),
                   SPH_ERR_ARG);
  ck_assert_str_eq(err.message, "xi applies to mooney-rivlin only, not toy");
  ck_assert_str_eq(err.key, "materials.m.xi");
}
END_TEST

int main(void) {
  Suite *s = suite_create("material_plugin");
  TCase *tc = tcase_create("material_plugin");
  tcase_add_test(tc, registered);
  tcase_add_test(tc, loads_with_its_key);
  tcase_add_test(tc, refusals);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
