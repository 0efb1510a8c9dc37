/*
 * Glass: a smooth dielectric. Reflection with the Fresnel probability F,
 * refraction (Snell) otherwise, total internal reflection where sin t > 1;
 * both lobes are deltas of weight 1. The frame's z is the outward normal:
 * wo.z < 0 when the light leaves from inside. Radiance is not scaled by
 * the squared index ratio on refraction: for camera paths through closed
 * objects the factors cancel, and it keeps a path's weight below 1.
 * Absorption inside (Beer) is the integrator's, over the distance a ray
 * travels inside (attenuation_color after attenuation_distance).
 */
#include "material/bsdf_kinds.h"
#include "material/fresnel.h"

int fr_glass_sample(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, float uc, float u1, float u2,
                    fr_bsdf_sample *out) {
  (void)sp; (void)u1; (void)u2;
  float ct;
  const float f = fr_fresnel_dielectric(wo.z, m->ior, &ct);
  out->delta = 1;
  out->weight = v3(1.0f, 1.0f, 1.0f);
  if (uc < f) {
    out->wi = fr_reflect_z(wo);
    out->pdf = f;
    return 1;
  }
  /* refraction: eta the ratio of the side wo is on to the other */
  const float eta = wo.z > 0.0f ? 1.0f / m->ior : m->ior;
  const vec3 t = v3_scale(v3(-wo.x, -wo.y, 0.0f), eta);
  out->wi = v3_norm(v3(t.x, t.y, wo.z > 0.0f ? -ct : ct));
  out->pdf = 1.0f - f;
  return 1;
}

vec3 fr_glass_eval(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, vec3 wi, float *pdf) {
  (void)m; (void)sp; (void)wo; (void)wi;
  *pdf = 0.0f;
  return v3(0, 0, 0);
}
