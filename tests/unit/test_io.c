/* Output: atomic files (no temporary left, content replaced, failures leave
 * nothing), the checkerboard indicator at its extremes, and summary.json /
 * energy.csv of a tiny run read back (JSON through python3's parser). */
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/sink.h"
#include "solver/stability.h"

static int exists(const char *p) {
  struct stat st;
  return stat(p, &st) == 0;
}

START_TEST(atomic_files) {
  char dir[] = "/tmp/sph_io_XXXXXX";
  ck_assert_ptr_nonnull(mkdtemp(dir));
  char path[128], tmp[160];
  snprintf(path, sizeof path, "%s/a.txt", dir);
  snprintf(tmp, sizeof tmp, "%s.part", path);
  sph_atomic_file af;
  sph_error err;
  ck_assert_int_eq(sph_atomic_open(&af, path, &err), SPH_OK);
  fputs("first", af.f);
  ck_assert(!exists(path)); /* nothing under the final name yet */
  ck_assert_int_eq(sph_atomic_commit(&af, &err), SPH_OK);
  ck_assert(exists(path) && !exists(tmp));
  ck_assert_int_eq(sph_atomic_open(&af, path, &err), SPH_OK);
  fputs("second", af.f);
  sph_atomic_abort(&af); /* a failed writer leaves the old file */
  char buf[16] = {0};
  FILE *f = fopen(path, "r");
  ck_assert_uint_eq(fread(buf, 1, sizeof buf - 1, f), 5);
  fclose(f);
  ck_assert_str_eq(buf, "first");
  ck_assert(!exists(tmp));
  char missing[160];
  snprintf(missing, sizeof missing, "%s/no/such/dir/x", dir);
  ck_assert_int_eq(sph_atomic_open(&af, missing, &err), SPH_ERR_IO);
  ck_assert_str_eq(err.file, missing);
  remove(path);
  rmdir(dir);
}
END_TEST

START_TEST(checkerboard_extremes) {
  /* 8 x 8 x 8 lattice: a linear field, a smooth bump, a red-black field */
  enum { N = 512 };
  static signed char parity[N];
  static double vol[N], lin[N], bump[N], rb[N];
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j)
      for (int k = 0; k < 8; ++k) {
        int a = (i * 8 + j) * 8 + k;
        parity[a] = ((i + j + k) % 2) ? -1 : 1;
        vol[a] = 1.0;
        lin[a] = 3.0 * i - 2.0 * j + k;
        bump[a] = exp(-((i - 3.5) * (i - 3.5) + (j - 3.5) * (j - 3.5)) / 8.0);
        rb[a] = 5.0 + 2.0 * parity[a];
      }
  double cl = sph_checkerboard_indicator(parity, vol, lin, N);
  double cb = sph_checkerboard_indicator(parity, vol, bump, N);
  double cr = sph_checkerboard_indicator(parity, vol, rb, N);
  ck_assert_msg(cl < 1e-12 && cb < 1e-12, "smooth fields: %g %g", cl, cb);
  ck_assert_msg(fabs(cr - 1.0) < 1e-12, "red-black field: %g", cr);
  ck_assert(cr > SPH_CHECKERBOARD_MAX && cl < SPH_CHECKERBOARD_MAX);
  /* a smooth field with 30 % red-black noise on top trips the threshold */
  for (int a = 0; a < N; ++a)
    bump[a] += 0.3 * parity[a];
  ck_assert(sph_checkerboard_indicator(parity, vol, bump, N) >
            SPH_CHECKERBOARD_MAX);
  memset(parity, 0, sizeof parity);
  ck_assert(isnan(sph_checkerboard_indicator(parity, vol, rb, N)));
}
END_TEST

START_TEST(run_outputs_read_back) {
  char dir[] = "/tmp/sph_run_XXXXXX";
  ck_assert_ptr_nonnull(mkdtemp(dir));
  char scene[160], cmd[1024];
  snprintf(scene, sizeof scene, "%s/s.yaml", dir);
  FILE *f = fopen(scene, "w");
  fputs("name: tiny\ndimension: 3\nmethod: {name: tl-jst}\n"
        "materials: {m: {density: 1000, youngs_modulus: 1e6, poisson_ratio: "
        "0.3}}\nbodies:\n  - {name: b, material: m, shape: {box: {min: [0, 0, "
        "0], max: [1, 1, 1]}}, particles: {count: [4, 4, 4]}, "
        "initial_velocity: {uniform: [1, 0, 0]}}\ntime: {end: 0.01}\n"
        "output: {every: 0.005, probes: [{name: c, at: [0, 0, 0]}]}\n",
        f);
  fclose(f);
  snprintf(cmd, sizeof cmd, "%s/sph run %s --out %s/out --quiet > /dev/null",
           SPH_BINARY_DIR, scene, dir);
  ck_assert_int_eq(system(cmd), 0);
  snprintf(
      cmd, sizeof cmd,
      "/usr/bin/python3 -c 'import json,sys; d=json.load(open(sys.argv[1]));"
      " k=[\"scene\",\"method\",\"terms\",\"particles\",\"steps\","
      "\"wall_seconds\",\"dt_min\",\"dt_max\",\"energy\","
      "\"linear_momentum_drift\",\"angular_momentum_drift\",\"J\",\"nan\","
      "\"stable\",\"reason\"]; sys.exit(0 if all(x in d for x in k) and "
      "d[\"particles\"]==64 and d[\"stable\"] else 1)' %s/out/summary.json",
      dir);
  ck_assert_int_eq(system(cmd), 0);
  char path[200], line[512];
  snprintf(path, sizeof path, "%s/out/energy.csv", dir);
  f = fopen(path, "r");
  ck_assert_ptr_nonnull(f);
  int rows = 0;
  double t, k, w, tot, px;
  ck_assert_ptr_nonnull(fgets(line, sizeof line, f));
  ck_assert_ptr_nonnull(
      strstr(line, "time [s],kinetic [J],strain [J],total [J]"));
  while (fgets(line, sizeof line, f)) {
    ck_assert_int_eq(sscanf(line, "%lf,%lf,%lf,%lf,%lf", &t, &k, &w, &tot, &px),
                     5);
    /* a uniform 1 m/s translation of 1000 kg: E = 500 J, p_x = 1000 */
    ck_assert(fabs(k - 500.0) < 1e-9 && fabs(px - 1000.0) < 1e-9);
    rows++;
  }
  fclose(f);
  ck_assert_int_eq(rows, 3); /* t = 0, 0.005, 0.01 */
  snprintf(path, sizeof path, "%s/out/probes.csv", dir);
  ck_assert(exists(path));
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  ck_assert_int_eq(system(cmd), 0);
}
END_TEST

int main(void) {
  Suite *s = suite_create("io");
  TCase *tc = tcase_create("io");
  tcase_set_timeout(tc, 60);
  tcase_add_test(tc, atomic_files);
  tcase_add_test(tc, checkerboard_extremes);
  tcase_add_test(tc, run_outputs_read_back);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
