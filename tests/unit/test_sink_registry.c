/* Adding a sink is one registry entry plus its file: the registry
 * (src/io/sink_registry.c) compiled here with one extra entry, the toy sink
 * of toy_sink.c; a short run through the public run API hands it every
 * output frame, after the shipped sinks, and names it in summary.json. */
#define SPH_SINK_LIST_EXTRA(X) X(toy)
#include "io/sink_registry.c"

#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sph/sph.h"
#include "toy_sink.h"

START_TEST(toy_sink_sees_every_frame) {
  const sph_sink_ops *const *list = sph_sink_list();
  int n = 0;
  while (list[n])
    ++n;
  ck_assert_int_eq(n, 5);
  ck_assert_str_eq(list[0]->name, "energy.csv");
  ck_assert_str_eq(list[1]->name, "vtk");
  ck_assert_str_eq(list[2]->name, "probes.csv");
  ck_assert_str_eq(list[3]->name, "png");
  ck_assert_str_eq(list[4]->name, "toy");

  char dir[] = "/tmp/sph_toy_sink_XXXXXX";
  ck_assert_ptr_nonnull(mkdtemp(dir));
  const char *sets[] = {"time.end=0.0004", "output.every=0.0001",
                        "output.png=false"};
  sph_scene *scene;
  sph_run *run;
  sph_error err;
  ck_assert_msg(sph_scene_load(&scene, SPH_SOURCE_DIR "/scenes/punch.yaml",
                               sets, 3, &err) == SPH_OK,
                "%s", err.message);
  sph_run_options opt = {.out_dir = dir};
  ck_assert_msg(sph_run_create(&run, scene, &opt, &err) == SPH_OK, "%s",
                err.message);
  ck_assert_int_eq(toy_seen.opened, 1);
  ck_assert_int_eq(toy_seen.frames, 1); /* t = 0 */
  ck_assert_int_eq(sph_run_advance(run, 0.0002, &err), SPH_OK);
  ck_assert_int_eq(toy_seen.frames, 3);
  ck_assert_int_eq(sph_run_advance(run, 1.0, &err), SPH_OK);
  sph_summary sum;
  ck_assert_msg(sph_run_close(run, &sum, &err) == SPH_OK, "%s", err.message);
  ck_assert_int_eq(sum.state, SPH_RUN_COMPLETED);
  ck_assert_int_eq(toy_seen.closed, 1);
  ck_assert_int_eq(toy_seen.frames, 5);
  for (int k = 0; k < 5; ++k) {
    ck_assert_int_eq(toy_seen.index[k], k);
    ck_assert_double_eq(toy_seen.time[k], fmin(0.0004, 0.0001 * k));
  }
  sph_run_destroy(run);
  sph_scene_destroy(scene);
  /* summary.json times it among the sinks */
  char path[256], buf[8192];
  snprintf(path, sizeof path, "%s/summary.json", dir);
  FILE *f = fopen(path, "r");
  ck_assert_ptr_nonnull(f);
  size_t got = fread(buf, 1, sizeof buf - 1, f);
  buf[got] = '\0';
  fclose(f);
  ck_assert_ptr_nonnull(strstr(buf, "\"toy\""));
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  ck_assert_int_eq(system(cmd), 0);
}
END_TEST

int main(void) {
  Suite *s = suite_create("sink_registry");
  TCase *tc = tcase_create("toy");
  tcase_set_timeout(tc, 120);
  tcase_add_test(tc, toy_sink_sees_every_frame);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
