/* Scene loading: the twisting column's typed values and particles, filled
 * defaults, --set overrides, and one test per class of bad input, each
 * checking the code, line, column, key and message. */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene/scene.h"

static const char *const good =
    "name: column\n"           /* 1 */
    "dimension: 3\n"           /* 2 */
    "method: {name: tl-jst}\n" /* 3 */
    "materials:\n"             /* 4 */
    "  rubber: {model: neo-hookean, density: 1100, youngs_modulus: 17e6, "
    "poisson_ratio: 0.45}\n"                                         /* 5 */
    "bodies:\n"                                                      /* 6 */
    "  - name: column\n"                                             /* 7 */
    "    material: rubber\n"                                         /* 8 */
    "    shape: {box: {min: [-0.5, 0, -0.5], max: [0.5, 6, 0.5]}}\n" /* 9 */
    "    particles: {count: [5, 25, 5]}\n"                           /* 10 */
    "    initial_velocity: {rotation: {axis: y, omega: 105, profile: "
    "\"sin(pi*y/(2*6))\"}}\n" /* 11 */
    "boundaries:\n"           /* 12 */
    "  - {name: base, select: {plane: {axis: y, at: 0}}, clamp: true}\n"
    "time: {end: 0.3}\n"                            /* 14 */
    "output:\n"                                     /* 15 */
    "  probes: [{name: tip, at: [0.5, 6, 0.5]}]\n"; /* 16 */

static char path[64];

static sph_status load_text(const char *text, sph_scene **s,
                            const char *const *sets, size_t nsets,
                            sph_error *err) {
  snprintf(path, sizeof path, "/tmp/sph_scene_XXXXXX");
  int fd = mkstemp(path);
  ck_assert_int_ge(fd, 0);
  FILE *f = fdopen(fd, "w");
  fputs(text, f);
  fclose(f);
  sph_status st = sph_scene_load(s, path, sets, nsets, err);
  unlink(path);
  return st;
}

/* `base` with one line replaced by `line` (1-based), into buf[4096] */
static char *replace_line(char *buf, const char *base, int lineno,
                          const char *line) {
  buf[0] = '\0';
  const char *p = base;
  for (int i = 1; *p; ++i) {
    const char *e = strchr(p, '\n');
    size_t len = e ? (size_t)(e - p) + 1 : strlen(p);
    if (i == lineno) {
      strcat(buf, line);
      strcat(buf, "\n");
    } else {
      strncat(buf, p, len);
    }
    p += len;
  }
  return buf;
}

/* good scene with one line replaced by `line` (1-based) */
static char *with_line(int lineno, const char *line) {
  static char buf[4096];
  return replace_line(buf, good, lineno, line);
}

/* the error must point at `needle` on line `line` of the text */
static void expect_error(const char *text, sph_status code, int line,
                         const char *needle, const char *key,
                         const char *fragment) {
  const char *p = text;
  for (int i = 1; i < line && p; ++i)
    p = strchr(p, '\n') ? strchr(p, '\n') + 1 : NULL;
  ck_assert_ptr_nonnull(p);
  const char *at = strstr(p, needle);
  ck_assert_ptr_nonnull(at);
  int col = (int)(at - p) + 1;
  sph_scene *s = NULL;
  sph_error err;
  sph_status st = load_text(text, &s, NULL, 0, &err);
  sph_particles *ps = NULL;
  if (st == SPH_OK) {
    st = sph_scene_build_particles(s, &ps, &err);
    sph_particles_destroy(ps);
    sph_scene_destroy(s);
  }
  ck_assert_msg(st == code, "expected %s, got %s: %s", sph_status_name(code),
                sph_status_name(st), err.message);
  ck_assert_str_eq(err.file, path);
  ck_assert_msg(err.line == line && err.col == col,
                "location %d:%d, expected %d:%d (%s)", err.line, err.col, line,
                col, err.message);
  ck_assert_str_eq(err.key, key);
  ck_assert_msg(strstr(err.message, fragment), "message '%s' lacks '%s'",
                err.message, fragment);
}

START_TEST(twisting_column_loads) {
  sph_scene *s;
  sph_error err;
  ck_assert_int_eq(load_text(good, &s, NULL, 0, &err), SPH_OK);
  ck_assert_str_eq(s->name, "column");
  ck_assert_int_eq(s->dimension, 3);
  ck_assert_str_eq(s->method_name, "tl-jst");
  ck_assert_int_eq(s->kernel_type, SPH_KERNEL_CUBIC);
  ck_assert(s->h_over_dp == 1.3);
  ck_assert(fabs(s->bodies[0].spacing - 0.25) < 1e-15);
  ck_assert(fabs(s->output.every - 0.003) < 1e-15); /* default end / 100 */
  ck_assert(fabs(s->boundaries[0].select.tolerance - 0.125) < 1e-15);
  sph_particles *ps;
  ck_assert_int_eq(sph_scene_build_particles(s, &ps, &err), SPH_OK);
  ck_assert_uint_eq(ps->n, 625);
  double vol = 0.0, tip = 0.0;
  int base = 0;
  for (size_t a = 0; a < ps->n; ++a) {
    vol += ps->field[SPH_FIELD_VOLUME0][a];
    base += (ps->flags[a] & SPH_FLAG_BOUNDARY) != 0;
    const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * a;
    if (X[1] == 6.0 && X[0] == 0.5 && X[2] == 0.5)
      tip = ps->field[SPH_FIELD_VELOCITY][3 * a + 2];
  }
  ck_assert(fabs(vol - 6.0) < 1e-13);
  ck_assert_int_eq(base, 25);
  /* v = omega e_y x r: v_z = -105 sin(pi/2) x = -52.5 at x = 0.5 */
  ck_assert(fabs(tip + 52.5) < 1e-12);
  /* defaults are in the tree */
  sph_node *k = sph_node_child(s->root, "kernel");
  ck_assert_ptr_nonnull(k);
  ck_assert_str_eq(sph_node_child(k, "type")->value, "cubic");
  sph_particles_destroy(ps);
  sph_scene_destroy(s);
}
END_TEST

START_TEST(overrides) {
  sph_scene *s;
  sph_error err;
  const char *sets[] = {"materials.rubber.poisson_ratio=0.499",
                        "bodies.0.particles.count=[3,13,3]"};
  ck_assert_int_eq(load_text(good, &s, sets, 2, &err), SPH_OK);
  ck_assert(s->materials[0].poisson_ratio == 0.499);
  ck_assert_int_eq(s->bodies[0].count[1], 13);
  sph_scene_destroy(s);
  const char *bad[] = {"materials.rubber.poisson_ratio=0.5"};
  ck_assert_int_eq(load_text(good, &s, bad, 1, &err), SPH_ERR_RANGE);
  ck_assert_str_eq(err.file, "<command line>");
  ck_assert_str_eq(err.key, "materials.rubber.poisson_ratio");
  const char *typo[] = {"materials.rubber.poisson=0.4"};
  ck_assert_int_eq(load_text(good, &s, typo, 1, &err), SPH_ERR_UNKNOWN_KEY);
  ck_assert_ptr_nonnull(strstr(err.message, "did you mean 'poisson_ratio'"));
}
END_TEST

/* output.png: a block or true turns frames on, false keeps them off */
START_TEST(png_off) {
  sph_scene *s;
  sph_error err;
  const char *on[] = {"output.png={}"};
  ck_assert_int_eq(load_text(good, &s, on, 1, &err), SPH_OK);
  ck_assert_int_eq(s->output.png.enabled, 1);
  sph_scene_destroy(s);
  const char *off[] = {"output.png={}", "output.png=false"};
  ck_assert_int_eq(load_text(good, &s, off, 2, &err), SPH_OK);
  ck_assert_int_eq(s->output.png.enabled, 0);
  sph_scene_destroy(s);
  const char *yes[] = {"output.png=true"};
  ck_assert_int_eq(load_text(good, &s, yes, 1, &err), SPH_OK);
  ck_assert_int_eq(s->output.png.enabled, 1);
  ck_assert_int_eq(s->output.png.width, 1280);
  sph_scene_destroy(s);
  const char *bad[] = {"output.png=7"};
  ck_assert_int_eq(load_text(good, &s, bad, 1, &err), SPH_ERR_TYPE);
  ck_assert_str_eq(err.key, "output.png");
}
END_TEST

START_TEST(error_classes) {
  expect_error(with_line(14, "time: {end: 0.3, ned: 1}"), SPH_ERR_UNKNOWN_KEY,
               14, "ned", "time.ned", "did you mean 'end'");
  expect_error(with_line(2, "dimension: 3\ndimension: 2"),
               SPH_ERR_DUPLICATE_KEY, 3, "dimension", "dimension",
               "duplicate key");
  expect_error(with_line(2, "dimension: three"), SPH_ERR_TYPE, 2, "dimension",
               "dimension", "expected an integer");
  expect_error(with_line(14, "time: {}"), SPH_ERR_MISSING_KEY, 14, "time",
               "time.end", "missing required key 'end'");
  expect_error(with_line(5, "  rubber: {model: neo-hookean, density: 1100, "
                            "youngs_modulus: 17e6, poisson_ratio: 0.5}"),
               SPH_ERR_RANGE, 5, "poisson_ratio",
               "materials.rubber.poisson_ratio", "(-1, 0.5)");
  expect_error(with_line(5, "  rubber: {model: neo-hookean, density: 1100, "
                            "youngs_modulus: 17e6, poisson_ratio: -1}"),
               SPH_ERR_RANGE, 5, "poisson_ratio",
               "materials.rubber.poisson_ratio", "(-1, 0.5)");
  expect_error(with_line(5, "  rubber: {model: neo-hookean, density: -1, "
                            "youngs_modulus: 17e6, poisson_ratio: 0.3}"),
               SPH_ERR_RANGE, 5, "density", "materials.rubber.density",
               "positive");
  expect_error(with_line(5, "  rubber: {model: neo-hookean, density: 1, "
                            "youngs_modulus: 0, poisson_ratio: 0.3}"),
               SPH_ERR_RANGE, 5, "youngs_modulus",
               "materials.rubber.youngs_modulus", "positive");
  expect_error(
      with_line(9, "    shape: {box: {min: [0, 0, 0], max: [1, 0, 1]}}"),
      SPH_ERR_GEOMETRY, 9, "max", "bodies[0].shape.box.max", "empty box");
  expect_error(with_line(8, "    material: rubbr"), SPH_ERR_ARG, 8, "material",
               "bodies[0].material", "did you mean 'rubber'");
  expect_error(with_line(16, "  probes: [{name: tip, at: [3, 6, 0.5]}]"),
               SPH_ERR_GEOMETRY, 16, "at:", "output.probes[0].at",
               "outside every body");
  expect_error(with_line(13, "  - {name: base, select: {plane: {axis: y, at: "
                             "-1}}, clamp: true}"),
               SPH_ERR_GEOMETRY, 13, "{name", "boundaries[0].select",
               "selects no particle");
  /* overlapping bodies: a second column shifted by half a spacing */
  char two[4096];
  snprintf(two, sizeof two, "%s",
           with_line(11, "  - name: other\n    material: rubber\n"
                         "    shape: {box: {min: [-0.4, 0, -0.5], max: [0.6, "
                         "6, 0.5]}}\n    particles: {count: [5, 25, 5]}"));
  expect_error(two, SPH_ERR_GEOMETRY, 11, "name: other", "bodies[1]",
               "overlaps body "
               "'column'");
}
END_TEST

START_TEST(dimension_and_shape_errors) {
  expect_error(
      with_line(9, "    shape: {disc: {center: [0, 0, 0], radius: 1}}"),
      SPH_ERR_GEOMETRY, 9, "disc", "bodies[0].shape.disc", "3D");
  expect_error(with_line(9, "    shape: {box: {min: [0, 0, 0], max: [1, 1, 1]},"
                            " sphere: {center: [0, 0, 0], radius: 1}}"),
               SPH_ERR_ARG, 9, "sphere", "bodies[0].shape.sphere", "only one");
  expect_error(with_line(1, "name: has space"), SPH_ERR_RANGE, 1, "name",
               "name", "output folder");
}
END_TEST

/* a body transform places the particles, turns the initial velocity and
 * the selections that name the body; vectors are normalised */
START_TEST(placed_body) {
  char text[4096];
  snprintf(text, sizeof text, "%s",
           with_line(11, "    initial_velocity: {rotation: {axis: [0, 2, 0], "
                         "omega: 105, profile: \"sin(pi*y/(2*6))\"}}\n"
                         "    transform: {rotate: {axis: [3, 0, 0], angle: "
                         "-270}, translate: [1, 2, 3]}"));
  const char *sets[] = {"boundaries.0.select.plane.body=column",
                        "output.probes=[]"};
  sph_scene *s;
  sph_error err;
  ck_assert_int_eq(load_text(text, &s, sets, 2, &err), SPH_OK);
  /* -270 degrees about x is +90: (x, y, z) -> (x, -z, y), exactly */
  const sph_transform *T = &s->bodies[0].transform;
  const double R[9] = {1, 0, 0, 0, 0, -1, 0, 1, 0};
  for (int k = 0; k < 9; ++k)
    ck_assert(T->R[k] == R[k]);
  /* the base plane y = 0 of the column is the world plane z = 3 */
  const sph_selection *sel = &s->boundaries[0].select;
  ck_assert_int_eq(sel->axis, 2);
  ck_assert(sel->at == 3.0);
  sph_particles *ps;
  ck_assert_int_eq(sph_scene_build_particles(s, &ps, &err), SPH_OK);
  int base = 0, tips = 0;
  for (size_t a = 0; a < ps->n; ++a) {
    base += (ps->flags[a] & SPH_FLAG_BOUNDARY) != 0;
    const double *X = ps->field[SPH_FIELD_POSITION0] + 3 * a;
    const double *v = ps->field[SPH_FIELD_VELOCITY] + 3 * a;
    /* the tip (0.5, 6, 0.5) of the body frame; there v = (52.5, 0, -52.5) */
    if (X[0] == 1.5 && X[1] == 1.5 && X[2] == 9.0) {
      ++tips;
      ck_assert(fabs(v[0] - 52.5) < 1e-12 && fabs(v[1] - 52.5) < 1e-12 &&
                fabs(v[2]) < 1e-12);
    }
  }
  ck_assert_int_eq(base, 25);
  ck_assert_int_eq(tips, 1);
  sph_particles_destroy(ps);
  sph_scene_destroy(s);
  /* an oblique roller: [0, 3, 4] is (0, 0.6, 0.8) */
  const char *roller[] = {
      "boundaries.0={name: r, select: {plane: {axis: [0, 1, 0], at: 0}}, "
      "roller: {axis: [0, 3, 4]}}"};
  ck_assert_int_eq(load_text(good, &s, roller, 1, &err), SPH_OK);
  const sph_boundary *b = &s->boundaries[0];
  ck_assert_int_eq(b->axis, -1);
  ck_assert(b->normal[0] == 0.0 && fabs(b->normal[1] - 0.6) < 1e-16 &&
            fabs(b->normal[2] - 0.8) < 1e-16);
  ck_assert_int_eq(b->select.axis, 1); /* [0, 1, 0] is y */
  sph_scene_destroy(s);
}
END_TEST

START_TEST(direction_errors) {
  expect_error(with_line(13, "  - {name: base, select: {plane: {axis: [0, 0, "
                             "0], at: 0}}, clamp: true}"),
               SPH_ERR_RANGE, 13, "axis", "boundaries[0].select.plane.axis",
               "non-zero");
  expect_error(with_line(13, "  - {name: base, select: {plane: {axis: [1, 0], "
                             "at: 0}}, clamp: true}"),
               SPH_ERR_TYPE, 13, "axis", "boundaries[0].select.plane.axis",
               "3 numbers");
  expect_error(with_line(13, "  - {name: base, select: {plane: {axis: w, at: "
                             "0}}, clamp: true}"),
               SPH_ERR_RANGE, 13, "axis", "boundaries[0].select.plane.axis",
               "x, y, z or a vector");
  expect_error(with_line(13, "  - {name: base, select: {plane: {axis: y, at: "
                             "0}}, roller: {axis: [0, 0, 0]}}"),
               SPH_ERR_RANGE, 13, "axis: [0, 0, 0]",
               "boundaries[0].roller.axis", "non-zero");
  expect_error(with_line(13, "  - {name: base, select: {plane: {axis: [1, 1, "
                             "0], at: 0}}, symmetry: {axis: [1, 1, 0.1]}}"),
               SPH_ERR_ARG, 13, "symmetry", "boundaries[0].symmetry",
               "same normal");
  expect_error(with_line(11, "    initial_velocity: {rotation: {axis: [0, "
                             "0, 0], omega: 1}}"),
               SPH_ERR_RANGE, 11, "axis",
               "bodies[0].initial_velocity.rotation.axis", "non-zero");
  expect_error(with_line(11, "    transform: {rotate: {axis: [0, 0, 0], "
                             "angle: 10}}"),
               SPH_ERR_RANGE, 11, "axis", "bodies[0].transform.rotate.axis",
               "non-zero");
  expect_error(with_line(11, "    transform: {rotate: {axis: x}}"),
               SPH_ERR_MISSING_KEY, 11, "rotate",
               "bodies[0].transform.rotate.angle", "angle");
  expect_error(with_line(11, "    transform: {rotat: {angle: 10}}"),
               SPH_ERR_UNKNOWN_KEY, 11, "rotat", "bodies[0].transform.rotat",
               "did you mean 'rotate'");
  /* a velocity by components in a turned frame */
  char text[4096];
  replace_line(
      text, with_line(11, "    transform: {rotate: {axis: x, angle: 10}}"), 13,
      "  - {name: v, select: {plane: {axis: y, at: 0, body: column}}, "
      "velocity: {value: [1, 0, 0], components: [x]}}");
  expect_error(text, SPH_ERR_ARG, 13, "components",
               "boundaries[0].velocity.components", "whole velocity");
}
END_TEST

int main(void) {
  Suite *s = suite_create("scene");
  TCase *tc = tcase_create("scene");
  tcase_add_test(tc, twisting_column_loads);
  tcase_add_test(tc, overrides);
  tcase_add_test(tc, png_off);
  tcase_add_test(tc, error_classes);
  tcase_add_test(tc, dimension_and_shape_errors);
  tcase_add_test(tc, placed_body);
  tcase_add_test(tc, direction_errors);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
