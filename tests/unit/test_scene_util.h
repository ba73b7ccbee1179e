/* A scene from YAML text for the Check suites: written to a temporary file
 * (errors then name a real path) and loaded. */
#ifndef SPH_TEST_SCENE_UTIL_H
#define SPH_TEST_SCENE_UTIL_H

#include <check.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene/scene.h"

/* name, dimension, method, one material "m" and the start of the bodies */
#define SPH_TEST_SCENE_HEAD(dim)                                               \
  "name: t\n"                                                                  \
  "dimension: " #dim "\n"                                                      \
  "method: {name: tl-jst}\n"                                                   \
  "materials:\n"                                                               \
  "  m: {model: neo-hookean, density: 1000, youngs_modulus: 1e6, "             \
  "poisson_ratio: 0.3}\n"                                                      \
  "time: {end: 0.1}\n"                                                         \
  "bodies:\n"

/* Loads `text` (the file is removed again) and asserts that it loads. */
static inline sph_scene *sph_test_scene_text(const char *text) {
  char path[64] = "/tmp/sph_test_XXXXXX";
  int fd = mkstemp(path);
  ck_assert_int_ge(fd, 0);
  ck_assert_int_eq(write(fd, text, strlen(text)), (ssize_t)strlen(text));
  close(fd);
  sph_scene *s;
  sph_error err;
  sph_status st = sph_scene_load(&s, path, NULL, 0, &err);
  unlink(path);
  ck_assert_msg(st == SPH_OK, "%s", err.message);
  return s;
}

#endif
