/* Images of the renderer: 8-bit RGBA buffers, PNG files read and written
 * through libpng, and the tolerant comparison `sph imgdiff` uses to check
 * rendered frames against references (channel tolerance, a small shift
 * allowance, limits on the bad-pixel fraction and on the largest cluster). */
#ifndef SPH_IMAGE_H
#define SPH_IMAGE_H

#include "sph/status.h"

/* Largest accepted width and height, in pixels. */
#define SPH_IMAGE_MAX_SIZE 16384

/* 8-bit RGBA, row 0 at the top, tightly packed (4 * width bytes a row). */
typedef struct sph_image {
  int width, height;
  unsigned char *rgba;
} sph_image;

/* Allocates a zeroed image; refuses width or height <= 0 or above
 * SPH_IMAGE_MAX_SIZE. On failure *img is left empty ({0, 0, NULL}). */
sph_status sph_image_create(sph_image *img, int width, int height,
                            sph_error *err);

/* Frees the pixels and empties the record. Accepts NULL and empty images. */
void sph_image_destroy(sph_image *img);

/* Reads a PNG of any colour type and bit depth into a new RGBA8 image
 * (palette and grey expanded, 16-bit scaled, transparency to alpha, opaque
 * alpha added; no gamma conversion). Missing, unreadable, non-PNG,
 * truncated or corrupt files fail with an error naming the file; on
 * failure *img is left empty. */
sph_status sph_image_read_png(const char *path, sph_image *img, sph_error *err);

/* Writes the image as an 8-bit PNG: RGB when every alpha is 255, else RGBA.
 * The bytes depend only on the pixels (no time stamp or other ancillary
 * chunk, fixed compression level and filter). Written to a temporary name
 * and renamed, so a failed write leaves nothing under `path`. */
sph_status sph_image_write_png(const char *path, const sph_image *img,
                               sph_error *err);

/* --- comparison ---------------------------------------------------------- */

/* Largest accepted shift radius, in pixels (the work per bad pixel grows
 * with its square: about 0.8 s for a 1280x720 image all bad at 8). */
#define SPH_IMGDIFF_MAX_SHIFT 8

typedef struct sph_imgdiff_options {
  int channel_tolerance;   /* a channel differing by <= this is equal (16) */
  int shift;               /* neighbourhood radius of the shift allowance (1) */
  double max_bad_fraction; /* fail when bad / all pixels exceeds this (0.001) */
  long max_cluster;        /* fail when the largest 8-connected cluster of bad
                              pixels exceeds this (8) */
} sph_imgdiff_options;

/* Fills the defaults given above. */
void sph_imgdiff_defaults(sph_imgdiff_options *o);

typedef struct sph_imgdiff_result {
  long bad_pixels;
  double bad_fraction;  /* bad_pixels / (width * height) */
  long largest_cluster; /* bad pixels in the largest 8-connected cluster */
  int max_channel_diff; /* largest R, G or B difference at equal positions */
  int passed;           /* fraction and cluster both within their limits */
} sph_imgdiff_result;

/* Compares two images of equal size. A pixel of A is bad when no pixel of B
 * within `shift` pixels (in x and y) matches it to within the channel
 * tolerance in each of R, G and B; B is checked against A the same way and
 * a position is bad when it fails either way. Alpha is not compared. The
 * comparison fails on the bad fraction or on the largest cluster, so one
 * missing feature is caught even when the fraction is tiny. `o` NULL means
 * the defaults. When `diff` is not NULL it receives a new image: A greyed
 * and dimmed, bad pixels in bright red. Different sizes are SPH_ERR_ARG,
 * options out of range SPH_ERR_RANGE. */
sph_status sph_image_diff(const sph_image *a, const sph_image *b,
                          const sph_imgdiff_options *o, sph_imgdiff_result *r,
                          sph_image *diff, sph_error *err);

#endif
