/* Synthetic images shared by the image tests and the CLI fixtures: a
 * vertical grey gradient with filled discs, which can be shifted, recoloured
 * or lose a disc. */
#ifndef SPH_TEST_IMAGE_UTIL_H
#define SPH_TEST_IMAGE_UTIL_H

#include "render/image.h"

/* Sets one pixel (no bounds check). */
static inline void sph_test_pixel(sph_image *img, int x, int y, int r, int g,
                                  int b, int a) {
  unsigned char *p = img->rgba + 4 * ((size_t)y * img->width + x);
  p[0] = (unsigned char)r;
  p[1] = (unsigned char)g;
  p[2] = (unsigned char)b;
  p[3] = (unsigned char)a;
}

/* Fills the pixels whose centres are within rad of (cx, cy). */
static inline void sph_test_disc(sph_image *img, int cx, int cy, int rad, int r,
                                 int g, int b) {
  for (int y = cy - rad; y <= cy + rad; ++y)
    for (int x = cx - rad; x <= cx + rad; ++x)
      if (x >= 0 && y >= 0 && x < img->width && y < img->height &&
          (x - cx) * (x - cx) + (y - cy) * (y - cy) <= rad * rad)
        sph_test_pixel(img, x, y, r, g, b, 255);
}

/* The test scene: a gradient background (about 0.25 grey levels a row) and
 * four discs, everything moved by (dx, dy). cool != 0 swaps red and blue in
 * the disc colours (another colour map); small != 0 adds a disc of radius 3
 * (29 pixels) at (40 + dx, 200 + dy). */
static inline sph_status sph_test_scene(sph_image *img, int w, int h, int dx,
                                        int dy, int cool, int small,
                                        sph_error *err) {
  sph_status st = sph_image_create(img, w, h, err);
  if (st != SPH_OK)
    return st;
  for (int y = 0; y < h; ++y) {
    int g = 30 + (y * 60) / h;
    for (int x = 0; x < w; ++x)
      sph_test_pixel(img, x, y, g, g, g + 8, 255);
  }
  static const int discs[4][6] = {{80, 80, 30, 220, 60, 40},
                                  {200, 120, 45, 240, 200, 60},
                                  {120, 180, 25, 60, 160, 220},
                                  {260, 60, 15, 230, 120, 90}};
  for (int i = 0; i < 4; ++i) {
    const int *d = discs[i];
    sph_test_disc(img, d[0] + dx, d[1] + dy, d[2], cool ? d[5] : d[3], d[4],
                  cool ? d[3] : d[5]);
  }
  if (small)
    sph_test_disc(img, 40 + dx, 200 + dy, 3, 250, 250, 120);
  return SPH_OK;
}

#endif
