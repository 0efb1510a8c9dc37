/*
 * Car paint: a clear coat over metallic flakes over a coloured base.
 *
 * The coat (strength `coat`, index ior) is a smooth dielectric: it reflects
 * coat F(wo) as a mirror and lets the rest through, twice, to the layer
 * beneath: f = (1 - coat F(wo)) (1 - coat F(wi)) f_layer cos.
 * The layer is a flake where one covers the point, else the base: space is
 * cut into cells of 1 / flake_scale; a cell holds a flake with probability
 * flake_density, centred at a jittered point and tilted from the normal by
 * up to flake_spread; a flake is a rough conductor-like mirror (Schlick
 * Fresnel from flake_color, GGX of flake_roughness) about its own normal.
 * The base is Lambertian with a colour that turns from `color` seen head-on
 * to flipflop_color at grazing angles (by the mean cosine of the two
 * directions, so that the BSDF stays reciprocal), the sooner the larger
 * flipflop_falloff.
 */
#include <stddef.h>
#include <stdint.h>
#include "material/bsdf_kinds.h"
#include "material/fresnel.h"
#include "material/microfacet.h"

static uint32_t hash3(int32_t x, int32_t y, int32_t z, uint32_t k) {
  uint32_t h = (uint32_t)x * 0x8da6b343u ^ (uint32_t)y * 0xd8163841u ^ (uint32_t)z * 0xcb1ab31fu ^ k * 0x9e3779b9u;
  h ^= h >> 16; h *= 0x7feb352du; h ^= h >> 15; h *= 0x846ca68bu; h ^= h >> 16;
  return h;
}
static float unit(uint32_t h) { return (float)(h >> 8) * (1.0f / 16777216.0f); }

/* The flake covering p, if any, tilted in the tangent plane (frame z = n). */
void fr_carpaint_prepare(const fr_bsdf *m, vec3 p, fr_shading_point *sp) {
  sp->flake = 0;
  sp->flake_n = v3(0, 0, 1);
  if (m->flake_density <= 0.0f || m->flake_scale <= 0.0f) return;
  const vec3 q = v3_scale(p, m->flake_scale);
  const float fx = floorf(q.x), fy = floorf(q.y), fz = floorf(q.z);
  if (!(fabsf(fx) < 2e9f && fabsf(fy) < 2e9f && fabsf(fz) < 2e9f)) return;
  const int32_t cx = (int32_t)fx, cy = (int32_t)fy, cz = (int32_t)fz;
  if (unit(hash3(cx, cy, cz, 1)) >= m->flake_density) return;
  /* a flake of radius 0.5 about a centre jittered within its cell */
  const float j = m->flake_jitter;
  const vec3 c = v3(fx + 0.5f + j * (unit(hash3(cx, cy, cz, 2)) - 0.5f), fy + 0.5f + j * (unit(hash3(cx, cy, cz, 3)) - 0.5f),
                    fz + 0.5f + j * (unit(hash3(cx, cy, cz, 4)) - 0.5f));
  const vec3 d = v3_sub(q, c);
  if (v3_dot(d, d) > 0.25f) return;
  const float r = m->flake_spread * sqrtf(unit(hash3(cx, cy, cz, 5))), phi = 2.0f * FR_PI * unit(hash3(cx, cy, cz, 6));
  sp->flake = 1;
  sp->flake_n = v3_norm(v3(r * cosf(phi), r * sinf(phi), 1.0f));
}

static vec3 base_color(const fr_bsdf *m, float cos_o) {
  const float t = powf(fr_maxf(cos_o, 0.0f), fr_maxf(1e-3f, 1.0f - m->flipflop_falloff) * 2.0f);
  return v3_add(v3_scale(m->color, t), v3_scale(m->flipflop_color, 1.0f - t));
}

/* A flake: GGX about its normal n, in the shading frame. */
static vec3 to_frame(vec3 w, vec3 t, vec3 b, vec3 n) { return v3(v3_dot(w, t), v3_dot(w, b), v3_dot(w, n)); }
static vec3 schlick(vec3 f0, float c) {
  const float x = 1.0f - fr_maxf(0.0f, fr_minf(1.0f, c)), x5 = x * x * x * x * x;
  return v3_add(f0, v3_scale(v3_sub(v3(1, 1, 1), f0), x5));
}
static vec3 flake_eval(const fr_bsdf *m, vec3 n, vec3 wo, vec3 wi, float *pdf) {
  vec3 t, b;
  v3_onb(n, &t, &b);
  const vec3 lo = to_frame(wo, t, b, n), li = to_frame(wi, t, b, n);
  const float a = fr_maxf(1e-3f, m->flake_roughness * m->flake_roughness);
  *pdf = 0.0f;
  if (lo.z <= 0.0f || li.z <= 0.0f || wi.z <= 0.0f) return v3(0, 0, 0);
  const vec3 h = v3_norm(v3_add(lo, li));
  const float oh = v3_dot(lo, h);
  if (oh <= 0.0f) return v3(0, 0, 0);
  *pdf = fr_ggx_pdf_reflect(lo, h, a);
  return v3_scale(schlick(m->flake_color, oh), fr_ggx_d(h, a) * fr_ggx_g2(lo, li, a) / (4.0f * lo.z) * wi.z / li.z);
}
static int flake_sample(const fr_bsdf *m, vec3 n, vec3 wo, float u1, float u2, vec3 *wi) {
  vec3 t, b;
  v3_onb(n, &t, &b);
  const vec3 lo = to_frame(wo, t, b, n);
  if (lo.z <= 0.0f) return 0;
  const float a = fr_maxf(1e-3f, m->flake_roughness * m->flake_roughness);
  const vec3 li = fr_reflect(lo, fr_ggx_sample_vndf(lo, a, u1, u2));
  *wi = v3_add(v3_add(v3_scale(t, li.x), v3_scale(b, li.y)), v3_scale(n, li.z));
  return li.z > 0.0f && wi->z > 0.0f;
}

static float coat_f(const fr_bsdf *m, float c) { return m->coat * fr_fresnel_dielectric(c, m->ior, NULL); }
static float coat_probability(const fr_bsdf *m, const fr_shading_point *sp, float fo) {
  const float d = (1.0f - fo) * (sp->flake ? fr_max3(m->flake_color) : fr_max3(base_color(m, 1.0f)));
  return fo + d > 0.0f ? fo / (fo + d) : 1.0f;
}
static vec3 layer_eval(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, vec3 wi, float *pdf) {
  if (sp->flake) return flake_eval(m, sp->flake_n, wo, wi, pdf);
  *pdf = wi.z * FR_INV_PI;
  return v3_scale(base_color(m, 0.5f * (wo.z + wi.z)), wi.z * FR_INV_PI); /* symmetric in wo, wi: reciprocal */
}

int fr_carpaint_sample(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, float uc, float u1, float u2,
                       fr_bsdf_sample *out) {
  if (wo.z <= 0.0f) return 0;
  const float fo = coat_f(m, wo.z), pc = coat_probability(m, sp, fo);
  if (uc < pc) {
    out->wi = fr_reflect_z(wo);
    out->pdf = pc;
    out->weight = v3(fo / pc, fo / pc, fo / pc);
    out->delta = 1;
    return 1;
  }
  if (sp->flake) {
    if (!flake_sample(m, sp->flake_n, wo, u1, u2, &out->wi)) return 0;
  } else {
    out->wi = fr_sample_cosine(u1, u2);
  }
  float pdf;
  const vec3 f = fr_carpaint_eval(m, sp, wo, out->wi, &pdf);
  if (!(pdf > 0.0f)) return 0;
  out->pdf = pdf;
  out->weight = v3_scale(f, 1.0f / pdf);
  out->delta = 0;
  return 1;
}

vec3 fr_carpaint_eval(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, vec3 wi, float *pdf) {
  *pdf = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return v3(0, 0, 0);
  const float fo = coat_f(m, wo.z), fi = coat_f(m, wi.z), pc = coat_probability(m, sp, fo);
  float lp;
  const vec3 f = layer_eval(m, sp, wo, wi, &lp);
  *pdf = (1.0f - pc) * lp;
  return v3_scale(f, (1.0f - fo) * (1.0f - fi));
}
