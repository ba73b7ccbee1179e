/* The per-rank set-up (sph_scene_build_share, sph_domain_create_share,
 * issue 20) against the whole set's (sph_scene_build_particles,
 * sph_particles_sort_morton, sph_domain_create): on every rank the same
 * owned particles (fields, ids, bodies, flags bit for bit), storage
 * indices, ghosts (positions, volumes, bodies, ids, in the same order) and
 * halo plan; the same for the updated-Lagrangian (dynamic) domain. 3D face
 * lattice with jitter (a turned column), 2D cells with jitter, two 3D bodies (a
 * block and a punch), relaxed bodies (a 2D ring; a turned 3D ball and a
 * plate), each rank relaxing its slice. With symmetry and skew-symmetry
 * planes (sph_domain_create_share_mirrored against
 * sph_domain_create_mirrored, the ghosts of the planes' images included):
 * the swinging cube's six coordinate planes, the punch's two (also
 * dynamic), a turned plate's oblique ones. Run under mpirun (ctest: 2, 3
 * and 4 ranks). */
#include "parallel/domain_impl.h"

#include <check.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpi_check.h"
#include "scene/scene.h"
#include "test_scene_util.h"

#define SAME(a, b, n) (memcmp((a), (b), (n) * sizeof *(a)) == 0)

/* the two particle sets' first n particles: equal bit for bit */
static int same_set(const sph_particles *a, const sph_particles *b) {
  static const sph_field f[] = {SPH_FIELD_POSITION0, SPH_FIELD_VOLUME0,
                                SPH_FIELD_VELOCITY};
  int ok = a->n == b->n;
  for (size_t k = 0; ok && k < sizeof f / sizeof *f; ++k)
    ok = a->field[f[k]] && b->field[f[k]] &&
         SAME(a->field[f[k]], b->field[f[k]],
              a->n * (size_t)sph_field_components(f[k]));
  return ok && SAME(a->id, b->id, a->n) && SAME(a->body, b->body, a->n) &&
         SAME(a->flags, b->flags, a->n);
}

/* the scene's symmetry and skew-symmetry planes, as solver/sim.c passes
 * them */
static int scene_planes(const sph_scene *s, sph_domain_plane *planes) {
  int np = 0;
  for (size_t k = 0; k < s->nboundaries && np < 32; ++k) {
    const sph_boundary *bc = &s->boundaries[k];
    if (bc->kind != SPH_BC_SYMMETRY && bc->kind != SPH_BC_SKEW_SYMMETRY)
      continue;
    planes[np] =
        (sph_domain_plane){.at = bc->select.at, .axis = bc->select.axis};
    memcpy(planes[np++].n, bc->select.normal, sizeof planes->n);
  }
  return np;
}

/* ranks where the two set-ups differ (dynamic: the updated-Lagrangian
 * domain's, owned sets and their room; with the scene's planes when it
 * has some) */
static int differences(const char *text, double support, int dynamic) {
  sph_scene *s = sph_test_scene_text(text);
  sph_domain_plane planes[32];
  int np = scene_planes(s, planes);
  sph_error err;
  sph_particles *whole = NULL, *share = NULL;
  int64_t *gidx = NULL, first;
  size_t N = 0;
  ck_assert_int_eq(sph_scene_build_particles(s, &whole, &err), SPH_OK);
  ck_assert_int_eq(sph_particles_sort_morton(whole, support, &err), SPH_OK);
  ck_assert_int_eq(sph_scene_build_share(s, support, sph_domain_world_rank(),
                                         sph_domain_world_size(), &share, &gidx,
                                         &N, &first, &err),
                   SPH_OK);
  ck_assert_ptr_nonnull(share);
  sph_domain *a = NULL, *b = NULL;
  ck_assert_int_eq(
      dynamic ? sph_domain_create_dynamic(&a, &whole, support, &err)
      : np ? sph_domain_create_mirrored(&a, &whole, support, planes, np, &err)
           : sph_domain_create(&a, &whole, support, &err),
      SPH_OK);
  ck_assert_int_eq(np && !dynamic
                       ? sph_domain_create_share_mirrored(
                             &b, &share, gidx, N, support, planes, np, &err)
                       : sph_domain_create_share(&b, &share, gidx, N, support,
                                                 dynamic, &err),
                   SPH_OK);
  ck_assert_int_eq(sph_domain_dyn_mirror(a, planes, np, 3.0, &err), SPH_OK);
  ck_assert_int_eq(sph_domain_dyn_mirror(b, planes, np, 3.0, &err), SPH_OK);
  int bad = a->n != b->n || a->ng != b->ng || a->nsend != b->nsend ||
            !same_set(whole, share) || whole->capacity != share->capacity ||
            sph_domain_migrates(a) != dynamic ||
            sph_domain_migrates(b) != dynamic;
  if (!bad) {
    size_t ng = a->ng;
    bad = !SAME(a->gidx, b->gidx, a->n + ng) || !SAME(a->gX, b->gX, 3 * ng) ||
          !SAME(a->gV, b->gV, ng) || !SAME(a->gbody, b->gbody, ng) ||
          !SAME(a->gid, b->gid, ng) ||
          !SAME(a->recv_count, b->recv_count, (size_t)a->size) ||
          !SAME(a->send_count, b->send_count, (size_t)a->size) ||
          !SAME(a->send_idx, b->send_idx, a->nsend);
  }
  int all = 0;
  MPI_Allreduce(&bad, &all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  sph_domain_destroy(a);
  sph_domain_destroy(b);
  sph_particles_destroy(whole);
  sph_particles_destroy(share);
  free(gidx);
  sph_scene_destroy(s);
  return all;
}

/* the fixed and the dynamic domain: the same on every rank */
static void same_both(const char *text, double support) {
  ck_assert_int_eq(differences(text, support, 0), 0);
  ck_assert_int_eq(differences(text, support, 1), 0);
}

START_TEST(column_3d) {
  const char *scene = SPH_TEST_SCENE_HEAD(
      3) "  - name: column\n"
         "    material: m\n"
         "    shape: {box: {min: [-0.5, 0, -0.5], max: [0.5, 6, 0.5]}}\n"
         "    particles: {count: [7, 37, 6], distribution: jitter, "
         "jitter: 0.3, seed: 7}\n"
         "    transform: {rotate: {axis: [1, 1, 0], angle: 20}}\n"
         "    initial_velocity: {rotation: {axis: y, omega: 105}}\n"
         "boundaries:\n"
         "  - {name: base, select: {plane: {axis: y, at: 0}}, clamp: "
         "true}\n";
  /* the support of h = 1.3 dp, wendland: 2.6 dp */
  same_both(scene, 2.6 * 1.0 / 6.0);
}
END_TEST

START_TEST(ring_2d) {
  const char *scene = SPH_TEST_SCENE_HEAD(
      2) "  - name: ring\n"
         "    material: m\n"
         "    shape: {ring: {center: [-1, 1], inner_radius: 0.2, "
         "outer_radius: 0.35}}\n"
         "    particles: {spacing: 0.01, distribution: jitter, seed: 5}\n"
         "    initial_velocity: {uniform: [1, 0, 0]}\n";
  same_both(scene, 0.026);
}
END_TEST

START_TEST(bodies_3d) {
  const char *scene = SPH_TEST_SCENE_HEAD(
      3) "  - name: block\n"
         "    material: m\n"
         "    shape: {box: {min: [-1, -0.4, -1], max: [1, 0, 1]}}\n"
         "    particles: {count: [21, 5, 21]}\n"
         "  - name: punch\n"
         "    material: m\n"
         "    shape: {cylinder: {center: [0, 0.05, 0], axis: y, radius: "
         "0.3, length: 0.5}}\n"
         "    particles: {spacing: 0.1, distribution: jitter, seed: 2}\n"
         "    initial_velocity: {uniform: [0, -1, 0]}\n";
  same_both(scene, 0.26);
}
END_TEST

/* the ghosts with planes against those without: more (the images'
 * sources and neighbourhoods), so the planes reached the search */
static size_t ghosts_of(const char *text, double support, int mirrored) {
  sph_scene *s = sph_test_scene_text(text);
  sph_domain_plane planes[32];
  int np = mirrored ? scene_planes(s, planes) : 0;
  sph_error err;
  sph_particles *share = NULL;
  int64_t *gidx = NULL, first;
  size_t N = 0;
  ck_assert_int_eq(sph_scene_build_share(s, support, sph_domain_world_rank(),
                                         sph_domain_world_size(), &share, &gidx,
                                         &N, &first, &err),
                   SPH_OK);
  sph_domain *d = NULL;
  ck_assert_int_eq(sph_domain_create_share_mirrored(&d, &share, gidx, N,
                                                    support, planes, np, &err),
                   SPH_OK);
  double ng = (double)d->ng;
  sph_domain_sum(d, &ng, 1);
  sph_domain_destroy(d);
  sph_particles_destroy(share);
  free(gidx);
  sph_scene_destroy(s);
  return (size_t)ng;
}

/* the swinging cube (scenes/swinging_cube.yaml) at spacing 1/8 (as
 * shipped, 2 ranks) and 1/16 */
#define CUBE(spacing)                                                          \
  SPH_TEST_SCENE_HEAD(3)                                                       \
  "  - name: cube\n"                                                           \
  "    material: m\n"                                                          \
  "    shape: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"                       \
  "    particles: {spacing: " spacing "}\n"                                    \
  "boundaries:\n"                                                              \
  "  - {name: b1, select: {plane: {axis: x, at: 0}}, symmetry: {axis: x}}\n"   \
  "  - {name: b2, select: {plane: {axis: y, at: 0}}, symmetry: {axis: y}}\n"   \
  "  - {name: b3, select: {plane: {axis: z, at: 0}}, symmetry: {axis: z}}\n"   \
  "  - {name: b4, select: {plane: {axis: x, at: 1}}, skew_symmetry: {axis: "   \
  "x}}\n"                                                                      \
  "  - {name: b5, select: {plane: {axis: y, at: 1}}, skew_symmetry: {axis: "   \
  "y}}\n"                                                                      \
  "  - {name: b6, select: {plane: {axis: z, at: 1}}, skew_symmetry: {axis: "   \
  "z}}\n"

START_TEST(swinging_cube) {
  /* the support of h = 1.3 dp, wendland: 2.6 dp */
  if (sph_domain_world_size() == 2)
    ck_assert_int_eq(differences(CUBE("0.125"), 2.6 * 0.125, 0), 0);
  ck_assert_int_eq(differences(CUBE("0.0625"), 2.6 * 0.0625, 0), 0);
  ck_assert_uint_gt(ghosts_of(CUBE("0.0625"), 2.6 * 0.0625, 1),
                    ghosts_of(CUBE("0.0625"), 2.6 * 0.0625, 0));
}
END_TEST

START_TEST(punch_2d) {
  /* scenes/punch_ul_csph.yaml's block and planes */
  const char *scene = SPH_TEST_SCENE_HEAD(
      2) "  - name: block\n"
         "    material: m\n"
         "    shape: {box: {min: [0, 0], max: [0.03, 0.01]}}\n"
         "    particles: {count: [31, 11]}\n"
         "boundaries:\n"
         "  - {name: b7, select: {plane: {axis: x, at: 0}}, symmetry: {axis: "
         "x}}\n"
         "  - {name: b8, select: {plane: {axis: y, at: 0}}, symmetry: {axis: "
         "y}}\n"
         "  - {name: b9, select: {plane: {axis: x, at: 0.03}}, roller: {axis: "
         "x}}\n";
  /* (on 4 ranks a rank would hold more ghosts than particles) */
  if (sph_domain_world_size() > 3)
    return;
  same_both(scene, 2.6 * 0.001);
}
END_TEST

START_TEST(oblique_2d) {
  /* the swinging plate turned by 30 degrees: its four planes oblique */
  const char *scene = SPH_TEST_SCENE_HEAD(
      2) "  - name: plate\n"
         "    material: m\n"
         "    shape: {box: {min: [0, 0], max: [2, 2]}}\n"
         "    particles: {spacing: 0.05, distribution: jitter, seed: 3}\n"
         "    transform: {rotate: {angle: 30}}\n"
         "boundaries:\n"
         "  - {name: b10, select: {plane: {axis: x, at: 0, body: plate}}, "
         "symmetry: {axis: x}}\n"
         "  - {name: b11, select: {plane: {axis: y, at: 0, body: plate}}, "
         "symmetry: {axis: y}}\n"
         "  - {name: b12, select: {plane: {axis: x, at: 2, body: plate}}, "
         "skew_symmetry: {axis: x}}\n"
         "  - {name: b13, select: {plane: {axis: y, at: 2, body: plate}}, "
         "skew_symmetry: {axis: y}}\n";
  same_both(scene, 0.13);
}
END_TEST

/* relaxed bodies: each rank relaxes its slice of each body, with the
 * other ranks' points as ghosts; a 2D ring and a turned 3D ball */
START_TEST(relax_ring_2d) {
  const char *scene = SPH_TEST_SCENE_HEAD(
      2) "  - name: ring\n"
         "    material: m\n"
         "    shape: {ring: {center: [-0.045, 0.01], inner_radius: 0.03, "
         "outer_radius: 0.04}}\n"
         "    particles: {spacing: 0.0015, distribution: relax, seed: 1}\n"
         "    initial_velocity: {uniform: [7, 0, 0]}\n";
  ck_assert_int_eq(differences(scene, 2.6 * 0.0015, 0), 0);
  ck_assert_int_eq(differences(scene, 2.6 * 0.0015, 1), 0);
}
END_TEST

START_TEST(relax_ball_3d) {
  const char *scene = SPH_TEST_SCENE_HEAD(
      3) "  - name: ball\n"
         "    material: m\n"
         "    shape: {shell: {center: [0.045, 0, 0], inner_radius: 0.02, "
         "outer_radius: 0.04}}\n"
         "    particles: {spacing: 0.005, distribution: relax, seed: 2}\n"
         "    transform: {rotate: {axis: [0, 1, 1], angle: 25}}\n"
         "    initial_velocity: {uniform: [-9, 0, 0]}\n"
         "  - name: plate\n"
         "    material: m\n"
         "    shape: {box: {min: [-0.05, -0.05, -0.05], max: [-0.01, 0.05, "
         "0.05]}}\n"
         "    particles: {spacing: 0.005, distribution: relax, seed: 3, "
         "relax_steps: 30}\n";
  ck_assert_int_eq(differences(scene, 2.6 * 0.005, 0), 0);
  ck_assert_int_eq(differences(scene, 2.6 * 0.005, 1), 0);
}
END_TEST

int main(int argc, char **argv) {
  sph_error err;
  if (sph_domain_init(&argc, &argv, &err) != SPH_OK)
    return 1;
  Suite *s = suite_create("share_setup");
  TCase *t = tcase_create("share_setup");
  tcase_set_timeout(t, 300);
  tcase_add_test(t, column_3d);
  tcase_add_test(t, ring_2d);
  tcase_add_test(t, bodies_3d);
  tcase_add_test(t, swinging_cube);
  tcase_add_test(t, punch_2d);
  tcase_add_test(t, oblique_2d);
  tcase_add_test(t, relax_ring_2d);
  tcase_add_test(t, relax_ball_3d);
  suite_add_tcase(s, t);
  return sph_mpi_check_run(s);
}
