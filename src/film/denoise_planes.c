/* The denoiser's rows into planes and back (film/denoise_planes.h). */
#include "film/denoise_planes.h"
#include <math.h>
#include "base/simd.h"
#include "base/vec3.h"
#include "film/atrous.h"

/* A unit normal's component in [-1, 1] as 16 bits, rounded half away from
 * zero (a truncating conversion: vector code on every ISA alike); NaN, or
 * anything outside, is 0. */
static inline int16_t quantize(float c) {
  float s = c * FR_ATROUS_NORMAL_ONE;
  s = s >= -FR_ATROUS_NORMAL_ONE && s <= FR_ATROUS_NORMAL_ONE ? s : 0.0f;
  return (int16_t)(int)(s + (s < 0.0f ? -0.5f : 0.5f));
}

void FR_ISA_FN(fr_denoise_split)(const float *restrict rgb, const float *restrict albedo, const float *restrict normal,
                                 const float *restrict depth, int n, float *restrict in0, float *restrict in1,
                                 float *restrict in2, int16_t *restrict n0, int16_t *restrict n1,
                                 int16_t *restrict n2, float *restrict z) {
  for (int x = 0; x < n; x++) {
    const float *c = rgb + 3 * x, *a = albedo + 3 * x, *nv = normal + 3 * x;
    const float zz = depth[x];
    const int hit = zz < 1e29f; /* NaN: background */
    /* the divisions and the root for every pixel, kept where they apply:
     * branch-free, so the loop is vector code */
    const float len2 = nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2], unit = 1.0f / sqrtf(len2 > 0.0f ? len2 : 1.0f);
    const float inv = hit && len2 > 0.0f ? unit : 0.0f;
    /* c - c is 0 for a finite colour only: inf and NaN become 0 */
    const float c0 = c[0] - c[0] == 0.0f ? c[0] : 0.0f, c1 = c[1] - c[1] == 0.0f ? c[1] : 0.0f;
    const float c2 = c[2] - c[2] == 0.0f ? c[2] : 0.0f;
    const float q0 = c0 / fr_maxf(a[0], FR_DENOISE_ALBEDO_MIN), q1 = c1 / fr_maxf(a[1], FR_DENOISE_ALBEDO_MIN);
    const float q2 = c2 / fr_maxf(a[2], FR_DENOISE_ALBEDO_MIN);
    in0[x] = hit ? q0 : c0;
    in1[x] = hit ? q1 : c1;
    in2[x] = hit ? q2 : c2;
    n0[x] = quantize(nv[0] * inv), n1[x] = quantize(nv[1] * inv), n2[x] = quantize(nv[2] * inv);
    z[x] = hit ? zz : FR_DENOISE_MISS;
  }
}

void FR_ISA_FN(fr_denoise_merge)(const float *restrict s0, const float *restrict s1, const float *restrict s2,
                                 const float *restrict z, const float *restrict albedo, int n, float *restrict out) {
  for (int x = 0; x < n; x++) {
    const int hit = z[x] < 1e29f;
    out[3 * x] = hit ? s0[x] * fr_maxf(albedo[3 * x], FR_DENOISE_ALBEDO_MIN) : s0[x];
    out[3 * x + 1] = hit ? s1[x] * fr_maxf(albedo[3 * x + 1], FR_DENOISE_ALBEDO_MIN) : s1[x];
    out[3 * x + 2] = hit ? s2[x] * fr_maxf(albedo[3 * x + 2], FR_DENOISE_ALBEDO_MIN) : s2[x];
  }
}
