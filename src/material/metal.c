/*
 * Metal: a conductor with complex index eta + i k per channel. Rough metal
 * is GGX with Smith's height-correlated masking, sampled by visible
 * normals: f cos = F(wo.h) D G2 / (4 wo.z), weight F G2 / G1(wo). Below
 * FR_METAL_MIRROR (alpha = roughness^2) it is a perfect mirror, weight F.
 */
#include "material/bsdf_kinds.h"
#include "material/fresnel.h"
#include "material/microfacet.h"

#define FR_METAL_MIRROR FR_BSDF_MIRROR_ALPHA

int fr_metal_sample(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, float uc, float u1, float u2,
                    fr_bsdf_sample *out) {
  (void)sp; (void)uc;
  if (wo.z <= 0.0f) return 0;
  const float a = m->roughness * m->roughness;
  if (a < FR_METAL_MIRROR) {
    out->wi = fr_reflect_z(wo);
    out->weight = fr_fresnel_conductor(wo.z, m->eta, m->k);
    out->pdf = 1.0f;
    out->delta = 1;
    return 1;
  }
  const vec3 h = fr_ggx_sample_vndf(wo, a, u1, u2);
  const float oh = v3_dot(wo, h);
  out->wi = fr_reflect(wo, h);
  if (out->wi.z <= 0.0f || oh <= 0.0f) return 0;
  out->pdf = fr_ggx_pdf_reflect(wo, h, a);
  out->weight = v3_scale(fr_fresnel_conductor(oh, m->eta, m->k), fr_ggx_g2(wo, out->wi, a) / fr_ggx_g1(wo, a));
  out->delta = 0;
  return out->pdf > 0.0f;
}

vec3 fr_metal_eval(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, vec3 wi, float *pdf) {
  (void)sp;
  const float a = m->roughness * m->roughness;
  *pdf = 0.0f;
  if (a < FR_METAL_MIRROR || wo.z <= 0.0f || wi.z <= 0.0f) return v3(0, 0, 0);
  const vec3 h = v3_norm(v3_add(wo, wi));
  const float oh = v3_dot(wo, h);
  if (oh <= 0.0f) return v3(0, 0, 0);
  const float d = fr_ggx_d(h, a);
  *pdf = fr_ggx_pdf_reflect(wo, h, a);
  return v3_scale(fr_fresnel_conductor(oh, m->eta, m->k), d * fr_ggx_g2(wo, wi, a) / (4.0f * wo.z));
}
