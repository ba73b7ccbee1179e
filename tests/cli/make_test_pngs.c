/* Writes the synthetic PNGs the imgdiff command-line test compares (see
 * tests/unit/test_image_util.h): usage make_test_pngs DIR. */
#include <stdio.h>

#include "render/image.h"
#include "test_image_util.h"

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: make_test_pngs DIR\n");
    return 2;
  }
  /* name, width, dx, dy, other colour map, small disc */
  static const struct {
    const char *name;
    int w, dx, dy, cool, small;
  } files[] = {{"a.png", 320, 0, 0, 0, 0},      {"a_copy.png", 320, 0, 0, 0, 0},
               {"shift1.png", 320, 1, 1, 0, 0}, {"shift3.png", 320, 3, 0, 0, 0},
               {"cool.png", 320, 0, 0, 1, 0},   {"small.png", 320, 0, 0, 0, 1},
               {"wide.png", 321, 0, 0, 0, 0}};
  for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", argv[1], files[i].name);
    sph_image img;
    sph_error err;
    sph_status st =
        sph_test_scene(&img, files[i].w, 240, files[i].dx, files[i].dy,
                       files[i].cool, files[i].small, &err);
    if (st == SPH_OK)
      st = sph_image_write_png(path, &img, &err);
    sph_image_destroy(&img);
    if (st != SPH_OK) {
      char msg[1200];
      sph_error_format(&err, msg, sizeof msg);
      fprintf(stderr, "make_test_pngs: %s\n", msg);
      return 1;
    }
  }
  return 0;
}
