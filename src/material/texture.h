/*
 * Image textures: an RGB image (linear) looked up at texture coordinates
 * (s, t), bilinearly, repeating beyond [0, 1) as OBJ and glTF textures do;
 * t = 0 is the image's bottom row (OBJ's convention).
 */
#ifndef FR_MATERIAL_TEXTURE_H
#define FR_MATERIAL_TEXTURE_H
#include "base/vec3.h"
#include "frusta.h"

typedef struct fr_texture {
  int w, h;
  float *rgb; /* w * h * 3, row 0 at the top */
} fr_texture;

/* PNG, JPEG, TGA, BMP (sRGB, decoded to linear), EXR or Radiance HDR (linear). */
fr_error fr_texture_load(fr_texture *t, const char *path);
void fr_texture_free(fr_texture *t);
vec3 fr_texture_lookup(const fr_texture *t, float s, float u);
#endif
