/* Colour maps for the overlay and the renderer.
 *
 * Cool to warm: the diverging map of K. Moreland, "Diverging Color Maps for
 * Scientific Visualization", ISVC 2009, computed from its definition: the end
 * points sRGB (59, 76, 192) and (180, 4, 38) are converted to CIELAB (D65)
 * and to the polar Msh space (M = |Lab|, s = acos(L / M), h = atan2(b, a)),
 * the path passes through the unsaturated white point M = max(M1, M2, 88)
 * with the hue of the saturated end adjusted as in the paper, and M, s, h
 * are interpolated linearly.
 *
 * Viridis: every third of the 256 entries (0, 3, ..., 255) of _viridis_data
 * in mpl-colormaps by N. J. Smith, S. van der Walt and E. Firing
 * (https://github.com/BIDS/colormap, CC0), interpolated linearly; the
 * deviation from the full table is below 0.25 of an 8-bit step. */
#include <math.h>

#include "overlay_impl.h"

static const double viridis[][3] = {
    {0.267004, 0.004874, 0.329415}, {0.271305, 0.019942, 0.347269},
    {0.274952, 0.037752, 0.364543}, {0.277941, 0.056324, 0.381191},
    {0.280267, 0.073417, 0.397163}, {0.281924, 0.089666, 0.412415},
    {0.282910, 0.105393, 0.426902}, {0.283229, 0.120777, 0.440584},
    {0.282884, 0.135920, 0.453427}, {0.281887, 0.150881, 0.465405},
    {0.280255, 0.165693, 0.476498}, {0.278012, 0.180367, 0.486697},
    {0.275191, 0.194905, 0.496005}, {0.271828, 0.209303, 0.504434},
    {0.267968, 0.223549, 0.512008}, {0.263663, 0.237631, 0.518762},
    {0.258965, 0.251537, 0.524736}, {0.253935, 0.265254, 0.529983},
    {0.248629, 0.278775, 0.534556}, {0.243113, 0.292092, 0.538516},
    {0.237441, 0.305202, 0.541921}, {0.231674, 0.318106, 0.544834},
    {0.225863, 0.330805, 0.547314}, {0.220057, 0.343307, 0.549413},
    {0.214298, 0.355619, 0.551184}, {0.208623, 0.367752, 0.552675},
    {0.203063, 0.379716, 0.553925}, {0.197636, 0.391528, 0.554969},
    {0.192357, 0.403199, 0.555836}, {0.187231, 0.414746, 0.556547},
    {0.182256, 0.426184, 0.557120}, {0.177423, 0.437527, 0.557565},
    {0.172719, 0.448791, 0.557885}, {0.168126, 0.459988, 0.558082},
    {0.163625, 0.471133, 0.558148}, {0.159194, 0.482237, 0.558073},
    {0.154815, 0.493313, 0.557840}, {0.150476, 0.504369, 0.557430},
    {0.146180, 0.515413, 0.556823}, {0.141935, 0.526453, 0.555991},
    {0.137770, 0.537492, 0.554906}, {0.133743, 0.548535, 0.553541},
    {0.129933, 0.559582, 0.551864}, {0.126453, 0.570633, 0.549841},
    {0.123463, 0.581687, 0.547445}, {0.121148, 0.592739, 0.544641},
    {0.119738, 0.603785, 0.541400}, {0.119483, 0.614817, 0.537692},
    {0.120638, 0.625828, 0.533488}, {0.123444, 0.636809, 0.528763},
    {0.128087, 0.647749, 0.523491}, {0.134692, 0.658636, 0.517649},
    {0.143303, 0.669459, 0.511215}, {0.153894, 0.680203, 0.504172},
    {0.166383, 0.690856, 0.496502}, {0.180653, 0.701402, 0.488189},
    {0.196571, 0.711827, 0.479221}, {0.214000, 0.722114, 0.469588},
    {0.232815, 0.732247, 0.459277}, {0.252899, 0.742211, 0.448284},
    {0.274149, 0.751988, 0.436601}, {0.296479, 0.761561, 0.424223},
    {0.319809, 0.770914, 0.411152}, {0.344074, 0.780029, 0.397381},
    {0.369214, 0.788888, 0.382914}, {0.395174, 0.797475, 0.367757},
    {0.421908, 0.805774, 0.351910}, {0.449368, 0.813768, 0.335384},
    {0.477504, 0.821444, 0.318195}, {0.506271, 0.828786, 0.300362},
    {0.535621, 0.835785, 0.281908}, {0.565498, 0.842430, 0.262877},
    {0.595839, 0.848717, 0.243329}, {0.626579, 0.854645, 0.223353},
    {0.657642, 0.860219, 0.203082}, {0.688944, 0.865448, 0.182725},
    {0.720391, 0.870350, 0.162603}, {0.751884, 0.874951, 0.143228},
    {0.783315, 0.879285, 0.125405}, {0.814576, 0.883393, 0.110347},
    {0.845561, 0.887322, 0.099702}, {0.876168, 0.891125, 0.095250},
    {0.906311, 0.894855, 0.098125}, {0.935904, 0.898570, 0.108131},
    {0.964894, 0.902323, 0.123941}, {0.993248, 0.906157, 0.143936},
};
enum { VIRIDIS_N = sizeof viridis / sizeof viridis[0] };

/* sRGB primaries to XYZ (IEC 61966-2-1) and back; white is the row sums. */
static const double rgb2xyz[3][3] = {{0.4124564, 0.3575761, 0.1804375},
                                     {0.2126729, 0.7151522, 0.0721750},
                                     {0.0193339, 0.1191920, 0.9503041}};
static const double xyz2rgb[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                                     {-0.9692660, 1.8760108, 0.0415560},
                                     {0.0556434, -0.2040259, 1.0572252}};

static double white(int i) {
  return rgb2xyz[i][0] + rgb2xyz[i][1] + rgb2xyz[i][2];
}

static double srgb_to_linear(double c) {
  return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static double linear_to_srgb(double c) {
  return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

static unsigned char to_byte(double c) {
  /* clamp to [0, 1] and round to the nearest 8-bit level */
  if (!(c > 0.0))
    return 0;
  if (c >= 1.0)
    return 255;
  return (unsigned char)floor(c * 255.0 + 0.5);
}

static double lab_f(double t) {
  const double d = 6.0 / 29.0;
  return t > d * d * d ? cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
}

static double lab_finv(double f) {
  const double d = 6.0 / 29.0;
  return f > d ? f * f * f : 3.0 * d * d * (f - 4.0 / 29.0);
}

/* 8-bit sRGB -> Msh */
static void rgb_to_msh(const unsigned char rgb[3], double msh[3]) {
  double lin[3], xyz[3], f[3];
  for (int i = 0; i < 3; ++i)
    lin[i] = srgb_to_linear(rgb[i] / 255.0);
  for (int i = 0; i < 3; ++i) {
    xyz[i] = rgb2xyz[i][0] * lin[0] + rgb2xyz[i][1] * lin[1] +
             rgb2xyz[i][2] * lin[2];
    f[i] = lab_f(xyz[i] / white(i));
  }
  double L = 116.0 * f[1] - 16.0;
  double a = 500.0 * (f[0] - f[1]);
  double b = 200.0 * (f[1] - f[2]);
  double M = sqrt(L * L + a * a + b * b);
  double c = M > 0.0 ? L / M : 1.0;
  msh[0] = M;
  msh[1] = acos(c > 1.0 ? 1.0 : (c < -1.0 ? -1.0 : c));
  msh[2] = atan2(b, a);
}

/* Msh -> 8-bit sRGB, out-of-gamut channels clamped */
static void msh_to_rgb(const double msh[3], unsigned char rgb[3]) {
  double L = msh[0] * cos(msh[1]);
  double a = msh[0] * sin(msh[1]) * cos(msh[2]);
  double b = msh[0] * sin(msh[1]) * sin(msh[2]);
  double fy = (L + 16.0) / 116.0;
  double f[3] = {fy + a / 500.0, fy, fy - b / 200.0};
  double xyz[3];
  for (int i = 0; i < 3; ++i)
    xyz[i] = lab_finv(f[i]) * white(i);
  for (int i = 0; i < 3; ++i) {
    double lin = xyz2rgb[i][0] * xyz[0] + xyz2rgb[i][1] * xyz[1] +
                 xyz2rgb[i][2] * xyz[2];
    rgb[i] = to_byte(linear_to_srgb(lin < 0.0 ? 0.0 : lin));
  }
}

/* Hue for the unsaturated end so that the path keeps turning smoothly. */
static double adjust_hue(const double sat[3], double m_unsat) {
  if (sat[0] >= m_unsat)
    return sat[2];
  double spin = sat[1] * sqrt(m_unsat * m_unsat - sat[0] * sat[0]) /
                (sat[0] * sin(sat[1]));
  return sat[2] > -M_PI / 3.0 ? sat[2] + spin : sat[2] - spin;
}

static void cool_warm(double t, unsigned char rgb[3]) {
  static const unsigned char lo[3] = {59, 76, 192}, hi[3] = {180, 4, 38};
  double m1[3], m2[3];
  rgb_to_msh(lo, m1);
  rgb_to_msh(hi, m2);
  /* both ends saturated with hues far apart: go through white */
  double dh = fabs(m1[2] - m2[2]);
  if (dh > M_PI)
    dh = 2.0 * M_PI - dh;
  if (m1[1] > 0.05 && m2[1] > 0.05 && dh > M_PI / 3.0) {
    double mid = fmax(fmax(m1[0], m2[0]), 88.0);
    if (t < 0.5) {
      m2[0] = mid, m2[1] = 0.0, m2[2] = 0.0;
      t = 2.0 * t;
    } else {
      m1[0] = mid, m1[1] = 0.0, m1[2] = 0.0;
      t = 2.0 * t - 1.0;
    }
  }
  /* an unsaturated end takes the adjusted hue of the other */
  if (m1[1] < 0.05 && m2[1] > 0.05)
    m1[2] = adjust_hue(m2, m1[0]);
  else if (m2[1] < 0.05 && m1[1] > 0.05)
    m2[2] = adjust_hue(m1, m2[0]);
  double m[3];
  for (int i = 0; i < 3; ++i)
    m[i] = (1.0 - t) * m1[i] + t * m2[i];
  msh_to_rgb(m, rgb);
}

static void viridis_eval(double t, unsigned char rgb[3]) {
  double u = t * (VIRIDIS_N - 1);
  int i = (int)u;
  if (i > VIRIDIS_N - 2)
    i = VIRIDIS_N - 2;
  double f = u - i;
  for (int c = 0; c < 3; ++c)
    rgb[c] = to_byte((1.0 - f) * viridis[i][c] + f * viridis[i + 1][c]);
}

void sph_colormap_nan(sph_colormap_kind k, unsigned char rgb[3]) {
  static const unsigned char yellow[3] = {255, 255, 0}, red[3] = {255, 0, 0};
  const unsigned char *c = k == SPH_CMAP_VIRIDIS ? red : yellow;
  for (int i = 0; i < 3; ++i)
    rgb[i] = c[i];
}

void sph_colormap_eval(sph_colormap_kind k, double t, unsigned char rgb[3]) {
  if (isnan(t)) {
    sph_colormap_nan(k, rgb);
    return;
  }
  t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  if (k == SPH_CMAP_VIRIDIS)
    viridis_eval(t, rgb);
  else
    cool_warm(t, rgb);
}

void sph_colormap_table(sph_colormap_kind k, int n, unsigned char *rgb) {
  for (int i = 0; i < n; ++i)
    sph_colormap_eval(k, n > 1 ? (double)i / (n - 1) : 0.0, rgb + 3 * i);
}
