/* From linear radiance to display values: the filmic curve of path-traced
 * images and the sRGB encoding of 8-bit pixels. */
#ifndef FR_FILM_TONEMAP_H
#define FR_FILM_TONEMAP_H
#include <math.h>
#include <stddef.h>

/* Narkowicz's fit of the ACES filmic curve. */
static inline float fr_filmic(float x) {
  x = x > 0.0f ? x : 0.0f;
  return x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f);
}

/* v[0..n) through the filmic curve after exposure in stops. */
static inline void fr_tonemap_filmic(float *v, size_t n, float exposure) {
  const float gain = exp2f(exposure);
  for (size_t i = 0; i < n; i++) v[i] = fr_filmic(v[i] * gain);
}

/* A linear value in [0, 1] (clamped; NaN is 0) as an 8-bit sRGB code. */
static inline unsigned char fr_srgb8(float v) {
  if (!(v > 0.0f)) return 0;
  if (v >= 1.0f) return 255;
  float s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
  return (unsigned char)(s * 255.0f + 0.5f);
}
#endif
