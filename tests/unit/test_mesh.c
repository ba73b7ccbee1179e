/* Mesh bodies (shape: {mesh: ...}, src/scene/mesh.c): the meshes of
 * tests/data/meshes (make_meshes.py) against the built-in shapes — a unit
 * cube mesh gives the box's particles exactly, defective cubes (a hole, a
 * duplicated and a flipped triangle), binary STL and millimetres the same;
 * an icosphere the sphere's count within one surface layer; a turned and
 * moved mesh body the pre-moved mesh; the same lattice on 1 and 2 threads;
 * rays through edges and vertices; and each refused input with its place. */
#include "test_scene_util.h"
#include "test_util.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/particles.h"
#include "scene/mesh.h"
#include "scene/scene.h"

#define MESHES SPH_SOURCE_DIR "/tests/data/meshes/"

static sph_status load(const char *shape, const char *particles,
                       const char *transform, sph_scene **s, sph_error *err) {
  char text[2048];
  sph_test_one_body(text, sizeof text, 3, "tl-jst", shape, particles,
                    transform);
  return sph_test_scene_load(text, s, err);
}

static sph_particles *particles_of(const char *shape, const char *particles,
                                   const char *transform) {
  char text[2048];
  sph_test_one_body(text, sizeof text, 3, "tl-jst", shape, particles,
                    transform);
  return sph_test_scene_particles(text, shape);
}

static const char *const box = "{box: {min: [0, 0, 0], max: [1, 1, 1]}}";
static const char *const lattices[] = {"{count: [5, 6, 7]}", "{spacing: 0.1}",
                                       "{spacing: 0.1, distribution: jitter}"};

START_TEST(test_cube_is_the_box) {
  /* the face lattice: the box's particles, faces included, bit for bit */
  sph_particles *b = particles_of(box, lattices[0], NULL);
  sph_particles *m =
      particles_of("{mesh: {file: " MESHES "cube.stl}}", lattices[0], NULL);
  ck_assert_uint_eq(b->n, 5 * 6 * 7);
  sph_test_assert_same_particles(b, m, "cube.stl, count");
  sph_particles_destroy(b);
  sph_particles_destroy(m);
}
END_TEST

START_TEST(test_defective_cubes) {
  static const char *const files[] = {
      "{mesh: {file: " MESHES "cube_binary.stl}}",
      "{mesh: {file: " MESHES "cube_hole.stl}}",
      "{mesh: {file: " MESHES "cube_dup_flip.stl}}",
      "{mesh: {file: " MESHES "cube_mm.stl, units: mm}}"};
  for (int l = 0; l < 3; ++l) {
    sph_particles *ref =
        particles_of("{mesh: {file: " MESHES "cube.stl}}", lattices[l], NULL);
    ck_assert_uint_gt(ref->n, 200);
    for (int f = 0; f < 4; ++f) {
      sph_particles *m = particles_of(files[f], lattices[l], NULL);
      char what[256];
      snprintf(what, sizeof what, "%s, %s", files[f], lattices[l]);
      sph_test_assert_same_particles(ref, m, what);
      sph_particles_destroy(m);
    }
    sph_particles_destroy(ref);
  }
}
END_TEST

START_TEST(test_icosphere_is_the_sphere) {
  const double r = 0.5, dp = 0.04;
  sph_particles *s =
      particles_of("{sphere: {center: [0.5, 0.5, 0.5], radius: 0.5}}",
                   "{spacing: 0.04}", NULL);
  sph_particles *m = particles_of("{mesh: {file: " MESHES "icosphere.obj}}",
                                  "{spacing: 0.04}", NULL);
  double layer = 4.0 * M_PI * r * r / (dp * dp);
  ck_assert_msg(fabs((double)m->n - (double)s->n) < layer,
                "icosphere %zu particles, sphere %zu, layer %g", m->n, s->n,
                layer);
  double vm = 0.0, vs = 4.0 / 3.0 * M_PI * r * r * r;
  for (size_t a = 0; a < m->n; ++a)
    vm += m->field[SPH_FIELD_VOLUME0][a];
  ck_assert_msg(fabs(vm / vs - 1.0) < 0.01, "particle volume %g, sphere %g", vm,
                vs);
  sph_scene *sc;
  sph_error err;
  ck_assert_int_eq(load("{mesh: {file: " MESHES "icosphere.obj}}",
                        "{spacing: 0.04}", NULL, &sc, &err),
                   SPH_OK);
  const sph_mesh_info *in = sph_mesh_get_info(sc->bodies[0].shape.mesh);
  ck_assert_uint_eq(in->triangles, 1280);
  ck_assert_uint_eq(in->open_edges, 0);
  ck_assert_msg(fabs(in->volume / vs - 1.0) < 0.01, "mesh volume %g",
                in->volume);
  sph_scene_destroy(sc);
  sph_particles_destroy(s);
  sph_particles_destroy(m);
}
END_TEST

START_TEST(test_transform_is_the_moved_mesh) {
  /* turned 90 degrees about z and moved: exact in binary, so the same
   * points (in another order) */
  sph_particles *t =
      particles_of("{mesh: {file: " MESHES "ell.stl}}", "{spacing: 0.125}",
                   "{rotate: {axis: z, angle: 90}, translate: [2, 1, 0.5]}");
  sph_particles *m = particles_of("{mesh: {file: " MESHES "ell_moved.stl}}",
                                  "{spacing: 0.125}", NULL);
  ck_assert_uint_eq(t->n, m->n);
  ck_assert_uint_eq(m->n, 8 * 8 * 4 * 3 / 4); /* the L: 3/4 of its box */
  double *a = t->field[SPH_FIELD_POSITION0], *b = m->field[SPH_FIELD_POSITION0];
  qsort(a, t->n, 3 * sizeof *a, sph_test_cmp_point);
  qsort(b, m->n, 3 * sizeof *b, sph_test_cmp_point);
  ck_assert(!memcmp(a, b, 3 * m->n * sizeof *a));
  sph_particles_destroy(t);
  sph_particles_destroy(m);
}
END_TEST

START_TEST(test_threads) {
  omp_set_num_threads(1);
  sph_particles *one = particles_of("{mesh: {file: " MESHES "icosphere.obj}}",
                                    "{spacing: 0.02}", NULL);
  omp_set_num_threads(2);
  sph_particles *two = particles_of("{mesh: {file: " MESHES "icosphere.obj}}",
                                    "{spacing: 0.02}", NULL);
  sph_test_assert_same_particles(one, two, "1 and 2 threads");
  sph_particles_destroy(one);
  sph_particles_destroy(two);
}
END_TEST

/* a unit cube in memory: rays along the face diagonals and through the
 * corners cross each face exactly once */
START_TEST(test_rays_on_edges) {
  double *tri;
  size_t n;
  sph_error err;
  ck_assert_int_eq(sph_mesh_read(MESHES "cube.stl", &tri, &n, &err), SPH_OK);
  ck_assert_uint_eq(n, 12);
  sph_mesh *m;
  ck_assert_int_eq(sph_mesh_create(&m, tri, n, 1.0, 0, &err), SPH_OK);
  static const double in[][3] = {{0.5, 0.5, 0.5},    {0.25, 0.25, 0.25},
                                 {0.75, 0.75, 0.75}, {0.3, 0.5, 0.5},
                                 {0.5, 0.5, 0.01},   {0.999, 0.5, 0.001}};
  static const double out[][3] = {{1.5, 0.5, 0.5}, {-0.5, 0.5, 0.5},
                                  {0.5, 0.5, 2.0}, {2.0, 2.0, 2.0},
                                  {1.0, 1.0, 1.5}, {-1.0, 0.0, 0.0}};
  for (size_t k = 0; k < sizeof in / sizeof *in; ++k)
    ck_assert_msg(sph_mesh_inside(m, in[k]), "point %zu", k);
  for (size_t k = 0; k < sizeof out / sizeof *out; ++k)
    ck_assert_msg(!sph_mesh_inside(m, out[k]), "point %zu", k);
  const sph_mesh_info *info = sph_mesh_get_info(m);
  ck_assert_double_eq(info->volume, 1.0);
  /* distances: to a face, an edge, a corner, and inside */
  static const double X[][4] = {{0.5, 0.5, 1.5, 0.5},
                                {2.0, 0.5, 2.0, M_SQRT2},
                                {-1.0, -1.0, -1.0, 1.7320508075688772},
                                {0.5, 0.5, 0.75, 0.25}};
  for (int k = 0; k < 4; ++k)
    ck_assert_double_eq_tol(sph_mesh_distance(m, X[k]), X[k][3], 1e-15);
  sph_mesh_destroy(m);
  ck_assert_int_eq(sph_mesh_create(&m, tri, n, 1.0, 1, &err), SPH_OK);
  ck_assert_double_eq(sph_mesh_get_info(m)->volume, -1.0);
  ck_assert(sph_mesh_inside(m, in[0])); /* the side does not need normals */
  sph_mesh_destroy(m);
  free(tri);
}
END_TEST

/* several shells: the unit cube, a second one apart (moved by 3 in x) and
 * a cavity inside the first (a cube of side 0.5 about its centre): the
 * solid they bound, whichever way the cavity's triangles face */
START_TEST(test_shells) {
  double *tri;
  size_t n;
  sph_error err;
  ck_assert_int_eq(sph_mesh_read(MESHES "cube.stl", &tri, &n, &err), SPH_OK);
  double *all = malloc(3 * 9 * n * sizeof *all);
  for (size_t k = 0; k < 9 * n; ++k) {
    all[k] = tri[k];
    all[9 * n + k] = tri[k] + (k % 3 == 0 ? 3.0 : 0.0);
    all[18 * n + k] = 0.25 + 0.5 * tri[k];
  }
  static const double in[][3] = {
      {0.1, 0.1, 0.1}, {0.9, 0.5, 0.5}, {3.5, 0.5, 0.5}, {3.1, 0.9, 0.2}};
  static const double out[][3] = {
      {0.5, 0.5, 0.5}, {0.3, 0.6, 0.7}, {2.0, 0.5, 0.5}, {1.5, 0.5, 0.5}};
  for (int flip = 0; flip < 2; ++flip) {
    if (flip) /* the cavity's triangles turned inwards, as it should be */
      for (size_t t = 2 * n; t < 3 * n; ++t)
        for (int c = 0; c < 3; ++c) {
          double x = all[9 * t + 3 + c];
          all[9 * t + 3 + c] = all[9 * t + 6 + c];
          all[9 * t + 6 + c] = x;
        }
    sph_mesh *m;
    ck_assert_int_eq(sph_mesh_create(&m, all, 3 * n, 1.0, 0, &err), SPH_OK);
    for (size_t k = 0; k < sizeof in / sizeof *in; ++k)
      ck_assert_msg(sph_mesh_inside(m, in[k]), "flip %d point %zu", flip, k);
    for (size_t k = 0; k < sizeof out / sizeof *out; ++k)
      ck_assert_msg(!sph_mesh_inside(m, out[k]), "flip %d point %zu", flip, k);
    ck_assert_double_eq_tol(sph_mesh_get_info(m)->volume,
                            flip ? 2.0 - 0.125 : 2.125, 1e-12);
    sph_mesh_destroy(m);
  }
  free(all);
  free(tri);
}
END_TEST

/* the error's place: `key` on line 10 (the shape) or 11 (the particles) */
static void refused(const char *shape, const char *particles, sph_status code,
                    const char *key, const char *fragment) {
  sph_scene *s;
  sph_error err;
  sph_status st = load(shape, particles, NULL, &s, &err);
  sph_test_assert_refused(st, &err, shape, code, key, fragment);
  ck_assert_int_eq(err.line, strstr(key, "particles") ? 11 : 10);
}

START_TEST(test_bad_input) {
  const char *file = "bodies[0].shape.mesh.file";
  const char *p = "{spacing: 0.1}";
  refused("{mesh: {file: " MESHES "none.stl}}", p, SPH_ERR_IO, file,
          "none.stl: no such file");
  refused("{mesh: {file: " MESHES "}}", p, SPH_ERR_IO, file, "not a file");
  refused("{mesh: {file: " MESHES "make_meshes.py}}", p, SPH_ERR_IO, file,
          "not a mesh sph can read");
  refused("{mesh: {file: " MESHES "sheet.stl}}", p, SPH_ERR_GEOMETRY, file,
          "no volume");
  refused("{mesh: {file: " MESHES "cube_inverted.stl}}", p, SPH_ERR_GEOMETRY,
          file, "set flip_normals: true");
  refused("{mesh: {file: " MESHES "cube.stl, flip_normals: true}}", p,
          SPH_ERR_GEOMETRY, file, "remove flip_normals");
  refused("{mesh: {file: " MESHES "cube.stl, units: furlong}}", p,
          SPH_ERR_RANGE, "bodies[0].shape.mesh.units", "furlong");
  refused("{mesh: {file: " MESHES "cube.stl}}",
          "{spacing: 0.1, distribution: relax}", SPH_ERR_ARG,
          "bodies[0].particles.distribution", "not relaxed");
  /* inverted normals flipped back: the cube again */
  sph_particles *a =
      particles_of("{mesh: {file: " MESHES "cube.stl}}", p, NULL);
  sph_particles *b = particles_of("{mesh: {file: " MESHES
                                  "cube_inverted.stl, flip_normals: true}}",
                                  p, NULL);
  sph_test_assert_same_particles(a, b, "flip_normals");
  sph_particles_destroy(a);
  sph_particles_destroy(b);
}
END_TEST

static Suite *mesh_suite(void) {
  Suite *s = suite_create("mesh");
  TCase *tc = tcase_create("core");
  tcase_add_test(tc, test_cube_is_the_box);
  tcase_add_test(tc, test_defective_cubes);
  tcase_add_test(tc, test_icosphere_is_the_sphere);
  tcase_add_test(tc, test_transform_is_the_moved_mesh);
  tcase_add_test(tc, test_threads);
  tcase_add_test(tc, test_rays_on_edges);
  tcase_add_test(tc, test_shells);
  tcase_add_test(tc, test_bad_input);
  suite_add_tcase(s, tc);
  return s;
}

int main(void) { return sph_test_run(mesh_suite()); }
