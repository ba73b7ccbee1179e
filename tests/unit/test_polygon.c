/* 2D outlines (shape: {polygon: ...}, src/scene/polygon.c): a square is the
 * built-in box exactly, a hole and an L take their share of the lattice,
 * a turned polygon body is the pre-turned outline, rays through vertices
 * count once, and each refused input names its key. */
#include "test_scene_util.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/particles.h"
#include "scene/polygon.h"
#include "scene/scene.h"

static sph_status load(int dim, const char *shape, const char *particles,
                       const char *transform, sph_scene **s, sph_error *err) {
  char text[2048];
  sph_test_one_body(text, sizeof text, dim, "ul-sph", shape, particles,
                    transform);
  return sph_test_scene_load(text, s, err);
}

static sph_particles *particles_of(const char *shape, const char *particles,
                                   const char *transform) {
  char text[2048];
  sph_test_one_body(text, sizeof text, 2, "ul-sph", shape, particles,
                    transform);
  return sph_test_scene_particles(text, shape);
}

static const char *const square =
    "{polygon: {points: [[0, 0], [1, 0], [1, 1], [0, 1]]}}";

START_TEST(test_square_is_the_box) {
  sph_particles *b = particles_of("{box: {min: [0, 0], max: [1, 1]}}",
                                  "{spacing: 0.05}", NULL);
  sph_particles *p = particles_of(square, "{spacing: 0.05}", NULL);
  ck_assert_uint_eq(b->n, 400);
  sph_test_assert_same_particles(b, p, "square");
  sph_particles_destroy(b);
  sph_particles_destroy(p);
}
END_TEST

START_TEST(test_hole_and_ell) {
  sph_particles *h = particles_of(
      "{polygon: {points: [[0, 0], [1, 0], [1, 1], [0, 1]], holes: [[[0.25, "
      "0.25], [0.75, 0.25], [0.75, 0.75], [0.25, 0.75]]]}}",
      "{spacing: 0.05}", NULL);
  ck_assert_uint_eq(h->n, 400 - 100);
  /* the L, clockwise: orientation does not matter */
  sph_particles *l = particles_of("{polygon: {points: [[0, 1], [0.5, 1], "
                                  "[0.5, 0.5], [1, 0.5], [1, 0], [0, 0]]}}",
                                  "{spacing: 0.05}", NULL);
  ck_assert_uint_eq(l->n, 300);
  sph_particles_destroy(h);
  sph_particles_destroy(l);
}
END_TEST

START_TEST(test_transform_is_the_moved_outline) {
  /* the L turned 90 degrees and moved by (2, 1): (x, y) -> (2 - y, 1 + x) */
  sph_particles *t = particles_of("{polygon: {points: [[0, 0], [1, 0], [1, "
                                  "0.5], [0.5, 0.5], [0.5, 1], [0, 1]]}}",
                                  "{spacing: 0.125}",
                                  "{rotate: {angle: 90}, translate: [2, 1]}");
  sph_particles *m = particles_of("{polygon: {points: [[2, 1], [2, 2], [1.5, "
                                  "2], [1.5, 1.5], [1, 1.5], [1, 1]]}}",
                                  "{spacing: 0.125}", NULL);
  ck_assert_uint_eq(t->n, 48);
  ck_assert_uint_eq(m->n, t->n);
  double *a = t->field[SPH_FIELD_POSITION0], *b = m->field[SPH_FIELD_POSITION0];
  qsort(a, t->n, 3 * sizeof *a, sph_test_cmp_point);
  qsort(b, m->n, 3 * sizeof *b, sph_test_cmp_point);
  ck_assert(!memcmp(a, b, 3 * m->n * sizeof *a));
  sph_particles_destroy(t);
  sph_particles_destroy(m);
}
END_TEST

START_TEST(test_rays_through_vertices) {
  /* a diamond: the ray from (0, 0) along +x passes through (1, 0) */
  const double xy[] = {0, -1, 1, 0, 0, 1, -1, 0};
  const size_t start[] = {0, 4};
  sph_polygon *p;
  sph_error err;
  ck_assert_int_eq(sph_polygon_create(&p, xy, start, 1, &err), SPH_OK);
  static const double in[][3] = {
      {0, 0, 0}, {-0.5, 0, 0}, {0, 0.5, 0}, {0.4, -0.5, 0}};
  static const double out[][3] = {
      {1.5, 0, 0}, {-1.5, 0, 0}, {0.6, 0.6, 0}, {0, 1.5, 0}};
  for (size_t k = 0; k < 4; ++k) {
    ck_assert_msg(sph_polygon_inside(p, in[k]), "point %zu", k);
    ck_assert_msg(!sph_polygon_inside(p, out[k]), "point %zu", k);
  }
  ck_assert_double_eq(sph_polygon_area(p), 2.0);
  sph_polygon_destroy(p);
}
END_TEST

static void refused(int dim, const char *shape, const char *particles,
                    sph_status code, const char *key, const char *fragment) {
  sph_scene *s;
  sph_error err;
  sph_status st = load(dim, shape, particles, NULL, &s, &err);
  sph_test_assert_refused(st, &err, shape, code, key, fragment);
}

START_TEST(test_bad_input) {
  const char *p = "{spacing: 0.1}", *key = "bodies[0].shape.polygon";
  refused(2, "{polygon: {points: [[0, 0], [1, 0]]}}", p, SPH_ERR_GEOMETRY, key,
          "the outline has 2 points");
  refused(2, "{polygon: {points: [[0, 0], [1, 0], [2, 0]]}}", p,
          SPH_ERR_GEOMETRY, key, "the outline encloses no area");
  refused(2,
          "{polygon: {points: [[0, 0], [1, 0], [1, 1]], holes: [[[0, 0], [1, "
          "1]]]}}",
          p, SPH_ERR_GEOMETRY, key, "hole 1 has 2 points");
  refused(2,
          "{polygon: {points: [[0, 0], [1, 0], [1, 1]], holes: [[[-1, -1], "
          "[3, -1], [3, 3], [-1, 3]]]}}",
          p, SPH_ERR_GEOMETRY, key, "the holes cover the outline");
  refused(2, "{polygon: {points: [[0, 0], [1, 0], [1, a]]}}", p, SPH_ERR_TYPE,
          "bodies[0].shape.polygon.points[2][1]", "expected a number");
  refused(2, "{polygon: {points: [[0, 0], [1, 0, 3], [1, 1]]}}", p,
          SPH_ERR_TYPE, "bodies[0].shape.polygon.points[1]",
          "expected a point [x, y]");
  refused(3, "{polygon: {points: [[0, 0], [1, 0], [1, 1]]}}", p,
          SPH_ERR_GEOMETRY, key, "a polygon is a 2D shape");
  refused(2, square, "{spacing: 0.1, distribution: relax}", SPH_ERR_ARG,
          "bodies[0].particles.distribution", "not relaxed");
  refused(2, square, "{count: [3, 3]}", SPH_ERR_ARG,
          "bodies[0].particles.count", "counts apply to boxes and meshes");
}
END_TEST

/* text into a file named `name` under /tmp; its path into path[128] */
static void put(char *path, const char *name, const char *text) {
  snprintf(path, 128, "/tmp/sph_outline_%d_%s", (int)getpid(), name);
  FILE *f = fopen(path, "w");
  ck_assert_ptr_nonnull(f);
  fputs(text, f);
  fclose(f);
}

static const char *const hole =
    "{polygon: {points: [[0, 0], [1, 0], [1, 1], [0, 1]], holes: [[[0.25, "
    "0.25], [0.75, 0.25], [0.75, 0.75], [0.25, 0.75]]]}}";

/* CSV (the hole first: the largest ring is the outline) and SVG (y down,
 * a path and a rect) in mm give the polygon's particles */
START_TEST(test_outline_files) {
  char csv[128], svg[128], shape[256];
  put(csv, "a.csv",
      "# a square with a hole, mm\nx, y\n250, 250\n750, 250\n750, "
      "750\n250, 750\n\n0, 0\n1000, 0\n1000, 1000\n0, 1000\n");
  put(svg, "a.svg",
      "<?xml version=\"1.0\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\">\n"
      "<path d=\"M 0 0 H 1000 V -1000 h -1000 Z\"/>\n"
      "<rect x=\"250\" y=\"-750\" width=\"500\" height=\"500\"/>\n</svg>\n");
  sph_particles *ref = particles_of(hole, "{spacing: 0.05}", NULL);
  ck_assert_uint_eq(ref->n, 300);
  const char *files[] = {csv, svg};
  for (int k = 0; k < 2; ++k) {
    snprintf(shape, sizeof shape, "{outline: {file: %s, units: mm}}", files[k]);
    sph_particles *o = particles_of(shape, "{spacing: 0.05}", NULL);
    ck_assert_uint_eq(o->n, ref->n);
    ck_assert_msg(!memcmp(ref->field[SPH_FIELD_POSITION0],
                          o->field[SPH_FIELD_POSITION0],
                          3 * o->n * sizeof(double)),
                  "%s", files[k]);
    sph_particles_destroy(o);
  }
  sph_particles_destroy(ref);
  unlink(csv);
  unlink(svg);
}
END_TEST

START_TEST(test_outline_bad_files) {
  static const struct {
    const char *name, *text, *fragment;
    sph_status code;
  } bad[] = {{"b.csv", "0, 0\n1, 0\n1, one\n", "b.csv:3: expected x, y",
              SPH_ERR_SYNTAX},
             {"c.csv", "# nothing\n", "no points", SPH_ERR_GEOMETRY},
             {"d.svg", "<svg><path d=\"M 0 0 C 1 1 2 2 3 3 Z\"/></svg>",
              "d.svg:1: a path with curves", SPH_ERR_SYNTAX},
             {"e.svg",
              "<svg>\n<g transform=\"scale(2)\"><rect width=\"1\" "
              "height=\"1\"/></g></svg>",
              "e.svg:2: a transform attribute", SPH_ERR_SYNTAX},
             {"f.svg", "<svg><rect width=\"1\" height=\"1\"></svg>",
              "not SVG that sph can read", SPH_ERR_SYNTAX},
             {"g.svg", "<svg><text>no shapes</text></svg>", "no polygon",
              SPH_ERR_GEOMETRY},
             {"h.dxf", "0\nSECTION\n", "an outline is a .svg or a .csv file",
              SPH_ERR_IO},
             {"i.svg", "<svg><polygon points=\"0,0 1,0 1\"/></svg>",
              "an x without its y", SPH_ERR_SYNTAX}};
  for (size_t k = 0; k < sizeof bad / sizeof *bad; ++k) {
    char path[128], shape[256];
    put(path, bad[k].name, bad[k].text);
    snprintf(shape, sizeof shape, "{outline: {file: %s}}", path);
    refused(2, shape, "{spacing: 0.1}", bad[k].code,
            "bodies[0].shape.outline.file", bad[k].fragment);
    unlink(path);
  }
}
END_TEST

static Suite *polygon_suite(void) {
  Suite *s = suite_create("polygon");
  TCase *tc = tcase_create("core");
  tcase_add_test(tc, test_square_is_the_box);
  tcase_add_test(tc, test_hole_and_ell);
  tcase_add_test(tc, test_transform_is_the_moved_outline);
  tcase_add_test(tc, test_rays_through_vertices);
  tcase_add_test(tc, test_bad_input);
  tcase_add_test(tc, test_outline_files);
  tcase_add_test(tc, test_outline_bad_files);
  suite_add_tcase(s, tc);
  return s;
}

int main(void) { return sph_test_run(polygon_suite()); }
