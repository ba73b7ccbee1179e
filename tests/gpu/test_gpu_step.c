/* The device step on a GPU (docs/gpu.md), against the CPU's tl-jst pF on a
 * jittered twisting column with its base clamped: after one step every
 * field within 1e-12 relative (the kernels are built with --fmad=false, so
 * products and sums round as the CPU's; pow in the stress may differ from
 * glibc's by an ulp), with and without the JST term, after 200 steps
 * within 1e-9 (round-off carried along), and two device runs equal to the
 * bit. Exit 77 (ctest SKIP) when there is no device or no CUDA build.
 * With the JST projection and the angular momentum projection (the shipped
 * column's method) the same; and the shipped twisting column's energies
 * after 500 steps within 1e-6 relative of the CPU's.
 *   test_gpu_step [--scenes DIR]  the checks above, PASS/FAIL per line
 *   test_gpu_step --twin ...      the host twin in the device's place: the
 *                                 harness checked without a GPU
 *   test_gpu_step --bench K       a K x 6K x K column (K = 55: ~1M
 *                                 particles): device particle-steps/s and
 *                                 bytes per particle, CPU for one step */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gpu/gpu.h"
#include "scene/scene.h"
#include "solver/sim.h"
#include "test_column.h"

#define SKIP 77

/* --twin: the host twin stands in for the device (the harness checked on a
 * machine without a GPU; its figures are then exact) */
static int use_twin;
typedef struct stepper {
  sph_gpu_step *d;
  sph_gpu_tl_jst *h;
  int stages;
} stepper;

static sph_status st_create(stepper *s, sph_gpu_tl_jst *h, int stages,
                            sph_error *err) {
  s->h = h;
  s->stages = stages;
  s->d = NULL;
  return use_twin ? SPH_OK : sph_gpu_tl_jst_create(&s->d, h, stages, err);
}

static sph_status st_advance(stepper *s, double dt, long steps,
                             sph_error *err) {
  if (!use_twin)
    return sph_gpu_tl_jst_advance(s->d, dt, steps, err);
  for (long i = 0; i < steps; ++i)
    sph_gpu_tl_jst_twin_step(s->h, s->stages, dt);
  return SPH_OK;
}

static sph_status st_download(stepper *s, double *x, double *p, double *F,
                              sph_error *err) {
  if (!use_twin)
    return sph_gpu_tl_jst_download(s->d, x, p, F, err);
  size_t n = s->h->n;
  if (x != s->h->x) {
    memcpy(x, s->h->x, 3 * n * sizeof *x);
    memcpy(p, s->h->p, 3 * n * sizeof *p);
    memcpy(F, s->h->F, 9 * n * sizeof *F);
  }
  return SPH_OK;
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static sph_scene *column(const char *method, int k, double height) {
  char text[2048], path[64] = "/tmp/sph_gpu_XXXXXX";
  sph_test_column_text(text, sizeof text, method, k, height);
  FILE *f = fdopen(mkstemp(path), "w");
  if (!f || fputs(text, f) < 0 || fclose(f) != 0)
    return NULL;
  sph_scene *s = NULL;
  sph_error err;
  if (sph_scene_load(&s, path, NULL, 0, &err) != SPH_OK)
    fprintf(stderr, "scene: %s\n", err.message);
  remove(path);
  return s;
}

/* CPU and device over `steps` steps; 0 when every field is within tol */
static int compare(const char *label, const char *method, int steps,
                   double tol) {
  sph_scene *s = column(method, 3, 3.0);
  sph_sim *sim;
  sph_error err;
  if (!s || sph_sim_create(&sim, s, &err) != SPH_OK) {
    printf("FAIL %s: set-up\n", label);
    return 1;
  }
  sph_gpu_tl_jst h[2];
  int stages, bad = 0;
  stepper d[2];
  for (int r = 0; r < 2 && !bad; ++r)
    bad = sph_gpu_tl_jst_host_create(sim, &h[r], &stages, &err) != SPH_OK ||
          st_create(&d[r], &h[r], stages, &err) != SPH_OK;
  double dt = 0.5 * sph_sim_stable_dt(sim);
  for (int k = 0; k < steps && !bad; ++k)
    bad = sph_sim_step(sim, dt, &err) != SPH_OK;
  for (int r = 0; r < 2 && !bad; ++r)
    bad = st_advance(&d[r], dt, steps, &err) != SPH_OK;
  if (bad) {
    printf("FAIL %s: %s\n", label, err.message);
    return 1;
  }
  size_t n = h[0].n;
  double *y[2][3];
  for (int r = 0; r < 2; ++r) {
    y[r][0] = malloc(3 * n * sizeof(double));
    y[r][1] = malloc(3 * n * sizeof(double));
    y[r][2] = malloc(9 * n * sizeof(double));
    st_download(&d[r], y[r][0], y[r][1], y[r][2], &err);
  }
  sph_state_array arr[8];
  int count = sim->method->state(sim, arr), fail = 0;
  static const char *const names[3] = {"x", "p", "F"};
  printf("%s (%zu particles, %d steps of %.3g s):", label, n, steps, dt);
  for (int f = 0; f < 3; ++f)
    for (int i = 0; i < count; ++i)
      if (strcmp(arr[i].name, names[f]) == 0) {
        double e = sph_test_rel_diff(y[0][f], arr[i].data, arr[i].len);
        int same = memcmp(y[0][f], y[1][f], arr[i].len * sizeof(double)) == 0;
        printf(" %s %.3g%s", names[f], e, same ? "" : " (runs differ)");
        fail |= !(e <= tol) || !same;
      }
  printf("\n%s %s: every field within %g relative of the CPU, two device "
         "runs equal to the bit\n",
         fail ? "FAIL" : "PASS", label, tol);
  for (int r = 0; r < 2; ++r) {
    for (int f = 0; f < 3; ++f)
      free(y[r][f]);
    sph_gpu_tl_jst_destroy(d[r].d);
    sph_gpu_tl_jst_host_destroy(&h[r]);
  }
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
  return fail;
}

static const char *const plain_rk2 =
    "{name: tl-jst, fields: pF, jst: {eps4_p: 0}, "
    "angular_momentum_projection: false, jst_projection: false}";
static const char *const jst_rk2 =
    "{name: tl-jst, fields: pF, jst: {eps4_p: 0.125}, "
    "angular_momentum_projection: false, jst_projection: false}";
static const char *const plain_rk3 =
    "{name: tl-jst, fields: pF, integrator: ssp-rk3, jst: {eps4_p: 0}, "
    "angular_momentum_projection: false, jst_projection: false}";

/* The shipped twisting column (scenes/twisting_column.yaml: JST with its
 * projection, the angular momentum projection, TVD-RK2, clamped base)
 * `steps` steps on the CPU and the device: kinetic and strain energy of
 * the device's state (copied into the CPU's method) within 1e-6 relative
 * of the CPU's */
static int shipped_energy(const char *scenes, int steps) {
  char path[1024];
  snprintf(path, sizeof path, "%s/twisting_column.yaml", scenes);
  sph_scene *s = NULL;
  sph_sim *sim;
  sph_error err;
  if (sph_scene_load(&s, path, NULL, 0, &err) != SPH_OK ||
      sph_sim_create(&sim, s, &err) != SPH_OK) {
    printf("FAIL shipped twisting column: %s\n", err.message);
    return 1;
  }
  sph_gpu_tl_jst h;
  int stages;
  stepper d = {0};
  double dt = 0.5 * sph_sim_stable_dt(sim), k0, s0, k1, s1;
  int bad = sph_gpu_tl_jst_host_create(sim, &h, &stages, &err) != SPH_OK ||
            st_create(&d, &h, stages, &err) != SPH_OK ||
            st_advance(&d, dt, steps, &err) != SPH_OK;
  for (int k = 0; k < steps && !bad; ++k)
    bad = sph_sim_step(sim, dt, &err) != SPH_OK;
  if (bad) {
    printf("FAIL shipped twisting column: %s\n", err.message);
    return 1;
  }
  sim->method->energy(sim, &k0, &s0);
  sph_state_array arr[8];
  int count = sim->method->state(sim, arr);
  double *y[3] = {NULL, NULL, NULL};
  for (int i = 0; i < count; ++i) {
    if (strcmp(arr[i].name, "x") == 0)
      y[0] = arr[i].data;
    else if (strcmp(arr[i].name, "p") == 0)
      y[1] = arr[i].data;
    else if (strcmp(arr[i].name, "F") == 0)
      y[2] = arr[i].data;
  }
  st_download(&d, y[0], y[1], y[2], &err);
  sim->method->energy(sim, &k1, &s1);
  double ek = fabs(k1 - k0) / fabs(k0), es = fabs(s1 - s0) / fabs(s0);
  int fail = !(ek <= 1e-6 && es <= 1e-6);
  printf("shipped twisting column, %d steps of %.3g s (t = %.4g s): kinetic "
         "CPU %.10g device %.10g (%.2g), strain CPU %.10g device %.10g "
         "(%.2g)\n%s shipped twisting column: energies within 1e-6 "
         "relative\n",
         steps, dt, steps * dt, k0, k1, ek, s0, s1, es, fail ? "FAIL" : "PASS");
  sph_gpu_tl_jst_destroy(d.d);
  sph_gpu_tl_jst_host_destroy(&h);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
  return fail;
}

/* particle-steps/s of the device on a k x 6k x k column */
static int bench(int k) {
  double t0 = now();
  sph_scene *s = column("{name: tl-jst}", k, 6.0);
  sph_sim *sim;
  sph_error err;
  if (!s || sph_sim_create(&sim, s, &err) != SPH_OK) {
    printf("FAIL bench: set-up\n");
    return 1;
  }
  sph_gpu_tl_jst h;
  int stages;
  sph_gpu_step *d = NULL;
  if (sph_gpu_tl_jst_host_create(sim, &h, &stages, &err) != SPH_OK ||
      sph_gpu_tl_jst_create(&d, &h, stages, &err) != SPH_OK) {
    printf("FAIL bench: %s\n", err.message);
    return 1;
  }
  double setup = now() - t0, dt = 0.5 * sph_sim_stable_dt(sim);
  long steps = 50;
  sph_gpu_tl_jst_advance(d, dt, 2, &err); /* warm-up */
  t0 = now();
  sph_status st = sph_gpu_tl_jst_advance(d, dt, steps, &err);
  double gpu = now() - t0;
  t0 = now();
  sph_gpu_tl_jst_download(d, h.x, h.p, h.F, &err);
  double copy = now() - t0;
  t0 = now();
  sph_sim_step(sim, dt, &err);
  double cpu = now() - t0;
  double n = (double)h.n;
  printf("bench: %.0f particles (set-up on the CPU %.1f s): device %.3g "
         "particle-steps/s (%ld steps in %.3f s), %.0f bytes of device "
         "memory per particle, copy back %.3f s; CPU %.3g particle-steps/s "
         "(one step, all threads)\n",
         n, setup, n * (double)steps / gpu, steps, gpu,
         (double)sph_gpu_tl_jst_bytes(d) / n, copy, n / cpu);
  printf("%s bench\n", st == SPH_OK ? "PASS" : "FAIL");
  sph_gpu_tl_jst_destroy(d);
  sph_gpu_tl_jst_host_destroy(&h);
  sph_sim_destroy(sim);
  sph_scene_destroy(s);
  return st != SPH_OK;
}

int main(int argc, char **argv) {
  char why[256];
  if (argc > 1 && strcmp(argv[1], "--twin") == 0) {
    use_twin = 1;
    --argc;
    ++argv;
    printf("the host twin stands in for the device\n");
  } else if (sph_gpu_probe(why, sizeof why) <= 0) {
    printf("SKIP: %s\n", why);
    return SKIP;
  }
  if (!use_twin)
    printf("device: %s\n", why);
  if (argc == 3 && strcmp(argv[1], "--bench") == 0)
    return use_twin ? 2 : bench(atoi(argv[2]));
  const char *scenes = argc == 3 && strcmp(argv[1], "--scenes") == 0
                           ? argv[2]
                           : SPH_SOURCE_DIR "/scenes";
  int fail = compare("one step, TVD-RK2", plain_rk2, 1, 1e-12);
  fail |= compare("one step, SSP-RK3", plain_rk3, 1, 1e-12);
  fail |= compare("one step, TVD-RK2 + JST", jst_rk2, 1, 1e-12);
  fail |= compare("200 steps, TVD-RK2", plain_rk2, 200, 1e-9);
  fail |= compare("200 steps, TVD-RK2 + JST", jst_rk2, 200, 1e-9);
  fail |= compare("one step, the shipped column's method", "{name: tl-jst}", 1,
                  1e-12);
  fail |= compare("one step, SSP-RK3 with projections",
                  "{name: tl-jst, integrator: ssp-rk3}", 1, 1e-12);
  fail |= compare("200 steps, the shipped column's method", "{name: tl-jst}",
                  200, 1e-9);
  fail |= shipped_energy(scenes, 500);
  return fail ? 1 : 0;
}
