#include "material/texture.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/bilinear.h"
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

vec3 fr_texture_lookup(const fr_texture *t, float s, float u) {
  if (!t->rgb || !isfinite(s) || !isfinite(u)) return v3(0.8f, 0.8f, 0.8f);
  /* texel centres at (i + 0.5) / w; rows from the bottom */
  const float x = s - floorf(s), y = u - floorf(u);
  return fr_rgb_bilinear(t->rgb, t->w, t->h, x * (float)t->w - 0.5f, (1.0f - y) * (float)t->h - 0.5f, 0);
}
