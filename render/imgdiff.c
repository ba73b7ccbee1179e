/* Tolerant image comparison (include/sph/image.h): per-channel tolerance,
 * a shift allowance checked in both directions (in the manner of VTK's image
 * regression test, which forgives one-pixel shifts), the bad-pixel fraction
 * and the largest 8-connected cluster of bad pixels, and the highlighted
 * difference image. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "render/image.h"

/* Mask values: a good pixel, a bad one, a bad one already in a cluster. */
enum { SPH_IMGDIFF_GOOD = 0, SPH_IMGDIFF_BAD = 1, SPH_IMGDIFF_SEEN = 2 };

void sph_imgdiff_defaults(sph_imgdiff_options *o) {
  o->channel_tolerance = 16;
  o->shift = 1;
  o->max_bad_fraction = 0.001;
  o->max_cluster = 8;
}

/* Whether R, G and B of p and q are each within tol. */
static inline int sph_imgdiff_close(const unsigned char *p,
                                    const unsigned char *q, int tol) {
  return abs((int)p[0] - (int)q[0]) <= tol &&
         abs((int)p[1] - (int)q[1]) <= tol && abs((int)p[2] - (int)q[2]) <= tol;
}

/* Marks pixels of a with no match in b within the shift window. */
static void sph_imgdiff_mark(const sph_image *a, const sph_image *b, int tol,
                             int shift, unsigned char *mask) {
  const int w = a->width, h = a->height;
  for (int y = 0; y < h; ++y) {
    const int y0 = y - shift < 0 ? 0 : y - shift;
    const int y1 = y + shift >= h ? h - 1 : y + shift;
    const unsigned char *arow = a->rgba + (size_t)y * w * 4;
    const unsigned char *brow = b->rgba + (size_t)y * w * 4;
    unsigned char *mrow = mask + (size_t)y * w;
    for (int x = 0; x < w; ++x) {
      const unsigned char *p = arow + 4 * (size_t)x;
      /* already bad, or matched in place (the common case) */
      if (mrow[x] || sph_imgdiff_close(p, brow + 4 * (size_t)x, tol))
        continue;
      const int x0 = x - shift < 0 ? 0 : x - shift;
      const int x1 = x + shift >= w ? w - 1 : x + shift;
      int found = 0;
      for (int yy = y0; yy <= y1 && !found; ++yy) {
        const unsigned char *q = b->rgba + ((size_t)yy * w + x0) * 4;
        for (int xx = x0; xx <= x1; ++xx, q += 4)
          if (sph_imgdiff_close(p, q, tol)) {
            found = 1;
            break;
          }
      }
      if (!found)
        mrow[x] = SPH_IMGDIFF_BAD;
    }
  }
}

/* Size of the largest 8-connected cluster of bad pixels (flood fill with an
 * explicit stack; each pixel is pushed at most once). */
static long sph_imgdiff_largest_cluster(unsigned char *mask, int w, int h,
                                        uint32_t *stack) {
  long largest = 0;
  const size_t n = (size_t)w * h;
  for (size_t start = 0; start < n; ++start) {
    if (mask[start] != SPH_IMGDIFF_BAD)
      continue;
    size_t top = 0;
    long size = 0;
    mask[start] = SPH_IMGDIFF_SEEN;
    stack[top++] = (uint32_t)start;
    while (top > 0) {
      const uint32_t i = stack[--top];
      ++size;
      const int x = (int)(i % (uint32_t)w), y = (int)(i / (uint32_t)w);
      for (int dy = -1; dy <= 1; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= h)
          continue;
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= w)
            continue;
          const size_t j = (size_t)yy * w + xx;
          if (mask[j] == SPH_IMGDIFF_BAD) {
            mask[j] = SPH_IMGDIFF_SEEN;
            stack[top++] = (uint32_t)j;
          }
        }
      }
    }
    if (size > largest)
      largest = size;
  }
  return largest;
}

/* A greyed and dimmed, bad pixels bright red, all opaque. */
static void sph_imgdiff_paint(const sph_image *a, const unsigned char *mask,
                              sph_image *diff) {
  const size_t n = (size_t)a->width * a->height;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char *p = a->rgba + 4 * i;
    unsigned char *q = diff->rgba + 4 * i;
    if (mask[i]) {
      q[0] = 255;
      q[1] = 0;
      q[2] = 0;
    } else {
      /* Rec. 601 luma, mapped into 40..125 */
      const unsigned luma = (77u * p[0] + 150u * p[1] + 29u * p[2]) >> 8;
      const unsigned char g = (unsigned char)(40u + luma / 3u);
      q[0] = q[1] = q[2] = g;
    }
    q[3] = 255;
  }
}

static sph_status sph_imgdiff_check_image(const sph_image *img,
                                          const char *which, sph_error *err) {
  if (!img || !img->rgba || img->width <= 0 || img->height <= 0 ||
      img->width > SPH_IMAGE_MAX_SIZE || img->height > SPH_IMAGE_MAX_SIZE)
    return sph_error_set(err, SPH_ERR_ARG, "image %s is empty or oversized",
                         which);
  return SPH_OK;
}

static sph_status sph_imgdiff_check_options(const sph_imgdiff_options *o,
                                            sph_error *err) {
  if (o->channel_tolerance < 0 || o->channel_tolerance > 255)
    return sph_error_set(err, SPH_ERR_RANGE,
                         "channel tolerance %d: must be 0 to 255",
                         o->channel_tolerance);
  if (o->shift < 0 || o->shift > SPH_IMGDIFF_MAX_SHIFT)
    return sph_error_set(err, SPH_ERR_RANGE, "shift %d: must be 0 to %d",
                         o->shift, SPH_IMGDIFF_MAX_SHIFT);
  if (!isfinite(o->max_bad_fraction) || o->max_bad_fraction < 0.0 ||
      o->max_bad_fraction > 1.0)
    return sph_error_set(err, SPH_ERR_RANGE,
                         "maximum bad fraction %g: must be 0 to 1",
                         o->max_bad_fraction);
  if (o->max_cluster < 0)
    return sph_error_set(err, SPH_ERR_RANGE,
                         "maximum cluster %ld: must be 0 or more",
                         o->max_cluster);
  return SPH_OK;
}

sph_status sph_image_diff(const sph_image *a, const sph_image *b,
                          const sph_imgdiff_options *o, sph_imgdiff_result *r,
                          sph_image *diff, sph_error *err) {
  memset(r, 0, sizeof *r);
  if (diff) {
    diff->width = 0;
    diff->height = 0;
    diff->rgba = NULL;
  }
  sph_imgdiff_options defaults;
  if (!o) {
    sph_imgdiff_defaults(&defaults);
    o = &defaults;
  }
  SPH_TRY(sph_imgdiff_check_image(a, "A", err));
  SPH_TRY(sph_imgdiff_check_image(b, "B", err));
  SPH_TRY(sph_imgdiff_check_options(o, err));
  if (a->width != b->width || a->height != b->height)
    return sph_error_set(err, SPH_ERR_ARG,
                         "image sizes differ: %dx%d and %dx%d", a->width,
                         a->height, b->width, b->height);
  const int w = a->width, h = a->height;
  const size_t n = (size_t)w * h;
  unsigned char *mask = calloc(n, 1);
  if (!mask)
    return sph_error_set(err, SPH_ERR_NOMEM,
                         "no memory to compare %dx%d images", w, h);
  /* largest channel difference in place */
  int maxd = 0;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const int d = abs((int)a->rgba[4 * i + c] - (int)b->rgba[4 * i + c]);
      maxd = d > maxd ? d : maxd;
    }
  /* bad pixels: A against B, then B against A */
  sph_imgdiff_mark(a, b, o->channel_tolerance, o->shift, mask);
  sph_imgdiff_mark(b, a, o->channel_tolerance, o->shift, mask);
  long bad = 0;
  for (size_t i = 0; i < n; ++i)
    bad += mask[i] != SPH_IMGDIFF_GOOD;
  /* clusters, then the difference image */
  long largest = 0;
  if (bad > 0) {
    uint32_t *stack = malloc((size_t)bad * sizeof *stack);
    if (!stack) {
      free(mask);
      return sph_error_set(err, SPH_ERR_NOMEM,
                           "no memory to compare %dx%d images", w, h);
    }
    largest = sph_imgdiff_largest_cluster(mask, w, h, stack);
    free(stack);
  }
  if (diff) {
    sph_status st = sph_image_create(diff, w, h, err);
    if (st != SPH_OK) {
      free(mask);
      return st;
    }
    sph_imgdiff_paint(a, mask, diff);
  }
  free(mask);
  r->bad_pixels = bad;
  r->bad_fraction = (double)bad / (double)n;
  r->largest_cluster = largest;
  r->max_channel_diff = maxd;
  r->passed =
      r->bad_fraction <= o->max_bad_fraction && largest <= o->max_cluster;
  return SPH_OK;
}
