/* The denoiser's driver (film/denoise.h): planes in, levels, planes out. */
#include "film/denoise.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"
#include "film/atrous.h"

#define MISS 1e30f /* FR_DEPTH_MISS of render/progressive.h */
#define ALBEDO_MIN 0.01f /* dividing by less would amplify noise on black surfaces */

enum { P_IN0, P_IN1, P_IN2, P_TMP0, P_TMP1, P_TMP2, P_N0, P_N1, P_N2, P_Z, P_ZG, P_COUNT };

struct fr_denoiser {
  int width, height, row; /* row: pixels filtered per row (width rounded up to the lanes) */
  size_t stride, plane;   /* floats per padded row and per plane */
  float *mem;
  float *p[P_COUNT];
};

static void atrous_rows(const fr_atrous_level *L, int y0, int y1) {
  switch (fr_get_isa()) {
  case FR_ISA_AVX512: fr_atrous_rows_avx512(L, y0, y1); break;
  case FR_ISA_AVX2: fr_atrous_rows_avx2(L, y0, y1); break;
  default: fr_atrous_rows_scalar(L, y0, y1); break;
  }
}

fr_error fr_denoiser_new(int width, int height, fr_denoiser **out) {
  *out = NULL;
  if (width < 1 || height < 1 || width > 32768 || height > 32768)
    return fr_fail(FR_ERR_ARG, "denoiser: bad image size %dx%d", width, height);
  fr_denoiser *d = calloc(1, sizeof *d);
  if (!d) return fr_fail(FR_ERR_NOMEM, "out of memory for the denoiser");
  d->width = width, d->height = height;
  d->row = (width + FR_ATROUS_LANES - 1) / FR_ATROUS_LANES * FR_ATROUS_LANES;
  d->stride = (size_t)d->row + 2 * FR_ATROUS_PAD;
  d->plane = d->stride * ((size_t)height + 2 * FR_ATROUS_PAD);
  d->mem = fr_alloc_aligned(d->plane * P_COUNT * sizeof(float), 64);
  if (!d->mem) { free(d); return fr_fail(FR_ERR_NOMEM, "out of memory for the denoiser"); }
  for (int k = 0; k < P_COUNT; k++) d->p[k] = d->mem + (size_t)k * d->plane;
  /* the border: background, which no pixel blends with */
  memset(d->mem, 0, d->plane * P_COUNT * sizeof(float));
  for (size_t i = 0; i < d->plane; i++) d->p[P_Z][i] = MISS;
  *out = d;
  return FR_OK;
}

void fr_denoiser_free(fr_denoiser *d) {
  if (!d) return;
  fr_free_aligned(d->mem);
  free(d);
}

static size_t at(const fr_denoiser *d, int x, int y) {
  return (size_t)(y + FR_ATROUS_PAD) * d->stride + (size_t)(x + FR_ATROUS_PAD);
}

/* Depth change per pixel step at (x, y): the smaller one-sided difference
 * on each axis (a silhouette on one side does not count), the larger axis. */
static float depth_gradient(const fr_denoiser *d, const float *depth, int x, int y) {
  const int W = d->width, H = d->height;
  const float z = depth[(size_t)y * W + x];
  float g[2];
  for (int axis = 0; axis < 2; axis++) {
    float best = INFINITY;
    for (int sgn = -1; sgn <= 1; sgn += 2) {
      const int xx = x + (axis == 0 ? sgn : 0), yy = y + (axis == 1 ? sgn : 0);
      if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
      const float zq = depth[(size_t)yy * W + xx];
      if (zq >= 1e29f) continue;
      best = fminf(best, fabsf(zq - z));
    }
    g[axis] = isfinite(best) ? best : 0.0f;
  }
  return fmaxf(g[0], g[1]);
}

void fr_denoise(fr_denoiser *d, const float *rgb, const float *albedo, const float *normal, const float *depth, int spp,
                int threads, float *out) {
  const int W = d->width, H = d->height;
  float **p = d->p;
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      const size_t i = (size_t)y * W + x, o = at(d, x, y);
      const float z = depth[i];
      const int hit = z < 1e29f && isfinite(z);
      float n[3] = {normal[3 * i], normal[3 * i + 1], normal[3 * i + 2]};
      const float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int c = 0; c < 3; c++) {
        const float v = rgb[3 * i + c];
        p[P_IN0 + c][o] = hit ? (isfinite(v) ? v : 0.0f) / fmaxf(albedo[3 * i + c], ALBEDO_MIN) : v;
        p[P_N0 + c][o] = hit && len > 0.0f ? n[c] / len : 0.0f;
      }
      p[P_Z][o] = hit ? z : MISS;
      p[P_ZG][o] = hit ? depth_gradient(d, depth, x, y) : 0.0f;
    }
  /* luminance is trusted more as samples add up: noise falls as 1/sqrt(spp) */
  const float sigma_l0 = 2.0f / sqrtf((float)(spp > 1 ? spp : 1));
  float *src[3] = {p[P_IN0], p[P_IN1], p[P_IN2]}, *dst[3] = {p[P_TMP0], p[P_TMP1], p[P_TMP2]};
  for (int level = 0; level < FR_DENOISE_LEVELS; level++) {
    fr_atrous_level L = {{src[0], src[1], src[2]}, {dst[0], dst[1], dst[2]}, {p[P_N0], p[P_N1], p[P_N2]}, p[P_Z], p[P_ZG],
                         d->stride, d->row, 1 << level, sigma_l0 / (float)(1 << level), 2.0f};
    const int chunk = 8;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int y0 = 0; y0 < H; y0 += chunk) atrous_rows(&L, y0, y0 + chunk < H ? y0 + chunk : H);
    for (int c = 0; c < 3; c++) { float *t = src[c]; src[c] = dst[c]; dst[c] = t; }
  }
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      const size_t i = (size_t)y * W + x, o = at(d, x, y);
      const int hit = p[P_Z][o] < 1e29f;
      for (int c = 0; c < 3; c++) out[3 * i + c] = hit ? src[c][o] * fmaxf(albedo[3 * i + c], ALBEDO_MIN) : src[c][o];
    }
}
