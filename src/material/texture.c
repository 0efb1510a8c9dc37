#include "material/texture.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "io/file_read.h"
#include "io/image_read.h"

fr_error fr_texture_load(fr_texture *t, const char *path) {
  memset(t, 0, sizeof *t);
  if (fr_has_suffix(path, ".exr") || fr_has_suffix(path, ".hdr") || fr_has_suffix(path, ".pic"))
    return fr_image_read(path, &t->w, &t->h, &t->rgb);
  return fr_image_read_ldr(path, &t->w, &t->h, &t->rgb);
}

void fr_texture_free(fr_texture *t) {
  free(t->rgb);
  memset(t, 0, sizeof *t);
}

/* wraps x into [0, n) */
static int wrap(int x, int n) {
  x %= n;
  return x < 0 ? x + n : x;
}

vec3 fr_texture_lookup(const fr_texture *t, float s, float u) {
  if (!t->rgb || !isfinite(s) || !isfinite(u)) return v3(0.8f, 0.8f, 0.8f);
  /* texel centres at (i + 0.5) / w; rows from the bottom */
  const float x = s - floorf(s), y = u - floorf(u);
  const float fx = x * (float)t->w - 0.5f, fy = (1.0f - y) * (float)t->h - 0.5f;
  const float x0f = floorf(fx), y0f = floorf(fy), ax = fx - x0f, ay = fy - y0f;
  const int x0 = wrap((int)x0f, t->w), x1 = wrap((int)x0f + 1, t->w), y0 = wrap((int)y0f, t->h), y1 = wrap((int)y0f + 1, t->h);
  const float *p00 = t->rgb + 3 * ((size_t)y0 * t->w + x0), *p01 = t->rgb + 3 * ((size_t)y0 * t->w + x1);
  const float *p10 = t->rgb + 3 * ((size_t)y1 * t->w + x0), *p11 = t->rgb + 3 * ((size_t)y1 * t->w + x1);
  float c[3];
  for (int k = 0; k < 3; k++)
    c[k] = (1.0f - ay) * ((1.0f - ax) * p00[k] + ax * p01[k]) + ay * ((1.0f - ax) * p10[k] + ax * p11[k]);
  return v3(c[0], c[1], c[2]);
}
