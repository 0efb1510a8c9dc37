/* Lambert: f = color / pi, cosine-weighted sampling (the weight is color). */
#include "material/bsdf_kinds.h"

int fr_lambert_sample(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, float uc, float u1, float u2,
                      fr_bsdf_sample *out) {
  (void)sp; (void)uc;
  if (wo.z <= 0.0f) return 0;
  out->wi = fr_sample_cosine(u1, u2);
  out->pdf = out->wi.z * FR_INV_PI;
  out->weight = m->color;
  out->delta = 0;
  return out->pdf > 0.0f;
}

vec3 fr_lambert_eval(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, vec3 wi, float *pdf) {
  (void)sp;
  if (wo.z <= 0.0f || wi.z <= 0.0f) { *pdf = 0.0f; return v3(0, 0, 0); }
  *pdf = wi.z * FR_INV_PI;
  return v3_scale(m->color, wi.z * FR_INV_PI);
}
