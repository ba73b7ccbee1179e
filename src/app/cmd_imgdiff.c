/* sph imgdiff: compare two PNG images with the tolerant comparison of
 * include/sph/image.h, print one line of figures, optionally write the
 * highlighted difference image; exit 0 when they match, 1 when they differ
 * (different sizes included), 2 for usage errors and unreadable files. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/app_impl.h"
#include "sph/image.h"

static const char *const imgdiff_usage =
    "usage: sph imgdiff A.png B.png [--tolerance N] [--shift N] "
    "[--max-fraction F] [--max-cluster N] [--diff OUT.png]\n";

/* An integer option value in [lo, hi]; 0 on a bad value. */
static int imgdiff_parse_long(const char *s, long lo, long hi, long *out) {
  char *end;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (end == s || *end || errno || v < lo || v > hi)
    return 0;
  *out = v;
  return 1;
}

static int imgdiff_bad_value(const char *opt, const char *val, const char *what,
                             long hi) {
  fprintf(stderr, "sph imgdiff: %s '%s': expected %s from 0 to %ld\n", opt, val,
          what, hi);
  return SPH_EXIT_USAGE;
}

/* Parses argv[2..]; prints usage errors; returns 0 or 2. */
static int imgdiff_parse(int argc, char **argv, const char **files,
                         const char **diff_path, sph_imgdiff_options *o) {
  int nfiles = 0;
  for (int i = 2; i < argc; ++i) {
    const char *a = argv[i];
    int takes = !strcmp(a, "--tolerance") || !strcmp(a, "--shift") ||
                !strcmp(a, "--max-fraction") || !strcmp(a, "--max-cluster") ||
                !strcmp(a, "--diff");
    const char *val = NULL;
    if (takes) {
      if (i + 1 >= argc) {
        fprintf(stderr, "sph imgdiff: %s needs a value\n%s", a, imgdiff_usage);
        return SPH_EXIT_USAGE;
      }
      val = argv[++i];
    }
    long n;
    if (!strcmp(a, "--tolerance")) {
      if (!imgdiff_parse_long(val, 0, 255, &n))
        return imgdiff_bad_value(a, val, "an integer", 255);
      o->channel_tolerance = (int)n;
    } else if (!strcmp(a, "--shift")) {
      if (!imgdiff_parse_long(val, 0, SPH_IMGDIFF_MAX_SHIFT, &n))
        return imgdiff_bad_value(a, val, "an integer", SPH_IMGDIFF_MAX_SHIFT);
      o->shift = (int)n;
    } else if (!strcmp(a, "--max-cluster")) {
      if (!imgdiff_parse_long(val, 0, 1L << 30, &n))
        return imgdiff_bad_value(a, val, "a pixel count", 1L << 30);
      o->max_cluster = n;
    } else if (!strcmp(a, "--max-fraction")) {
      char *end;
      double f = strtod(val, &end);
      if (end == val || *end || !isfinite(f) || f < 0.0 || f > 1.0)
        return imgdiff_bad_value(a, val, "a fraction", 1);
      o->max_bad_fraction = f;
    } else if (!strcmp(a, "--diff")) {
      *diff_path = val;
    } else if (a[0] == '-' && a[1] == '-') {
      fprintf(stderr, "sph imgdiff: unknown option %s\n%s", a, imgdiff_usage);
      return SPH_EXIT_USAGE;
    } else if (nfiles < 2) {
      files[nfiles++] = a;
    } else {
      fprintf(stderr, "sph imgdiff: more than two images given (%s)\n%s", a,
              imgdiff_usage);
      return SPH_EXIT_USAGE;
    }
  }
  if (nfiles < 2) {
    fprintf(stderr, "sph imgdiff: two images are needed\n%s", imgdiff_usage);
    return SPH_EXIT_USAGE;
  }
  return SPH_EXIT_OK;
}

int sph_cmd_imgdiff(int argc, char **argv) {
  const char *files[2] = {NULL, NULL};
  const char *diff_path = NULL;
  sph_imgdiff_options o;
  sph_imgdiff_defaults(&o);
  int rc = imgdiff_parse(argc, argv, files, &diff_path, &o);
  if (rc != SPH_EXIT_OK)
    return rc;
  sph_error err;
  sph_error_clear(&err);
  sph_image a = {0, 0, NULL}, b = {0, 0, NULL}, diff = {0, 0, NULL};
  /* both images, each error naming its file */
  if (sph_image_read_png(files[0], &a, &err) != SPH_OK ||
      sph_image_read_png(files[1], &b, &err) != SPH_OK) {
    sph_app_print_error(&err);
    sph_image_destroy(&a);
    return SPH_EXIT_USAGE;
  }
  /* different sizes are a failed comparison */
  if (a.width != b.width || a.height != b.height) {
    sph_error_set(&err, SPH_ERR_ARG,
                  "image sizes differ: %s is %dx%d, %s is %dx%d", files[0],
                  a.width, a.height, files[1], b.width, b.height);
    sph_app_print_error(&err);
    printf("different: image sizes differ (%dx%d and %dx%d)\n", a.width,
           a.height, b.width, b.height);
    sph_image_destroy(&a);
    sph_image_destroy(&b);
    return SPH_EXIT_FAIL;
  }
  sph_imgdiff_result r;
  sph_status st =
      sph_image_diff(&a, &b, &o, &r, diff_path ? &diff : NULL, &err);
  sph_image_destroy(&a);
  sph_image_destroy(&b);
  if (st != SPH_OK) {
    sph_app_print_error(&err);
    return SPH_EXIT_USAGE;
  }
  /* the figures, with what tripped */
  int over_fraction = r.bad_fraction > o.max_bad_fraction;
  int over_cluster = r.largest_cluster > o.max_cluster;
  printf("%s%s: bad_pixels=%ld bad_fraction=%.6g largest_cluster=%ld "
         "max_channel_diff=%d (tolerance %d, shift %d, max fraction %g, "
         "max cluster %ld)\n",
         r.passed ? "passed" : "different",
         over_fraction && over_cluster ? " (fraction and cluster)"
         : over_fraction               ? " (fraction)"
         : over_cluster                ? " (cluster)"
                                       : "",
         r.bad_pixels, r.bad_fraction, r.largest_cluster, r.max_channel_diff,
         o.channel_tolerance, o.shift, o.max_bad_fraction, o.max_cluster);
  if (diff_path) {
    st = sph_image_write_png(diff_path, &diff, &err);
    sph_image_destroy(&diff);
    if (st != SPH_OK) {
      sph_app_print_error(&err);
      return SPH_EXIT_USAGE;
    }
  }
  return r.passed ? SPH_EXIT_OK : SPH_EXIT_FAIL;
}
