/* Anti-aliased text on an RGBA image through FreeType: hinted glyphs rendered
 * as 8-bit coverage (FT_RENDER_MODE_NORMAL), laid out on whole-pixel
 * advances with the font's kerning, and blended over the image with the
 * coverage as alpha. Each sph_text owns its FreeType library, so several
 * can exist at once; the library never prints. */
#include <stdlib.h>
#include <string.h>

#include <fontconfig/fontconfig.h>
#include <ft2build.h>
#include FT_FREETYPE_H

#include "overlay_impl.h"

struct sph_text {
  FT_Library lib;
  FT_Face face;
  int px; /* pixel size currently set on the face, 0 = none */
};

/* The file fontconfig matches for DejaVu Sans (any sans-serif face when it
 * is missing), into path; 0 when fontconfig finds none. */
static int fontconfig_sans(char *path, size_t size) {
  int found = 0;
  FcConfig *cfg = FcInitLoadConfigAndFonts();
  FcPattern *pat =
      cfg ? FcNameParse((const FcChar8 *)"DejaVu Sans:style=Book") : NULL;
  if (pat && FcConfigSubstitute(cfg, pat, FcMatchPattern)) {
    FcDefaultSubstitute(pat);
    FcResult res;
    FcPattern *match = FcFontMatch(cfg, pat, &res);
    FcChar8 *file = NULL;
    if (match &&
        FcPatternGetString(match, FC_FILE, 0, &file) == FcResultMatch &&
        strlen((const char *)file) < size) {
      strcpy(path, (const char *)file);
      found = 1;
    }
    if (match)
      FcPatternDestroy(match);
  }
  if (pat)
    FcPatternDestroy(pat);
  if (cfg)
    FcConfigDestroy(cfg);
  return found;
}

sph_status sph_text_create(const char *font_path, sph_text **out,
                           sph_error *err) {
  if (!out)
    return sph_error_set(err, SPH_ERR_ARG, "sph_text_create: no output");
  *out = NULL;
  /* the font: as given, else fontconfig's DejaVu Sans, else the path of
   * Debian's fonts-dejavu-core */
  char found[1024];
  const char *path = font_path                              ? font_path
                     : fontconfig_sans(found, sizeof found) ? found
                                                            : SPH_DEFAULT_FONT;
  sph_text *t = calloc(1, sizeof *t);
  if (!t)
    return sph_error_set(err, SPH_ERR_NOMEM, "no memory for the text object");
  FT_Error fe = FT_Init_FreeType(&t->lib);
  if (fe) {
    free(t);
    return sph_error_set(err, SPH_ERR_UNSUPPORTED,
                         "cannot initialise FreeType (error %d)", fe);
  }
  fe = FT_New_Face(t->lib, path, 0, &t->face);
  if (fe) {
    FT_Done_FreeType(t->lib);
    free(t);
    const char *why = "cannot load the font";
    if (fe == FT_Err_Cannot_Open_Resource)
      why = "cannot open the file";
    else if (fe == FT_Err_Unknown_File_Format)
      why = "not a font file";
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "font '%s': %s (FreeType error %d)", path, why, fe);
  }
  /* the face must have a Unicode character map */
  if (FT_Select_Charmap(t->face, FT_ENCODING_UNICODE)) {
    sph_text_destroy(t);
    return sph_error_at(err, SPH_ERR_IO, path, 0, 0, NULL,
                        "font '%s': no Unicode character map", path);
  }
  *out = t;
  return SPH_OK;
}

void sph_text_destroy(sph_text *t) {
  if (!t)
    return;
  if (t->face)
    FT_Done_Face(t->face);
  FT_Done_FreeType(t->lib);
  free(t);
}

static int set_size(sph_text *t, int px) {
  if (px <= 0 || px > 1000)
    return 0;
  if (t->px != px) {
    if (FT_Set_Pixel_Sizes(t->face, 0, (FT_UInt)px))
      return 0;
    t->px = px;
  }
  return 1;
}

/* Next code point of a UTF-8 string; malformed input gives U+FFFD and
 * consumes one byte. */
static unsigned long utf8_next(const unsigned char **ps) {
  const unsigned char *s = *ps;
  unsigned long c = s[0];
  int n = -1;
  if (c < 0x80)
    n = 0;
  else if (c >= 0xC2 && c < 0xE0)
    n = 1;
  else if (c >= 0xE0 && c < 0xF0)
    n = 2;
  else if (c >= 0xF0 && c < 0xF5)
    n = 3;
  if (n < 0) {
    *ps = s + 1;
    return 0xFFFD;
  }
  c &= n == 0 ? 0x7F : (0x3F >> n);
  for (int i = 1; i <= n; ++i) {
    if ((s[i] & 0xC0) != 0x80) {
      *ps = s + 1;
      return 0xFFFD;
    }
    c = (c << 6) | (s[i] & 0x3F);
  }
  /* overlong forms, surrogates and values past U+10FFFF */
  static const unsigned long least[4] = {0, 0x80, 0x800, 0x10000};
  if (c < least[n] || (c >= 0xD800 && c <= 0xDFFF) || c > 0x10FFFF) {
    *ps = s + 1;
    return 0xFFFD;
  }
  *ps = s + n + 1;
  return c;
}

/* Called for each rendered glyph: its bitmap with the top-left corner at
 * (left, top) relative to the baseline-left origin, y down. */
typedef void (*glyph_fn)(void *ctx, const FT_Bitmap *bm, int left, int top);

/* Lays the string out and returns the advance width in pixels; renders each
 * glyph for `fn` when it is given. */
static int layout(sph_text *t, int px, const char *utf8, glyph_fn fn,
                  void *ctx) {
  if (!t || !utf8 || !set_size(t, px))
    return 0;
  FT_Face face = t->face;
  int kerning = FT_HAS_KERNING(face) != 0;
  FT_UInt prev = 0;
  long pen = 0; /* 26.6 fixed point */
  const unsigned char *s = (const unsigned char *)utf8;
  while (*s) {
    unsigned long c = utf8_next(&s);
    /* control characters take no room */
    if (c < 0x20 || (c >= 0x7F && c < 0xA0))
      continue;
    FT_UInt gi = FT_Get_Char_Index(face, c);
    if (kerning && prev && gi) {
      FT_Vector d;
      if (!FT_Get_Kerning(face, prev, gi, FT_KERNING_DEFAULT, &d))
        pen += d.x;
    }
    if (FT_Load_Glyph(face, gi, FT_LOAD_DEFAULT))
      continue;
    FT_GlyphSlot g = face->glyph;
    if (fn && g->format != FT_GLYPH_FORMAT_BITMAP &&
        FT_Render_Glyph(g, FT_RENDER_MODE_NORMAL))
      fn = NULL;
    if (fn && g->bitmap.pixel_mode == FT_PIXEL_MODE_GRAY && g->bitmap.rows)
      fn(ctx, &g->bitmap, (int)((pen + 32) >> 6) + g->bitmap_left,
         -g->bitmap_top);
    pen += g->advance.x;
    prev = gi;
  }
  return (int)((pen + 32) >> 6);
}

int sph_text_width(sph_text *t, int px, const char *utf8) {
  return layout(t, px, utf8, NULL, NULL);
}

void sph_text_metrics(sph_text *t, int px, int *ascent, int *descent) {
  int a = 0, d = 0;
  if (t && set_size(t, px)) {
    const FT_Size_Metrics *m = &t->face->size->metrics;
    a = (int)((m->ascender + 63) >> 6);
    d = (int)((-m->descender + 63) >> 6);
  }
  if (ascent)
    *ascent = a;
  if (descent)
    *descent = d;
}

typedef struct bounds_ctx {
  int box[4], any;
} bounds_ctx;

static void bounds_glyph(void *ctx, const FT_Bitmap *bm, int left, int top) {
  bounds_ctx *b = ctx;
  int x1 = left + (int)bm->width, y1 = top + (int)bm->rows;
  if (bm->width == 0)
    return;
  if (!b->any) {
    b->box[0] = left, b->box[1] = top, b->box[2] = x1, b->box[3] = y1;
    b->any = 1;
    return;
  }
  b->box[0] = left < b->box[0] ? left : b->box[0];
  b->box[1] = top < b->box[1] ? top : b->box[1];
  b->box[2] = x1 > b->box[2] ? x1 : b->box[2];
  b->box[3] = y1 > b->box[3] ? y1 : b->box[3];
}

void sph_text_bounds(sph_text *t, int px, const char *utf8, int box[4]) {
  bounds_ctx b = {{0, 0, 0, 0}, 0};
  layout(t, px, utf8, bounds_glyph, &b);
  memcpy(box, b.box, sizeof b.box);
}

typedef struct draw_ctx {
  sph_image *img;
  int x, y;
  unsigned char rgb[3];
} draw_ctx;

static void draw_glyph(void *ctx, const FT_Bitmap *bm, int left, int top) {
  draw_ctx *d = ctx;
  sph_image *img = d->img;
  int x0 = d->x + left, y0 = d->y + top;
  for (int r = 0; r < (int)bm->rows; ++r) {
    int yy = y0 + r;
    if (yy < 0 || yy >= img->height)
      continue;
    const unsigned char *src = bm->buffer + (long)r * bm->pitch;
    for (int c = 0; c < (int)bm->width; ++c) {
      int xx = x0 + c;
      unsigned a = src[c];
      if (xx < 0 || xx >= img->width || a == 0)
        continue;
      /* "over" with the coverage as alpha, rounded to the nearest level */
      unsigned char *p = img->rgba + 4 * ((size_t)yy * img->width + xx);
      for (int k = 0; k < 3; ++k)
        p[k] = (unsigned char)((d->rgb[k] * a + p[k] * (255 - a) + 127) / 255);
      p[3] = (unsigned char)(a + (p[3] * (255 - a) + 127) / 255);
    }
  }
}

void sph_text_draw(sph_text *t, sph_image *img, int x, int y, int px,
                   const char *utf8, const unsigned char rgb[3]) {
  if (!img || !img->rgba || img->width <= 0 || img->height <= 0)
    return;
  draw_ctx d = {img, x, y, {rgb[0], rgb[1], rgb[2]}};
  layout(t, px, utf8, draw_glyph, &d);
}
