/* Bilinear lookup in an RGB float image (row 0 at the top), shared by the
 * textures and the environment map. */
#ifndef FR_BASE_BILINEAR_H
#define FR_BASE_BILINEAR_H
#include <math.h>
#include <stddef.h>
#include "base/vec3.h"

/* wraps x into [0, n) */
static inline int fr_wrap(int x, int n) {
  x %= n;
  return x < 0 ? x + n : x;
}

/* At (fx, fy) in texels, texel i's centre at i (callers subtract 0.5 from
 * scaled coordinates): columns repeat; rows repeat too, or, with
 * clamp_rows, stop at the first and last (a latitude-longitude map's
 * poles). */
static inline vec3 fr_rgb_bilinear(const float *rgb, int w, int h, float fx, float fy, int clamp_rows) {
  const float x0f = floorf(fx), y0f = floorf(fy), ax = fx - x0f, ay = fy - y0f;
  const int x0 = fr_wrap((int)x0f, w), x1 = fr_wrap((int)x0f + 1, w);
  int y0 = (int)y0f, y1 = y0 + 1;
  if (clamp_rows) y0 = y0 < 0 ? 0 : y0 >= h ? h - 1 : y0, y1 = y1 >= h ? h - 1 : y1 < 0 ? 0 : y1;
  else y0 = fr_wrap(y0, h), y1 = fr_wrap(y1, h);
  const float *p00 = rgb + 3 * ((size_t)y0 * w + x0), *p01 = rgb + 3 * ((size_t)y0 * w + x1);
  const float *p10 = rgb + 3 * ((size_t)y1 * w + x0), *p11 = rgb + 3 * ((size_t)y1 * w + x1);
  float c[3];
  for (int k = 0; k < 3; k++)
    c[k] = (1.0f - ay) * ((1.0f - ax) * p00[k] + ax * p01[k]) + ay * ((1.0f - ax) * p10[k] + ax * p11[k]);
  return v3(c[0], c[1], c[2]);
}
#endif
