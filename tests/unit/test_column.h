/* The GPU step's test case for tests/unit/test_gpu_twin.c and
 * tests/gpu/test_gpu_step.c: a jittered twisting column of rubber, its
 * base clamped, as scene text; and the relative difference of two
 * arrays. */
#ifndef SPH_TEST_COLUMN_H
#define SPH_TEST_COLUMN_H

#include <math.h>
#include <stdio.h>

/* a k x round(k height) x k column of height `height`, method `method` */
static inline void sph_test_column_text(char *buf, size_t size,
                                        const char *method, int k,
                                        double height) {
  snprintf(buf, size,
           "name: t\ndimension: 3\nmethod: %s\n"
           "kernel: {type: cubic, h_over_dp: 1.3}\n"
           "materials: {rubber: {model: neo-hookean, density: 1100, "
           "youngs_modulus: 17e6, poisson_ratio: 0.45}}\n"
           "bodies:\n  - name: column\n    material: rubber\n"
           "    shape: {box: {min: [-0.5, 0, -0.5], max: [0.5, %g, 0.5]}}\n"
           "    particles: {count: [%d, %d, %d], distribution: jitter, "
           "jitter: 0.2, seed: 7}\n"
           "    initial_velocity: {rotation: {axis: y, omega: 105, center: "
           "[0, 0, 0], profile: \"sin(pi*y/(2*%g))\"}}\n"
           "boundaries:\n  - {name: base, select: {plane: {axis: y, at: 0}}, "
           "clamp: true}\ntime: {end: 1}\n",
           method, height, k, (int)lround(k * height), k, height);
}

/* the largest |a - b| over the array, relative to its largest |b| */
static inline double sph_test_rel_diff(const double *a, const double *b,
                                       size_t len) {
  double d = 0.0, m = 0.0;
  for (size_t i = 0; i < len; ++i) {
    d = fmax(d, fabs(a[i] - b[i]));
    m = fmax(m, fabs(b[i]));
  }
  return m > 0.0 ? d / m : d;
}

#endif
