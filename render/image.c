/* RGBA8 images and their PNG files (include/sph/image.h): reading any PNG
 * through libpng's transforms, and deterministic, atomic writing. libpng
 * reports errors by longjmp; each setjmp lives in a helper whose state is in
 * a context record owned by the caller, which frees whatever was allocated
 * whichever way the helper returns. libpng never prints: its error and
 * warning handlers only record the message. */
#include <errno.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/sink.h"
#include "render/image.h"

/* Fixed zlib level and row filter: the same pixels give the same bytes
 * (level 1: a third faster than 6 on rendered frames, 5 % larger files). */
#define SPH_IMAGE_PNG_LEVEL 1
#define SPH_IMAGE_PNG_FILTER PNG_FILTER_SUB

sph_status sph_image_create(sph_image *img, int width, int height,
                            sph_error *err) {
  img->width = 0;
  img->height = 0;
  img->rgba = NULL;
  if (width <= 0 || height <= 0 || width > SPH_IMAGE_MAX_SIZE ||
      height > SPH_IMAGE_MAX_SIZE)
    return sph_error_set(err, SPH_ERR_ARG,
                         "image size %dx%d: width and height must be 1 to %d",
                         width, height, SPH_IMAGE_MAX_SIZE);
  img->rgba = calloc((size_t)width * (size_t)height, 4);
  if (!img->rgba)
    return sph_error_set(err, SPH_ERR_NOMEM, "no memory for a %dx%d image",
                         width, height);
  img->width = width;
  img->height = height;
  return SPH_OK;
}

void sph_image_destroy(sph_image *img) {
  if (!img)
    return;
  free(img->rgba);
  img->rgba = NULL;
  img->width = 0;
  img->height = 0;
}

/* What libpng's callbacks and the setjmp helpers share. */
typedef struct sph_image_png_ctx {
  FILE *f;
  png_structp png;
  png_infop info;
  png_bytep *rows;
  sph_image img;
  int truncated;     /* the file ended early */
  int io_errno;      /* a read or write call failed with this errno */
  int too_large;     /* the header gives a size out of range */
  char message[256]; /* libpng's error text */
} sph_image_png_ctx;

static void sph_image_png_error(png_structp png, png_const_charp msg) {
  sph_image_png_ctx *c = png_get_error_ptr(png);
  snprintf(c->message, sizeof c->message, "%s", msg ? msg : "libpng error");
  png_longjmp(png, 1);
}

static void sph_image_png_warning(png_structp png, png_const_charp msg) {
  (void)png;
  (void)msg;
}

static void sph_image_png_read_fn(png_structp png, png_bytep data,
                                  size_t length) {
  sph_image_png_ctx *c = png_get_io_ptr(png);
  size_t got = fread(data, 1, length, c->f);
  if (got == length)
    return;
  if (ferror(c->f)) {
    c->io_errno = errno ? errno : EIO;
    png_error(png, "read error");
  }
  c->truncated = 1;
  png_error(png, "unexpected end of file");
}

/* The libpng part of reading; returns 0 after a libpng error. */
static int sph_image_png_read_body(sph_image_png_ctx *c) {
  if (setjmp(png_jmpbuf(c->png)))
    return 0;
  png_set_read_fn(c->png, c, sph_image_png_read_fn);
  png_set_sig_bytes(c->png, 8);
  png_read_info(c->png, c->info);
  png_uint_32 w = png_get_image_width(c->png, c->info);
  png_uint_32 h = png_get_image_height(c->png, c->info);
  if (w == 0 || h == 0 || w > SPH_IMAGE_MAX_SIZE || h > SPH_IMAGE_MAX_SIZE) {
    c->too_large = 1;
    snprintf(c->message, sizeof c->message, "image size %lux%lu",
             (unsigned long)w, (unsigned long)h);
    return 0;
  }
  int type = png_get_color_type(c->png, c->info);
  int has_trns = png_get_valid(c->png, c->info, PNG_INFO_tRNS) != 0;
  /* palette and low-bit grey to 8 bits, tRNS to an alpha channel */
  png_set_expand(c->png);
  /* 16-bit channels rounded to 8 bits */
  png_set_scale_16(c->png);
  /* grey to RGB */
  if (!(type & PNG_COLOR_MASK_COLOR))
    png_set_gray_to_rgb(c->png);
  /* opaque alpha where the file has none */
  if (!(type & PNG_COLOR_MASK_ALPHA) && !has_trns)
    png_set_add_alpha(c->png, 0xff, PNG_FILLER_AFTER);
  png_set_interlace_handling(c->png);
  png_read_update_info(c->png, c->info);
  if (png_get_bit_depth(c->png, c->info) != 8 ||
      png_get_channels(c->png, c->info) != 4 ||
      png_get_rowbytes(c->png, c->info) != (size_t)w * 4) {
    snprintf(c->message, sizeof c->message,
             "unexpected layout after conversion to RGBA8");
    return 0;
  }
  /* the image and its row pointers, owned by the context */
  c->img.rgba = malloc((size_t)w * h * 4);
  c->rows = malloc((size_t)h * sizeof *c->rows);
  if (!c->img.rgba || !c->rows) {
    c->io_errno = ENOMEM;
    return 0;
  }
  c->img.width = (int)w;
  c->img.height = (int)h;
  for (png_uint_32 y = 0; y < h; ++y)
    c->rows[y] = c->img.rgba + (size_t)y * w * 4;
  png_read_image(c->png, c->rows);
  /* the rest of the file up to IEND, so a truncated tail is noticed */
  png_read_end(c->png, NULL);
  return 1;
}

sph_status sph_image_read_png(const char *path, sph_image *img,
                              sph_error *err) {
  img->width = 0;
  img->height = 0;
  img->rgba = NULL;
  sph_image_png_ctx c;
  memset(&c, 0, sizeof c);
  c.f = fopen(path, "rb");
  if (!c.f)
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "cannot open the image: %s", strerror(errno));
  /* the signature first, for a clear "not a PNG" */
  unsigned char sig[8];
  size_t n = fread(sig, 1, sizeof sig, c.f);
  sph_status st = SPH_OK;
  if (n < sizeof sig && ferror(c.f))
    st = sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                      "cannot read the image: %s", strerror(errno));
  else if (n > 0 && png_sig_cmp(sig, 0, n) != 0)
    st = sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                      "not a PNG file (wrong signature)");
  else if (n == 0)
    st = sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                      "not a PNG file (empty)");
  else if (n < sizeof sig)
    st = sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                      "truncated PNG file (ends inside the signature)");
  if (st != SPH_OK) {
    fclose(c.f);
    return st;
  }
  /* libpng's structures, then the body under setjmp */
  c.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &c, sph_image_png_error,
                                 sph_image_png_warning);
  if (c.png)
    c.info = png_create_info_struct(c.png);
  int ok = 0;
  if (!c.png || !c.info)
    c.io_errno = ENOMEM;
  else
    ok = sph_image_png_read_body(&c);
  png_destroy_read_struct(&c.png, &c.info, NULL);
  free(c.rows);
  fclose(c.f);
  if (ok) {
    *img = c.img;
    return SPH_OK;
  }
  free(c.img.rgba);
  /* the reason, most specific first */
  if (c.io_errno == ENOMEM)
    return sph_error_at(err, SPH_ERR_NOMEM, path, 0, 0, NULL,
                        "no memory to read the image");
  if (c.io_errno)
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "cannot read the image: %s", strerror(c.io_errno));
  if (c.truncated)
    return sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                        "truncated PNG file (unexpected end of file)");
  if (c.too_large)
    return sph_error_at(err, SPH_ERR_RANGE, path, 0, 0, NULL,
                        "%s: width and height must be 1 to %d", c.message,
                        SPH_IMAGE_MAX_SIZE);
  return sph_error_at(err, SPH_ERR_SYNTAX, path, 0, 0, NULL,
                      "corrupt PNG file: %s", c.message);
}

static void sph_image_png_write_fn(png_structp png, png_bytep data,
                                   size_t length) {
  sph_image_png_ctx *c = png_get_io_ptr(png);
  if (fwrite(data, 1, length, c->f) != length) {
    c->io_errno = errno ? errno : EIO;
    png_error(png, "write error");
  }
}

static void sph_image_png_flush_fn(png_structp png) { (void)png; }

/* The libpng part of writing; returns 0 after a libpng error. */
static int sph_image_png_write_body(sph_image_png_ctx *c, const sph_image *img,
                                    int opaque) {
  if (setjmp(png_jmpbuf(c->png)))
    return 0;
  png_set_write_fn(c->png, c, sph_image_png_write_fn, sph_image_png_flush_fn);
  png_set_compression_level(c->png, SPH_IMAGE_PNG_LEVEL);
  png_set_filter(c->png, PNG_FILTER_TYPE_BASE, SPH_IMAGE_PNG_FILTER);
  png_set_IHDR(
      c->png, c->info, (png_uint_32)img->width, (png_uint_32)img->height, 8,
      opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE,
      PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  png_write_info(c->png, c->info);
  /* RGB files: libpng drops the fourth byte of each pixel */
  if (opaque)
    png_set_filler(c->png, 0, PNG_FILLER_AFTER);
  png_write_image(c->png, c->rows);
  png_write_end(c->png, NULL);
  return 1;
}

sph_status sph_image_write_png(const char *path, const sph_image *img,
                               sph_error *err) {
  if (!img || !img->rgba || img->width <= 0 || img->height <= 0 ||
      img->width > SPH_IMAGE_MAX_SIZE || img->height > SPH_IMAGE_MAX_SIZE)
    return sph_error_at(err, SPH_ERR_ARG, path, 0, 0, NULL,
                        "cannot write an empty or oversized image");
  /* RGB when every pixel is opaque */
  size_t npix = (size_t)img->width * (size_t)img->height;
  int opaque = 1;
  for (size_t i = 0; i < npix && opaque; ++i)
    opaque = img->rgba[4 * i + 3] == 255;
  sph_image_png_ctx c;
  memset(&c, 0, sizeof c);
  c.rows = malloc((size_t)img->height * sizeof *c.rows);
  if (!c.rows)
    return sph_error_at(err, SPH_ERR_NOMEM, path, 0, 0, NULL,
                        "no memory to write the image");
  for (int y = 0; y < img->height; ++y)
    c.rows[y] = img->rgba + (size_t)y * (size_t)img->width * 4;
  sph_atomic_file af;
  sph_status st = sph_atomic_open(&af, path, err);
  if (st != SPH_OK) {
    free(c.rows);
    return st;
  }
  c.f = af.f;
  c.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &c,
                                  sph_image_png_error, sph_image_png_warning);
  if (c.png)
    c.info = png_create_info_struct(c.png);
  int ok = 0;
  if (!c.png || !c.info)
    c.io_errno = ENOMEM;
  else
    ok = sph_image_png_write_body(&c, img, opaque);
  png_destroy_write_struct(&c.png, &c.info);
  free(c.rows);
  if (ok)
    return sph_atomic_commit(&af, err);
  sph_atomic_abort(&af);
  if (c.io_errno == ENOMEM)
    return sph_error_at(err, SPH_ERR_NOMEM, path, 0, 0, NULL,
                        "no memory to write the image");
  if (c.io_errno)
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "cannot write the image: %s", strerror(c.io_errno));
  return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                      "cannot write the image: libpng: %s", c.message);
}
