/* Fresnel reflectance of smooth interfaces, unpolarized light. */
#ifndef FR_MATERIAL_FRESNEL_H
#define FR_MATERIAL_FRESNEL_H
#include <math.h>
#include <stddef.h>
#include "base/vec3.h"

/* A dielectric interface of relative index eta (inside over outside);
 * cos_i < 0 means the light arrives from inside. *cos_t: the cosine of the
 * refracted direction (0 under total internal reflection, which returns 1). */
static inline float fr_fresnel_dielectric(float cos_i, float eta, float *cos_t) {
  if (cos_i < 0.0f) { eta = 1.0f / eta; cos_i = -cos_i; }
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) { if (cos_t) *cos_t = 0.0f; return 1.0f; }
  const float ct = sqrtf(1.0f - sin2_t);
  if (cos_t) *cos_t = ct;
  const float rs = (cos_i - eta * ct) / (cos_i + eta * ct), rp = (eta * cos_i - ct) / (eta * cos_i + ct);
  return 0.5f * (rs * rs + rp * rp);
}

/* A conductor of complex index eta + i k, one channel, cos_i in [0, 1]. */
static inline float fr_fresnel_conductor1(float c, float eta, float k) {
  const float c2 = c * c, s2 = 1.0f - c2;
  const float t0 = eta * eta - k * k - s2;
  const float a2b2 = sqrtf(fr_maxf(0.0f, t0 * t0 + 4.0f * eta * eta * k * k));
  const float a = sqrtf(fr_maxf(0.0f, 0.5f * (a2b2 + t0)));
  const float t1 = a2b2 + c2, t2 = 2.0f * c * a;
  const float rs = (t1 - t2) / (t1 + t2);
  const float t3 = c2 * a2b2 + s2 * s2, t4 = t2 * s2;
  const float rp = rs * (t3 - t4) / (t3 + t4);
  return 0.5f * (rs + rp);
}
static inline vec3 fr_fresnel_conductor(float c, vec3 eta, vec3 k) {
  return v3(fr_fresnel_conductor1(c, eta.x, k.x), fr_fresnel_conductor1(c, eta.y, k.y),
            fr_fresnel_conductor1(c, eta.z, k.z));
}

/* The reflectance of an interface for diffuse light arriving from inside a
 * medium of relative index eta > 1, 2 int F(cos) cos dcos, by the fit of
 * d'Eon and Irving (about 0.6 at 1.5; from outside it is
 * 1 - (1 - that) eta^2, about 0.09). */
static inline float fr_fresnel_diffuse(float eta) {
  if (eta < 1.0f) return 0.0f;
  return -1.4399f / (eta * eta) + 0.7099f / eta + 0.6681f + 0.0636f * eta;
}
#endif
