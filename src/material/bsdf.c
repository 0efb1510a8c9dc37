/* Dispatch to the kinds, their defaults and names. */
#include "material/bsdf.h"
#include <string.h>
#include "material/bsdf_kinds.h"

void fr_carpaint_prepare(const fr_bsdf *m, vec3 p, fr_shading_point *sp);

static const char *const kind_names[FR_BSDF_KINDS] = {"lambert", "plastic", "metal", "glass", "carpaint"};

const char *fr_bsdf_kind_name(fr_bsdf_kind k) { return k < FR_BSDF_KINDS ? kind_names[k] : "?"; }

int fr_bsdf_kind_parse(const char *name, fr_bsdf_kind *k) {
  for (int i = 0; i < FR_BSDF_KINDS; i++)
    if (!strcmp(name, kind_names[i])) { *k = (fr_bsdf_kind)i; return 1; }
  return 0;
}

/* RGB fits of measured complex indices (at 650, 550 and 450 nm or so). */
static const struct { const char *name; vec3 eta, k; } metals[] = {
    {"chrome", {3.1071f, 3.1812f, 2.3230f}, {3.3314f, 3.3291f, 3.1350f}},
    {"gold", {0.1431f, 0.3749f, 1.4425f}, {3.9831f, 2.3857f, 1.6032f}},
    {"copper", {0.2004f, 0.9240f, 1.1022f}, {3.9129f, 2.4528f, 2.1421f}},
    {"aluminium", {1.6574f, 0.8803f, 0.5212f}, {9.2238f, 6.2695f, 4.8370f}},
    {"silver", {0.1552f, 0.1167f, 0.1383f}, {4.8283f, 3.1222f, 2.1469f}},
};

int fr_bsdf_metal_preset(const char *name, fr_bsdf *m) {
  for (size_t i = 0; i < sizeof metals / sizeof metals[0]; i++)
    if (!strcmp(name, metals[i].name)) { m->eta = metals[i].eta; m->k = metals[i].k; return 1; }
  return 0;
}

fr_bsdf fr_bsdf_default(fr_bsdf_kind kind) {
  fr_bsdf m;
  memset(&m, 0, sizeof m);
  m.kind = kind;
  m.color = v3(0.8f, 0.8f, 0.8f);
  m.color_tex = -1;
  m.ior = 1.5f;
  fr_bsdf_metal_preset("chrome", &m);
  m.attenuation_color = v3(1, 1, 1);
  m.attenuation_distance = 1.0f;
  m.coat = 1.0f;
  m.flake_color = v3(0.9f, 0.9f, 0.9f);
  m.flake_density = 0.0f;
  m.flake_scale = 100.0f;
  m.flake_spread = 0.3f;
  m.flake_jitter = 0.75f;
  m.flake_roughness = 0.3f;
  if (kind == FR_BSDF_CARPAINT) {
    m.color = v3(0.6f, 0.04f, 0.03f);
    m.flipflop_color = v3(0.15f, 0.0f, 0.02f);
    m.flipflop_falloff = 0.3f;
    m.flake_density = 0.4f;
  }
  return m;
}

void fr_bsdf_prepare(const fr_bsdf *m, vec3 p, fr_shading_point *sp) {
  sp->flake = 0;
  sp->flake_n = v3(0, 0, 1);
  if (m->kind == FR_BSDF_CARPAINT) fr_carpaint_prepare(m, p, sp);
}

int fr_bsdf_sample_dir(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, float uc, float u1, float u2,
                       fr_bsdf_sample *out) {
  switch (m->kind) {
  case FR_BSDF_LAMBERT: return fr_lambert_sample(m, sp, wo, uc, u1, u2, out);
  case FR_BSDF_PLASTIC: return fr_plastic_sample(m, sp, wo, uc, u1, u2, out);
  case FR_BSDF_METAL: return fr_metal_sample(m, sp, wo, uc, u1, u2, out);
  case FR_BSDF_GLASS: return fr_glass_sample(m, sp, wo, uc, u1, u2, out);
  case FR_BSDF_CARPAINT: return fr_carpaint_sample(m, sp, wo, uc, u1, u2, out);
  default: return 0;
  }
}

vec3 fr_bsdf_eval(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, vec3 wi, float *pdf) {
  switch (m->kind) {
  case FR_BSDF_LAMBERT: return fr_lambert_eval(m, sp, wo, wi, pdf);
  case FR_BSDF_PLASTIC: return fr_plastic_eval(m, sp, wo, wi, pdf);
  case FR_BSDF_METAL: return fr_metal_eval(m, sp, wo, wi, pdf);
  case FR_BSDF_GLASS: return fr_glass_eval(m, sp, wo, wi, pdf);
  case FR_BSDF_CARPAINT: return fr_carpaint_eval(m, sp, wo, wi, pdf);
  default: *pdf = 0.0f; return v3(0, 0, 0);
  }
}

int fr_bsdf_has_smooth(const fr_bsdf *m, const fr_shading_point *sp) {
  (void)sp;
  if (m->kind == FR_BSDF_GLASS) return 0;
  if (m->kind == FR_BSDF_METAL) return m->roughness * m->roughness >= FR_BSDF_MIRROR_ALPHA;
  return 1;
}

vec3 fr_bsdf_albedo(const fr_bsdf *m) {
  switch (m->kind) {
  case FR_BSDF_METAL: return v3(0.9f, 0.9f, 0.9f);
  case FR_BSDF_GLASS: return m->attenuation_color;
  default: return m->color;
  }
}
