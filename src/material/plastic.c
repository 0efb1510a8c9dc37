/*
 * Plastic: a dielectric coat (index ior, GGX roughness `roughness`; below
 * FR_BSDF_MIRROR_ALPHA a smooth one) over a Lambertian base.
 *
 * The coat reflects like a rough dielectric, F(wo.h) D G2 / (4 wo.z wi.z)
 * (smooth: a mirror of weight F(wo.z)). What enters scatters in the base,
 * bouncing between base and coat, and leaves through the coat, as in
 * Weidlich and Wilkie's layered model with the internal bounces summed in
 * closed form:
 *   f_d = (1 - F(wo)) (1 - F(wi)) color / (pi ior^2 (1 - color Fdr_in)),
 * Fdr_in the coat's reflectance of diffuse light from below. Since
 * 1 - Fdr_in = (1 - Fdr_out) / ior^2, white color reflects 1 - F(wo) by the
 * base and F(wo) by the coat: all of it (up to the Fresnel fit, and, when
 * rough, less what single-scattering microfacets lose).
 * The coat's lobe is picked with probability F / (F + (1 - F) max(color)),
 * F at wo.z; the pdf of a direction is the mixture of both lobes'.
 */
#include "material/bsdf_kinds.h"
#include "material/fresnel.h"
#include "material/microfacet.h"

static vec3 diffuse_f(const fr_bsdf *m, float fo, float fi) {
  const float e2 = m->ior * m->ior, fdr_in = fr_fresnel_diffuse(m->ior);
  const vec3 c = m->color;
  const float s = (1.0f - fo) * (1.0f - fi) * FR_INV_PI / e2;
  return v3(s * c.x / (1.0f - c.x * fdr_in), s * c.y / (1.0f - c.y * fdr_in), s * c.z / (1.0f - c.z * fdr_in));
}

static float coat_probability(const fr_bsdf *m, float fo) {
  const float d = (1.0f - fo) * fr_max3(m->color);
  return fo + d > 0.0f ? fo / (fo + d) : 1.0f;
}

static int smooth(const fr_bsdf *m) { return m->roughness * m->roughness < FR_BSDF_MIRROR_ALPHA; }

int fr_plastic_sample(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, float uc, float u1, float u2,
                      fr_bsdf_sample *out) {
  if (wo.z <= 0.0f) return 0;
  const float fo = fr_fresnel_dielectric(wo.z, m->ior, NULL), ps = coat_probability(m, fo);
  if (uc < ps && smooth(m)) {
    out->wi = fr_reflect_z(wo);
    out->pdf = ps;
    out->weight = v3(fo / ps, fo / ps, fo / ps);
    out->delta = 1;
    return 1;
  }
  if (uc < ps) {
    const float a = m->roughness * m->roughness;
    out->wi = fr_reflect(wo, fr_ggx_sample_vndf(wo, a, u1, u2));
  } else {
    out->wi = fr_sample_cosine(u1, u2);
  }
  if (out->wi.z <= 0.0f) return 0;
  const vec3 f = fr_plastic_eval(m, sp, wo, out->wi, &out->pdf);
  if (!(out->pdf > 0.0f)) return 0;
  out->weight = v3_scale(f, 1.0f / out->pdf);
  out->delta = 0;
  return 1;
}

vec3 fr_plastic_eval(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, vec3 wi, float *pdf) {
  (void)sp;
  if (wo.z <= 0.0f || wi.z <= 0.0f) { *pdf = 0.0f; return v3(0, 0, 0); }
  const float fo = fr_fresnel_dielectric(wo.z, m->ior, NULL), fi = fr_fresnel_dielectric(wi.z, m->ior, NULL);
  const float ps = coat_probability(m, fo);
  vec3 f = v3_scale(diffuse_f(m, fo, fi), wi.z);
  *pdf = (1.0f - ps) * wi.z * FR_INV_PI;
  if (!smooth(m)) {
    const float a = m->roughness * m->roughness;
    const vec3 h = v3_norm(v3_add(wo, wi));
    const float oh = v3_dot(wo, h);
    if (oh > 0.0f) {
      const float spec = fr_fresnel_dielectric(oh, m->ior, NULL) * fr_ggx_d(h, a) * fr_ggx_g2(wo, wi, a) / (4.0f * wo.z);
      f = v3_add(f, v3(spec, spec, spec));
      *pdf += ps * fr_ggx_pdf_reflect(wo, h, a);
    }
  }
  return f;
}
