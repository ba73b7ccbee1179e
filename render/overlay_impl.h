/* 2-D overlay of rendered frames: colour maps (Moreland's cool-to-warm and
 * viridis), anti-aliased text through FreeType with DejaVu Sans, a vertical
 * colour bar with nice ticks and a label block, all drawn on a plain 8-bit
 * RGBA buffer. Deterministic: the same input gives identical bytes. */
#ifndef SPH_OVERLAY_IMPL_H
#define SPH_OVERLAY_IMPL_H

#include <stddef.h>

#include "sph/status.h"

#include "render/image.h"

/* --- colour maps ------------------------------------------------------------
 */

typedef enum sph_colormap_kind {
  SPH_CMAP_COOL_WARM,
  SPH_CMAP_VIRIDIS
} sph_colormap_kind;

/* t in [0,1] -> sRGB 8-bit; t outside is clamped, NaN gives the NaN colour. */
void sph_colormap_eval(sph_colormap_kind k, double t, unsigned char rgb[3]);
/* Colour for values that are not numbers (yellow for cool-to-warm, red for
 * viridis: neither occurs in its map). */
void sph_colormap_nan(sph_colormap_kind k, unsigned char rgb[3]);
/* n >= 2 evenly spaced samples t = i / (n - 1) into rgb[3 * n], e.g. for a
 * 1-D texture. */
void sph_colormap_table(sph_colormap_kind k, int n, unsigned char *rgb);

/* --- text -------------------------------------------------------------------
 */

#define SPH_DEFAULT_FONT "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"

/* One font face with its own FreeType library instance: any number may exist
 * at once; one object is used by one thread at a time. */
typedef struct sph_text sph_text;

/* Opens font_path (NULL -> SPH_DEFAULT_FONT); SPH_ERR_IO naming the path when
 * the file is missing or not a font. */
sph_status sph_text_create(const char *font_path, sph_text **out,
                           sph_error *err);
void sph_text_destroy(sph_text *t);

/* Pixel height px (the em size, e.g. 16); advance width in pixels of the
 * string (pen travel, kerning included). */
int sph_text_width(sph_text *t, int px, const char *utf8);
/* Font ascent and descent in pixels (both >= 0) at px: a line spans
 * [baseline - ascent, baseline + descent). */
void sph_text_metrics(sph_text *t, int px, int *ascent, int *descent);
/* Ink box of the string drawn with baseline-left at (0, 0): box = {x0, y0,
 * x1, y1}, half-open, y down; all zero for an empty string. */
void sph_text_bounds(sph_text *t, int px, const char *utf8, int box[4]);
/* Draws anti-aliased text (grey-level glyph coverage alpha-blended over the
 * image) with baseline-left at (x, y), clipped to the image. Control
 * characters are skipped; invalid UTF-8 draws U+FFFD. */
void sph_text_draw(sph_text *t, sph_image *img, int x, int y, int px,
                   const char *utf8, const unsigned char rgb[3]);

/* --- colour bar -------------------------------------------------------------
 */

typedef struct sph_colorbar {
  sph_colormap_kind map;
  double min, max;               /* value range drawn */
  const char *title;             /* e.g. "pressure [Pa]"; NULL for none */
  int clamped_low, clamped_high; /* values outside the range exist */
  int x, y, width, height;       /* bar rectangle in pixels */
  int font_px;                   /* 0 -> sph_overlay_font_px(img) */
  unsigned char text_rgb[3];     /* labels, ticks and outline; 0 = black */
} sph_colorbar;

/* Tick labels are formatted in one scheme per bar: fixed notation while every
 * tick magnitude is below 1e5 and the largest is at least 1e-3 (or all are
 * zero), with the decimals the step needs ("0.2", "-1.50"); otherwise
 * engineering form: one shared exponent E, the multiple of three at or
 * below log10(max |tick|), written as "-2e6" or "350e3", mantissa decimals
 * enough to resolve the step, and zero as "0". The bar labels its two ends
 * as well (sph_colorbar_end_label); ticks too near an end give way. */
#define SPH_TICK_LABEL_MAX 32

/* Nice tick values m * 10^k (m = 1, 2 or 5) inside [min, max]: the finest
 * step giving at most max_ticks of them, ascending. min == max (or a range
 * too narrow to label) gives one tick; non-finite input gives none. */
int sph_colorbar_ticks(double min, double max, int max_ticks, double *ticks);
/* Labels of n ascending ticks from sph_colorbar_ticks in the scheme above. */
void sph_colorbar_labels(const double *ticks, int n,
                         char (*labels)[SPH_TICK_LABEL_MAX]);
/* Label of a range end v (lo or hi of the bar's [lo, hi]) to three
 * significant digits of the span, in the ticks' scheme. */
void sph_colorbar_end_label(double v, double lo, double hi,
                            char label[SPH_TICK_LABEL_MAX]);
/* Vertical bar, max at the top and min at the bottom, the map's end colours
 * in the first and last rows of the rectangle. A 1-pixel outline just
 * outside the rectangle, ticks and labels to its right, a triangle above
 * (below) for clamped_high (clamped_low) and the title above it all, kept
 * inside the image. */
void sph_colorbar_draw(sph_image *img, sph_text *t, const sph_colorbar *cb);
/* Pixels sph_colorbar_draw uses right of cb->x for the bar, its ticks and
 * the widest tick label (the title aside): cb->x = width - margin - extent
 * keeps the labels inside the image. */
int sph_colorbar_extent(const sph_image *img, sph_text *t,
                        const sph_colorbar *cb);

/* Default text height for an image: height / 32, within [12, 40]. */
int sph_overlay_font_px(const sph_image *img);
/* Axes triad: the world X, Y, Z directions as seen on screen (dir[k] = the
 * screen x, y (y up) of unit axis k, length <= 1) drawn from (x, y) as red,
 * green and blue segments len pixels long, labelled. */
void sph_overlay_axes(sph_image *img, sph_text *t, int x, int y, int len,
                      const double dir[3][2]);
/* Scale bar from (x, y) rightwards: the length of 1, 2 or 5 x 10^k metres
 * nearest to an eighth of the frame's width at metres_per_px, end ticks,
 * the length written above it. */
void sph_overlay_scale_bar(sph_image *img, sph_text *t, int x, int y,
                           double metres_per_px);
/* Label block with top-left corner (x, y): black text on a translucent white
 * box, one line per '\n', e.g. "twisting_column   t = 0.0250 s". */
void sph_overlay_label(sph_image *img, sph_text *t, int x, int y,
                       const char *text);

#endif
