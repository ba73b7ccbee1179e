/* A scene from YAML text for the Check suites: written to a temporary file
 * (errors then name a real path) and loaded; one-body scenes and a point
 * order for comparing particle sets. */
#ifndef SPH_TEST_SCENE_UTIL_H
#define SPH_TEST_SCENE_UTIL_H

#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/particles.h"
#include "scene/scene.h"

/* one material "m", the end time and the start of the bodies */
#define SPH_TEST_SCENE_MATERIALS                                               \
  "materials:\n"                                                               \
  "  m: {model: neo-hookean, density: 1000, youngs_modulus: 1e6, "             \
  "poisson_ratio: 0.3}\n"                                                      \
  "time: {end: 0.1}\n"                                                         \
  "bodies:\n"

/* name, dimension, method, one material "m" and the start of the bodies */
#define SPH_TEST_SCENE_HEAD(dim)                                               \
  "name: t\n"                                                                  \
  "dimension: " #dim "\n"                                                      \
  "method: {name: tl-jst}\n" SPH_TEST_SCENE_MATERIALS

/* A scene of one body "part" of material m: `shape`, and `particles` and
 * `transform` (flow mappings) where not NULL. */
static inline void sph_test_one_body(char *buf, size_t size, int dim,
                                     const char *method, const char *shape,
                                     const char *particles,
                                     const char *transform) {
  int n = snprintf(
      buf, size,
      "name: t\n"
      "dimension: %d\n"
      "method: {name: %s}\n" SPH_TEST_SCENE_MATERIALS "  - name: part\n"
      "    material: m\n"
      "    shape: %s\n"
      "%s%s\n"
      "%s%s\n",
      dim, method, shape, particles ? "    particles: " : "",
      particles ? particles : "", transform ? "    transform: " : "",
      transform ? transform : "");
  ck_assert_msg(n >= 0 && (size_t)n < size, "scene text too long");
}

/* Loads `text` (the file is removed again); the loader's status. */
static inline sph_status sph_test_scene_load(const char *text, sph_scene **s,
                                             sph_error *err) {
  char path[64] = "/tmp/sph_test_XXXXXX";
  int fd = mkstemp(path);
  ck_assert_int_ge(fd, 0);
  ck_assert_int_eq(write(fd, text, strlen(text)), (ssize_t)strlen(text));
  close(fd);
  sph_status st = sph_scene_load(s, path, NULL, 0, err);
  unlink(path);
  return st;
}

/* Loads `text` (the file is removed again) and asserts that it loads. */
static inline sph_scene *sph_test_scene_text(const char *text) {
  sph_scene *s;
  sph_error err;
  sph_status st = sph_test_scene_load(text, &s, &err);
  ck_assert_msg(st == SPH_OK, "%s", err.message);
  return s;
}

/* The particles of the scene `text` (asserts that it loads and builds;
 * `what` labels a failure). */
static inline sph_particles *sph_test_scene_particles(const char *text,
                                                      const char *what) {
  sph_scene *s;
  sph_error err;
  sph_status st = sph_test_scene_load(text, &s, &err);
  ck_assert_msg(st == SPH_OK, "%s: %s", what, err.message);
  sph_particles *ps;
  st = sph_scene_build_particles(s, &ps, &err);
  ck_assert_msg(st == SPH_OK, "%s: %s", what, err.message);
  sph_scene_destroy(s);
  return ps;
}

/* Asserts that a and b are the same particles: count, positions and
 * volumes to the bit (`what` labels a failure). */
static inline void sph_test_assert_same_particles(const sph_particles *a,
                                                  const sph_particles *b,
                                                  const char *what) {
  ck_assert_msg(a->n == b->n, "%s: %zu particles, expected %zu", what, b->n,
                a->n);
  ck_assert_msg(!memcmp(a->field[SPH_FIELD_POSITION0],
                        b->field[SPH_FIELD_POSITION0],
                        3 * a->n * sizeof(double)),
                "%s: positions differ", what);
  ck_assert_msg(!memcmp(a->field[SPH_FIELD_VOLUME0],
                        b->field[SPH_FIELD_VOLUME0], a->n * sizeof(double)),
                "%s: volumes differ", what);
}

/* Asserts that a load of `shape` returned `code` (st), its error at `key`
 * with `fragment` in the message. */
static inline void sph_test_assert_refused(sph_status st, const sph_error *err,
                                           const char *shape, sph_status code,
                                           const char *key,
                                           const char *fragment) {
  ck_assert_msg(st == code, "%s: got %s (%s)", shape, sph_status_name(st),
                err->message);
  ck_assert_msg(!strcmp(err->key, key), "key %s, expected %s", err->key, key);
  ck_assert_msg(strstr(err->message, fragment), "message '%s' lacks '%s'",
                err->message, fragment);
}

/* qsort order of 3-vectors: lexicographic */
static inline int sph_test_cmp_point(const void *a, const void *b) {
  const double *x = a, *y = b;
  for (int c = 0; c < 3; ++c)
    if (x[c] != y[c])
      return x[c] < y[c] ? -1 : 1;
  return 0;
}

#endif
