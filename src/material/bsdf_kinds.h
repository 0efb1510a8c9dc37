/* The material kinds' own sample / eval / pdf (internal to src/material). */
#ifndef FR_MATERIAL_BSDF_KINDS_H
#define FR_MATERIAL_BSDF_KINDS_H
#include "base/trig.h"
#include "material/bsdf.h"

#define FR_DECLARE_BSDF(kind)                                                                                      \
  int fr_##kind##_sample(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, float uc, float u1, float u2, \
                         fr_bsdf_sample *out);                                                                     \
  vec3 fr_##kind##_eval(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, vec3 wi, float *pdf);
FR_DECLARE_BSDF(lambert)
FR_DECLARE_BSDF(plastic)
FR_DECLARE_BSDF(metal)
FR_DECLARE_BSDF(glass)
FR_DECLARE_BSDF(carpaint)

#define FR_PI 3.14159265358979323846f
#define FR_INV_PI 0.31830988618379067154f

/* Cosine-weighted direction about +z from u1, u2 (pdf cos/pi). */
static inline vec3 fr_sample_cosine(float u1, float u2) {
  float r = sqrtf(u1), s, c;
  fr_sincos_turns(u2, &s, &c);
  return v3(r * c, r * s, sqrtf(fr_maxf(0.0f, 1.0f - u1)));
}
static inline vec3 fr_reflect_z(vec3 w) { return v3(-w.x, -w.y, w.z); }
static inline float fr_lum(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
static inline float fr_max3(vec3 c) { return fr_maxf(c.x, fr_maxf(c.y, c.z)); }
#endif
