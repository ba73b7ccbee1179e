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
#include "render/image.h"

static const char *const imgdiff_usage =
    "usage: sph imgdiff A.png B.png [--tolerance N] [--shift N] "
    "[--max-fraction F]\n"
    "                   [--max-cluster N] [--diff OUT.png]\n"
    "  compare two images: exit 0 same, 1 different, 2 usage or unreadable\n";

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

typedef struct imgdiff_parse {
  const char **files;
  int nfiles;
  const char **diff_path;
  sph_imgdiff_options *o;
} imgdiff_parse;

static int imgdiff_option(void *ctx, int id, const char *val) {
  imgdiff_parse *p = ctx;
  sph_imgdiff_options *o = p->o;
  long n;
  switch (id) {
  case SPH_OPT_TOLERANCE:
    if (!imgdiff_parse_long(val, 0, 255, &n))
      return imgdiff_bad_value("--tolerance", val, "an integer", 255);
    o->channel_tolerance = (int)n;
    return SPH_EXIT_OK;
  case SPH_OPT_SHIFT:
    if (!imgdiff_parse_long(val, 0, SPH_IMGDIFF_MAX_SHIFT, &n))
      return imgdiff_bad_value("--shift", val, "an integer",
                               SPH_IMGDIFF_MAX_SHIFT);
    o->shift = (int)n;
    return SPH_EXIT_OK;
  case SPH_OPT_MAX_CLUSTER:
    if (!imgdiff_parse_long(val, 0, 1L << 30, &n))
      return imgdiff_bad_value("--max-cluster", val, "a pixel count", 1L << 30);
    o->max_cluster = n;
    return SPH_EXIT_OK;
  case SPH_OPT_MAX_FRACTION: {
    char *end;
    double f = strtod(val, &end);
    if (end == val || *end || !isfinite(f) || f < 0.0 || f > 1.0)
      return imgdiff_bad_value("--max-fraction", val, "a fraction", 1);
    o->max_bad_fraction = f;
    return SPH_EXIT_OK;
  }
  case SPH_OPT_DIFF:
    *p->diff_path = val;
    return SPH_EXIT_OK;
  default:
    return SPH_EXIT_USAGE;
  }
}

static int imgdiff_operand(void *ctx, const char *arg) {
  imgdiff_parse *p = ctx;
  if (p->nfiles >= 2) {
    fprintf(stderr, "sph imgdiff: more than two images given (%s)\n", arg);
    return SPH_EXIT_USAGE;
  }
  p->files[p->nfiles++] = arg;
  return SPH_EXIT_OK;
}

static const int imgdiff_allowed[] = {SPH_OPT_TOLERANCE,    SPH_OPT_SHIFT,
                                      SPH_OPT_MAX_FRACTION, SPH_OPT_MAX_CLUSTER,
                                      SPH_OPT_DIFF,         0};
static const sph_app_command imgdiff_command = {
    "imgdiff", imgdiff_usage, imgdiff_allowed, imgdiff_option, imgdiff_operand};

/* Parses argv[2..]; prints usage errors; returns 0, 2 or SPH_APP_HELP. */
static int imgdiff_parse_args(int argc, char **argv, const char **files,
                              const char **diff_path, sph_imgdiff_options *o) {
  imgdiff_parse p = {files, 0, diff_path, o};
  int rc = sph_app_getopt(&imgdiff_command, argc, argv, &p);
  if (rc == SPH_EXIT_OK && p.nfiles < 2) {
    fprintf(stderr, "sph imgdiff: two images are needed\n%s", imgdiff_usage);
    return SPH_EXIT_USAGE;
  }
  return rc;
}

int sph_cmd_imgdiff(int argc, char **argv) {
  const char *files[2] = {NULL, NULL};
  const char *diff_path = NULL;
  sph_imgdiff_options o;
  sph_imgdiff_defaults(&o);
  int rc = imgdiff_parse_args(argc, argv, files, &diff_path, &o);
  if (rc != SPH_EXIT_OK)
    return rc == SPH_APP_HELP ? SPH_EXIT_OK : rc;
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
