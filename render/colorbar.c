/* Colour bar with nice ticks (1, 2, 5 x 10^k, the classic "nice numbers" of
 * axis labelling), end triangles for clamped values, and the label block of
 * a frame; drawn with sph_text on an RGBA image. Edges of the triangles are
 * anti-aliased by 4 x 4 supersampling of their signed edge distances. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "overlay_impl.h"

/* m * 10^k with the fewest roundings: i * m / 10^-k for negative k */
static double nice_value(double i, int m, int k) {
  double v = k >= 0 ? i * m * pow(10.0, k) : i * m / pow(10.0, -k);
  return v == 0.0 ? 0.0 : v;
}

int sph_colorbar_ticks(double min, double max, int max_ticks, double *ticks) {
  if (max_ticks < 1 || !ticks || !isfinite(min) || !isfinite(max))
    return 0;
  if (min > max) {
    double s = min;
    min = max, max = s;
  }
  double span = max - min, mag = fmax(fabs(min), fabs(max));
  /* a point, or a range narrower than a label could resolve: one tick */
  if (!(span > 1e-12 * mag) || !(span > 1e-300) || !isfinite(span)) {
    ticks[0] = 0.5 * min + 0.5 * max;
    return 1;
  }
  static const int mult[3] = {1, 2, 5};
  int k = (int)floor(log10(span / max_ticks)) - 1;
  double prev_lo = 0.0, prev_hi = -1.0;
  int prev_m = 1, prev_k = k;
  for (int iter = 0; iter < 64; ++iter, ++k)
    for (int j = 0; j < 3; ++j) {
      /* multiples of the step inside [min, max], ends within 1e-9 steps */
      double s = nice_value(1.0, mult[j], k);
      double lo = ceil(min / s - 1e-9), hi = floor(max / s + 1e-9);
      if (hi - lo + 1.0 > max_ticks) {
        prev_lo = lo, prev_hi = hi, prev_m = mult[j], prev_k = k;
        continue;
      }
      if (hi >= lo) {
        int n = (int)(hi - lo + 1.0);
        for (int i = 0; i < n; ++i)
          ticks[i] = nice_value(lo + i, mult[j], k);
        return n;
      }
      /* only for max_ticks == 1: no multiple left, keep the previous step's
       * tick nearest the middle */
      double mid = 0.5 * min + 0.5 * max, best = prev_lo;
      for (double i = prev_lo + 1.0; i <= prev_hi; i += 1.0)
        if (fabs(nice_value(i, prev_m, prev_k) - mid) <
            fabs(nice_value(best, prev_m, prev_k) - mid))
          best = i;
      ticks[0] = nice_value(best, prev_m, prev_k);
      return 1;
    }
  return 0;
}

/* floor(log10(v)) for v > 0, exact at powers of ten; a span that
 * overflows (a range of -1e308 .. 1e308) counts as DBL_MAX's, and 0 or NaN
 * as 1's (no int conversion of an infinity) */
static int decade(double v) {
  if (!(v > 0.0))
    return 0;
  v = fmin(v, DBL_MAX);
  int e = (int)floor(log10(v));
  if (pow(10.0, e + 1) <= v)
    e++;
  else if (pow(10.0, e) > v)
    e--;
  return e;
}

void sph_colorbar_labels(const double *ticks, int n,
                         char (*labels)[SPH_TICK_LABEL_MAX]) {
  if (n <= 0 || !ticks || !labels)
    return;
  double maxabs = 0.0;
  for (int i = 0; i < n; ++i)
    maxabs = fmax(maxabs, fabs(ticks[i]));
  /* the step's decade sets the digits; a lone tick gets four significant */
  int k = 0;
  if (n >= 2 && ticks[1] > ticks[0])
    k = decade(ticks[1] - ticks[0]);
  else if (maxabs > 0.0)
    k = decade(maxabs) - 3;
  if (maxabs == 0.0 || (maxabs >= 1e-3 && maxabs < 1e5)) {
    int d = k < 0 ? -k : 0;
    d = d > 15 ? 15 : d;
    for (int i = 0; i < n; ++i)
      snprintf(labels[i], SPH_TICK_LABEL_MAX, "%.*f", d,
               ticks[i] == 0.0 ? 0.0 : ticks[i]);
    return;
  }
  /* engineering form: an exponent that is a multiple of three, so the
   * mantissas read 1 to 999 ("50e3", "-2.5e6"), never "0.5e7" */
  int e = decade(maxabs);
  int E = 3 * (int)floor(e / 3.0);
  int d = E - k < 0 ? 0 : (E - k > 15 ? 15 : E - k);
  double scale = pow(10.0, E);
  for (int i = 0; i < n; ++i) {
    if (ticks[i] == 0.0)
      snprintf(labels[i], SPH_TICK_LABEL_MAX, "0");
    else
      snprintf(labels[i], SPH_TICK_LABEL_MAX, "%.*fe%d", d, ticks[i] / scale,
               E);
  }
}

void sph_colorbar_end_label(double v, double lo, double hi,
                            char label[SPH_TICK_LABEL_MAX]) {
  /* three significant digits of the span, in the ticks' scheme (chosen by
   * the larger end) */
  double ref = fmax(fabs(lo), fabs(hi)), span = hi - lo;
  if (v == 0.0 || !isfinite(v) || !(ref > 0.0)) {
    snprintf(label, SPH_TICK_LABEL_MAX, "%s", isfinite(v) ? "0" : "nan");
    return;
  }
  int k = span > 0.0 ? decade(span) - 2 : decade(ref) - 2;
  if (ref >= 1e-3 && ref < 1e5) {
    int d = k < 0 ? (-k > 15 ? 15 : -k) : 0;
    snprintf(label, SPH_TICK_LABEL_MAX, "%.*f", d, v);
    return;
  }
  int E = 3 * (int)floor(decade(ref) / 3.0);
  int d = E - k < 0 ? 0 : (E - k > 15 ? 15 : E - k);
  snprintf(label, SPH_TICK_LABEL_MAX, "%.*fe%d", d, v / pow(10.0, E), E);
}

int sph_overlay_font_px(const sph_image *img) {
  int px = img ? img->height / 32 : 12;
  return px < 12 ? 12 : (px > 40 ? 40 : px);
}

/* Blends rgb over pixel (x, y) with alpha a in [0, 255]; clipped. */
static void blend(sph_image *img, int x, int y, const unsigned char rgb[3],
                  unsigned a) {
  if (x < 0 || y < 0 || x >= img->width || y >= img->height || a == 0)
    return;
  unsigned char *p = img->rgba + 4 * ((size_t)y * img->width + x);
  for (int k = 0; k < 3; ++k)
    p[k] = (unsigned char)((rgb[k] * a + p[k] * (255 - a) + 127) / 255);
  p[3] = (unsigned char)(a + (p[3] * (255 - a) + 127) / 255);
}

/* Rectangle [x0, x1) x [y0, y1) blended with alpha a, clipped. */
static void blend_rect(sph_image *img, int x0, int y0, int x1, int y1,
                       const unsigned char rgb[3], unsigned a) {
  x0 = x0 < 0 ? 0 : x0, y0 = y0 < 0 ? 0 : y0;
  x1 = x1 > img->width ? img->width : x1;
  y1 = y1 > img->height ? img->height : y1;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      blend(img, x, y, rgb, a);
}

static void fill_rect(sph_image *img, int x0, int y0, int x1, int y1,
                      const unsigned char rgb[3]) {
  blend_rect(img, x0, y0, x1, y1, rgb, 255);
}

/* Triangle a, b, c (pixel-edge coordinates): the outline colour where a
 * sample lies inside, the fill where it lies at least one pixel inside. */
static void triangle(sph_image *img, const double v[3][2],
                     const unsigned char outline[3],
                     const unsigned char fill[3]) {
  double n[3][3]; /* inward unit normal and offset of each edge */
  double cx = (v[0][0] + v[1][0] + v[2][0]) / 3.0;
  double cy = (v[0][1] + v[1][1] + v[2][1]) / 3.0;
  for (int e = 0; e < 3; ++e) {
    const double *p = v[e], *q = v[(e + 1) % 3];
    double nx = -(q[1] - p[1]), ny = q[0] - p[0], len = hypot(nx, ny);
    nx /= len, ny /= len;
    double s = nx * (cx - p[0]) + ny * (cy - p[1]) < 0.0 ? -1.0 : 1.0;
    n[e][0] = s * nx, n[e][1] = s * ny;
    n[e][2] = -(n[e][0] * p[0] + n[e][1] * p[1]);
  }
  int x0 = (int)floor(fmin(fmin(v[0][0], v[1][0]), v[2][0]));
  int x1 = (int)ceil(fmax(fmax(v[0][0], v[1][0]), v[2][0]));
  int y0 = (int)floor(fmin(fmin(v[0][1], v[1][1]), v[2][1]));
  int y1 = (int)ceil(fmax(fmax(v[0][1], v[1][1]), v[2][1]));
  x0 = x0 < 0 ? 0 : x0, y0 = y0 < 0 ? 0 : y0;
  x1 = x1 > img->width ? img->width : x1;
  y1 = y1 > img->height ? img->height : y1;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      /* 4 x 4 samples: inside the outline, inside the fill */
      int in_out = 0, in_fill = 0;
      for (int sy = 0; sy < 4; ++sy)
        for (int sx = 0; sx < 4; ++sx) {
          double px = x + (sx + 0.5) / 4.0, py = y + (sy + 0.5) / 4.0;
          double dmin = INFINITY;
          for (int e = 0; e < 3; ++e)
            dmin = fmin(dmin, n[e][0] * px + n[e][1] * py + n[e][2]);
          in_out += dmin >= 0.0;
          in_fill += dmin >= 1.0;
        }
      blend(img, x, y, outline, (unsigned)(in_out * 255 + 8) / 16);
      blend(img, x, y, fill, (unsigned)(in_fill * 255 + 8) / 16);
    }
}

/* Ticks and labels of a bar, the tick length and the labels' offset from
 * the bar's left edge. */
typedef struct bar_layout {
  int px, n, tick_len, label_dx;
  double ticks[13];
  char labels[13][SPH_TICK_LABEL_MAX];
} bar_layout;

static void layout(const sph_image *img, const sph_colorbar *cb,
                   bar_layout *l) {
  l->px = cb->font_px > 0 ? cb->font_px : sph_overlay_font_px(img);
  int max_ticks = (int)(cb->height / (2.2 * l->px));
  max_ticks = max_ticks < 2 ? 2 : (max_ticks > 11 ? 11 : max_ticks);
  int n = sph_colorbar_ticks(cb->min, cb->max, max_ticks, l->ticks);
  sph_colorbar_labels(l->ticks, n, l->labels);
  /* the range's ends labelled at the bar's ends; ticks within a label's
   * height of an end give way */
  double lo = fmin(cb->min, cb->max), hi = fmax(cb->min, cb->max);
  double room = hi > lo ? 1.2 * l->px * (hi - lo) / cb->height : 0.0;
  int m = 0;
  for (int i = 0; i < n; ++i)
    if (!(hi > lo) || (l->ticks[i] - lo > room && hi - l->ticks[i] > room)) {
      l->ticks[m] = l->ticks[i];
      memmove(l->labels[m], l->labels[i], SPH_TICK_LABEL_MAX);
      ++m;
    }
  if (hi > lo) {
    l->ticks[m] = lo;
    sph_colorbar_end_label(lo, lo, hi, l->labels[m++]);
    l->ticks[m] = hi;
    sph_colorbar_end_label(hi, lo, hi, l->labels[m++]);
  }
  l->n = m;
  l->tick_len = l->px / 3 < 3 ? 3 : l->px / 3;
  l->label_dx = cb->width + 1 + l->tick_len + (l->px / 4 < 2 ? 2 : l->px / 4);
}

int sph_colorbar_extent(const sph_image *img, sph_text *t,
                        const sph_colorbar *cb) {
  if (!img || !cb || cb->width <= 0 || cb->height <= 0)
    return 0;
  bar_layout l;
  layout(img, cb, &l);
  int right = cb->width + 1;
  for (int i = 0; i < l.n; ++i) {
    int lw = sph_text_width(t, l.px, l.labels[i]);
    right = l.label_dx + lw > right ? l.label_dx + lw : right;
  }
  return right;
}

void sph_colorbar_draw(sph_image *img, sph_text *t, const sph_colorbar *cb) {
  if (!img || !img->rgba || !cb || cb->width <= 0 || cb->height <= 0)
    return;
  bar_layout l;
  layout(img, cb, &l);
  int px = l.px, n = l.n, tick_len = l.tick_len;
  const double *ticks = l.ticks;
  const unsigned char *fg = cb->text_rgb;
  int x = cb->x, y = cb->y, w = cb->width, h = cb->height;
  unsigned char rgb[3], end_hi[3], end_lo[3];
  /* the bar: max in the first row, min in the last */
  for (int r = 0; r < h; ++r) {
    sph_colormap_eval(cb->map, h > 1 ? (double)(h - 1 - r) / (h - 1) : 0.5,
                      rgb);
    fill_rect(img, x, y + r, x + w, y + r + 1, rgb);
  }
  sph_colormap_eval(cb->map, 1.0, end_hi);
  sph_colormap_eval(cb->map, 0.0, end_lo);
  /* end triangles for values beyond the range, as tall as the bar is wide */
  double th = fmax(4.0, 0.9 * w);
  if (cb->clamped_high) {
    double v[3][2] = {
        {x - 1.0, y}, {x + w + 1.0, y}, {x + 0.5 * w, y - 1.0 - th}};
    triangle(img, v, fg, end_hi);
  }
  if (cb->clamped_low) {
    double v[3][2] = {{x - 1.0, y + h},
                      {x + w + 1.0, y + h},
                      {x + 0.5 * w, y + h + 1.0 + th}};
    triangle(img, v, fg, end_lo);
  }
  /* outline just outside the rectangle */
  fill_rect(img, x - 1, y - 1, x + w + 1, y, fg);
  fill_rect(img, x - 1, y + h, x + w + 1, y + h + 1, fg);
  fill_rect(img, x - 1, y, x, y + h, fg);
  fill_rect(img, x + w, y, x + w + 1, y + h, fg);
  /* ticks at the value rows, labels centred on them by the digit height */
  int lx = x + l.label_dx;
  int digit[4];
  sph_text_bounds(t, px, "0", digit);
  int right = x + w + 1;
  double lo = fmin(cb->min, cb->max), hi = fmax(cb->min, cb->max);
  for (int i = 0; i < n; ++i) {
    double f = hi > lo ? (hi - ticks[i]) / (hi - lo) : 0.5;
    int r = y + (int)floor(f * (h - 1) + 0.5);
    fill_rect(img, x + w + 1, r, x + w + 1 + tick_len, r + 1, fg);
    int base = r + (1 - digit[1] - digit[3]) / 2;
    sph_text_draw(t, img, lx, base, px, l.labels[i], fg);
    int lw = sph_text_width(t, px, l.labels[i]);
    right = lx + lw > right ? lx + lw : right;
  }
  /* title centred over bar and labels, above the triangle, inside the image */
  if (cb->title && cb->title[0]) {
    int box[4];
    sph_text_bounds(t, px, cb->title, box);
    int tw = sph_text_width(t, px, cb->title);
    int tx = (x - 1 + right - tw) / 2;
    if (tx + tw > img->width - 2)
      tx = img->width - 2 - tw;
    if (tx < 2)
      tx = 2;
    int top = y - 1 - (cb->clamped_high ? (int)ceil(th) + 1 : 0);
    int gap = px / 2 < 4 ? 4 : px / 2;
    sph_text_draw(t, img, tx, top - gap - box[3], px, cb->title, fg);
  }
}

void sph_overlay_label(sph_image *img, sph_text *t, int x, int y,
                       const char *text) {
  if (!img || !img->rgba || !t || !text || !text[0])
    return;
  char *copy = strdup(text);
  if (!copy)
    return;
  int px = sph_overlay_font_px(img), asc, desc;
  sph_text_metrics(t, px, &asc, &desc);
  int line_h = asc + desc, pad = px / 3 < 3 ? 3 : px / 3;
  /* split into lines and measure the widest */
  int lines = 1, wmax = 0;
  for (char *c = copy; *c; ++c)
    if (*c == '\n')
      *c = '\0', lines++;
  const char *s = copy;
  for (int i = 0; i < lines; s += strlen(s) + 1, ++i) {
    int lw = sph_text_width(t, px, s);
    wmax = lw > wmax ? lw : wmax;
  }
  /* translucent white box, then the lines in black */
  static const unsigned char white[3] = {255, 255, 255}, black[3] = {0, 0, 0};
  blend_rect(img, x, y, x + wmax + 2 * pad, y + lines * line_h + 2 * pad, white,
             200);
  s = copy;
  for (int i = 0; i < lines; s += strlen(s) + 1, ++i)
    sph_text_draw(t, img, x + pad, y + pad + asc + i * line_h, px, s, black);
  free(copy);
}

void sph_overlay_axes(sph_image *img, sph_text *t, int x, int y, int len,
                      const double dir[3][2]) {
  if (!img || !img->rgba || len <= 0)
    return;
  static const unsigned char rgb[3][3] = {
      {200, 40, 40}, {40, 150, 40}, {40, 70, 200}};
  static const char *const name[3] = {"X", "Y", "Z"};
  int px = sph_overlay_font_px(img);
  for (int k = 0; k < 3; ++k) {
    double dx = dir[k][0], dy = dir[k][1];
    double l = sqrt(dx * dx + dy * dy);
    /* 2 px wide, drawn by samples along the segment */
    int steps = (int)ceil(2.0 * len * l) + 1;
    for (int i = 0; i <= steps; ++i) {
      double f = (double)i / steps;
      int cx = (int)floor(x + f * len * dx + 0.5);
      int cy = (int)floor(y - f * len * dy + 0.5);
      fill_rect(img, cx - 1, cy - 1, cx + 1, cy + 1, rgb[k]);
    }
    if (t && l > 0.2) /* a label where the axis is not seen end-on */
      sph_text_draw(t, img, (int)(x + 1.15 * len * dx) - px / 4,
                    (int)(y - 1.15 * len * dy) + px / 3, px * 3 / 4, name[k],
                    rgb[k]);
  }
}

void sph_overlay_scale_bar(sph_image *img, sph_text *t, int x, int y,
                           double metres_per_px) {
  if (!img || !img->rgba || !(metres_per_px > 0.0) || !isfinite(metres_per_px))
    return;
  /* the nice length nearest to an eighth of the frame's width */
  double want = img->width / 8.0 * metres_per_px, best = 0.0;
  int k = (int)floor(log10(want));
  static const int mult[3] = {1, 2, 5};
  for (int e = k - 1; e <= k + 1; ++e)
    for (int j = 0; j < 3; ++j) {
      double v = mult[j] * pow(10.0, e);
      if (best == 0.0 || fabs(log(v / want)) < fabs(log(best / want)))
        best = v;
    }
  int len = (int)floor(best / metres_per_px + 0.5);
  static const unsigned char black[3] = {0, 0, 0};
  fill_rect(img, x, y - 1, x + len, y + 2, black);
  fill_rect(img, x, y - 6, x + 2, y + 2, black);
  fill_rect(img, x + len - 2, y - 6, x + len, y + 2, black);
  if (t) {
    char label[32];
    snprintf(label, sizeof label, "%g m", best);
    int px = sph_overlay_font_px(img) * 3 / 4;
    int w = sph_text_width(t, px, label);
    sph_text_draw(t, img, x + (len - w) / 2, y - 9, px, label, black);
  }
}
