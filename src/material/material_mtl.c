/* MTL parameters to path-tracing materials (material_mtl.h). */
#include "material/material_mtl.h"
#include <math.h>

void fr_bsdf_metal_from_reflectance(fr_bsdf *b, vec3 f0) {
  /* eta = 1: F0 = k^2 / (4 + k^2), so k = 2 sqrt(F0 / (1 - F0)) */
  float c[3] = {f0.x, f0.y, f0.z}, k[3];
  for (int i = 0; i < 3; i++) {
    const float f = fr_minf(fr_maxf(c[i], 0.0f), 0.999f);
    k[i] = 2.0f * sqrtf(f / (1.0f - f));
  }
  b->eta = v3(1.0f, 1.0f, 1.0f);
  b->k = v3(k[0], k[1], k[2]);
}

fr_bsdf fr_bsdf_from_mtl(const fr_material *m, float scale) {
  const vec3 kd = v3_load(m->diffuse), ks = v3_load(m->specular), tf = v3_load(m->transmission);
  const float ksmax = fr_maxf(ks.x, fr_maxf(ks.y, ks.z)), tfmax = fr_maxf(tf.x, fr_maxf(tf.y, tf.z));
  const float ior = m->ior > 1.0f && m->ior < 4.0f ? m->ior : 1.5f;
  fr_bsdf b;
  if (m->illum == 4 || m->illum == 6 || m->illum == 7 || tfmax > 0.0f) {
    b = fr_bsdf_default(FR_BSDF_GLASS);
    b.ior = ior;
    /* a transmission given as 1 - d is grey: clear glass; a colour tints */
    const int tinted = tfmax > 0.0f && (tf.x != tf.y || tf.y != tf.z);
    b.attenuation_color = tinted ? v3_scale(tf, 1.0f / tfmax) : v3(1, 1, 1);
    b.attenuation_distance = scale > 0.0f ? scale : 1.0f;
  } else if (m->illum == 3 && ksmax > 0.0f && fr_maxf(kd.x, fr_maxf(kd.y, kd.z)) <= FR_MTL_METAL_MAX_KD) {
    b = fr_bsdf_default(FR_BSDF_METAL);
    fr_bsdf_metal_from_reflectance(&b, ks);
    b.roughness = 0.0f;
  } else if (ksmax > 0.0f) {
    b = fr_bsdf_default(FR_BSDF_PLASTIC);
    b.color = kd;
    b.ior = ior;
    /* a Phong exponent as a microfacet roughness: alpha = sqrt(2 / (Ns + 2)),
     * Walter et al.'s match of Blinn-Phong to Beckmann, which GGX follows
     * closely; no exponent, or a large one, is a smooth coat */
    b.roughness = m->shininess > 0.0f && m->shininess < 1000.0f ? sqrtf(sqrtf(2.0f / (m->shininess + 2.0f))) : 0.0f;
  } else {
    b = fr_bsdf_default(FR_BSDF_LAMBERT);
    b.color = kd;
  }
  b.emission = v3_load(m->emission);
  return b;
}
