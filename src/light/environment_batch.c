/*
 * An image environment's samples and texel lookups for many paths at once
 * (light/environment.h): the ISA's vector code (light/environment_lanes.c)
 * for an image, one at a time for a constant colour.
 */
#include "light/environment.h"

void fr_env_sample_batch(const fr_env *e, size_t n, const float *u1, const float *u2, vec3 *dir, vec3 *le, float *pdf) {
  if (e->black || !e->rgb) {
    for (size_t j = 0; j < n; j++) le[j] = fr_env_sample(e, u1[j], u2[j], dir + j, pdf + j);
    return;
  }
  const fr_isa isa = fr_get_isa();
  if (isa == FR_ISA_AVX512) fr_env_sample_batch_avx512(e, n, u1, u2, dir, le, pdf);
  else if (isa == FR_ISA_AVX2) fr_env_sample_batch_avx2(e, n, u1, u2, dir, le, pdf);
  else fr_env_sample_batch_scalar(e, n, u1, u2, dir, le, pdf);
}

void fr_env_texel_batch(const fr_env *e, size_t n, const float *x, const float *y, const float *z,
                        const float **texel, float *sin_t) {
  enum { CHUNK = 64 };
  int at[CHUNK];
  const fr_isa isa = fr_get_isa();
  for (size_t a = 0; a < n; a += CHUNK) {
    const size_t m = n - a < CHUNK ? n - a : CHUNK;
    if (isa == FR_ISA_AVX512) fr_env_texel_batch_avx512(e, m, x + a, y + a, z + a, at, sin_t + a);
    else if (isa == FR_ISA_AVX2) fr_env_texel_batch_avx2(e, m, x + a, y + a, z + a, at, sin_t + a);
    else fr_env_texel_batch_scalar(e, m, x + a, y + a, z + a, at, sin_t + a);
    for (size_t j = 0; j < m; j++) texel[a + j] = e->texels + 4 * (size_t)at[j];
  }
}

void fr_env_eval_smooth_batch(const fr_env *e, size_t n, const float *x, const float *y, const float *z, vec3 *le) {
  if (!e->rgb) {
    for (size_t j = 0; j < n; j++) le[j] = fr_env_eval_smooth(e, v3(x[j], y[j], z[j]));
    return;
  }
  enum { CHUNK = 64 };
  float fx[CHUNK], fy[CHUNK];
  const fr_isa isa = fr_get_isa();
  for (size_t a = 0; a < n; a += CHUNK) {
    const size_t m = n - a < CHUNK ? n - a : CHUNK;
    if (isa == FR_ISA_AVX512) fr_env_smooth_at_batch_avx512(e, m, x + a, y + a, z + a, fx, fy);
    else if (isa == FR_ISA_AVX2) fr_env_smooth_at_batch_avx2(e, m, x + a, y + a, z + a, fx, fy);
    else fr_env_smooth_at_batch_scalar(e, m, x + a, y + a, z + a, fx, fy);
    for (size_t j = 0; j < m; j++) le[a + j] = fr_env_smooth_radiance(e, fx[j], fy[j]);
  }
}
