/*
 * The GGX (Trowbridge-Reitz) microfacet distribution, isotropic, with
 * Smith's height-correlated masking and Heitz's sampling of the visible
 * normals ("Sampling the GGX Distribution of Visible Normals", JCGT 2018).
 * Directions in the frame whose z is the macro normal.
 */
#ifndef FR_MATERIAL_MICROFACET_H
#define FR_MATERIAL_MICROFACET_H
#include <math.h>
#include "base/vec3.h"
#include "base/trig.h"

static inline float fr_ggx_d(vec3 h, float a) {
  if (h.z <= 0.0f) return 0.0f;
  const float a2 = a * a, c2 = h.z * h.z, t = c2 * (a2 - 1.0f) + 1.0f;
  return a2 / (3.14159265358979323846f * t * t);
}
static inline float fr_ggx_lambda(vec3 w, float a) {
  const float c2 = w.z * w.z, s2 = fr_maxf(0.0f, 1.0f - c2);
  if (c2 <= 0.0f) return 1e30f;
  return 0.5f * (-1.0f + sqrtf(1.0f + a * a * s2 / c2));
}
static inline float fr_ggx_g1(vec3 w, float a) { return 1.0f / (1.0f + fr_ggx_lambda(w, a)); }
static inline float fr_ggx_g2(vec3 wo, vec3 wi, float a) {
  return 1.0f / (1.0f + fr_ggx_lambda(wo, a) + fr_ggx_lambda(wi, a));
}
/* A visible normal for wo (wo.z > 0). */
static inline vec3 fr_ggx_sample_vndf(vec3 wo, float a, float u1, float u2) {
  const vec3 vh = v3_norm(v3(a * wo.x, a * wo.y, wo.z));
  const float l2 = vh.x * vh.x + vh.y * vh.y;
  const vec3 t1 = l2 > 0.0f ? v3_scale(v3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(l2)) : v3(1.0f, 0.0f, 0.0f);
  const vec3 t2 = v3_cross(vh, t1);
  float sp, cp;
  fr_sincos_turns(u2, &sp, &cp);
  const float r = sqrtf(u1), p1 = r * cp, s = 0.5f * (1.0f + vh.z);
  const float p2 = (1.0f - s) * sqrtf(fr_maxf(0.0f, 1.0f - p1 * p1)) + s * r * sp;
  const vec3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)),
                         v3_scale(vh, sqrtf(fr_maxf(0.0f, 1.0f - p1 * p1 - p2 * p2))));
  return v3_norm(v3(a * nh.x, a * nh.y, fr_maxf(1e-6f, nh.z)));
}
/* The pdf of wi = reflect(wo, h) when h is sampled by fr_ggx_sample_vndf. */
static inline float fr_ggx_pdf_reflect(vec3 wo, vec3 h, float a) {
  return fr_ggx_g1(wo, a) * fr_ggx_d(h, a) / (4.0f * wo.z);
}
static inline vec3 fr_reflect(vec3 w, vec3 n) { return v3_sub(v3_scale(n, 2.0f * v3_dot(w, n)), w); }
#endif
