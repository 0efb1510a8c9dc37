/* The denoiser's driver (film/denoise.h): planes in, levels, planes out. */
#include "film/denoise.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"
#include "film/atrous.h"
#include "film/denoise_planes.h"
#include "render/progressive.h"

#define MISS FR_DEPTH_MISS

/* max and min as compares (fmaxf and fminf are calls at this ISA level) */
static inline float maxf(float a, float b) { return a > b ? a : b; }
static inline float minf(float a, float b) { return a < b ? a : b; }
static inline float absf(float a) { return a < 0.0f ? -a : a; }

enum { P_IN0, P_IN1, P_IN2, P_TMP0, P_TMP1, P_TMP2, P_Z, P_ZG, P_COUNT };

struct fr_denoiser {
  int width, height, row; /* row: pixels filtered per row (width rounded up to the lanes) */
  size_t stride, plane;   /* floats per padded row and per plane */
  float *mem;
  float *p[P_COUNT];
  int16_t *nrm[3];        /* the normal planes, 16 bits (film/atrous.h) */
  double *row_lum;        /* per row: the summed luminance of the illumination where it sees geometry */
  int *row_hits;          /* ... and how many pixels that is */
};

/* The per-ISA loops (film/atrous.h, film/denoise_planes.h), chosen once a call. */
typedef struct denoise_kernels {
  void (*atrous_rows)(const fr_atrous_level *L, int y0, int y1);
  void (*split)(const float *rgb, const float *albedo, const float *normal, const float *depth, int n, float *in0,
                float *in1, float *in2, int16_t *n0, int16_t *n1, int16_t *n2, float *z);
  void (*merge)(const float *s0, const float *s1, const float *s2, const float *z, const float *albedo, int n, float *out);
} denoise_kernels;

static const denoise_kernels *kernels_of(fr_isa isa) {
  static const denoise_kernels avx512 = {fr_atrous_rows_avx512, fr_denoise_split_avx512, fr_denoise_merge_avx512};
  static const denoise_kernels avx2 = {fr_atrous_rows_avx2, fr_denoise_split_avx2, fr_denoise_merge_avx2};
  static const denoise_kernels scalar = {fr_atrous_rows_scalar, fr_denoise_split_scalar, fr_denoise_merge_scalar};
  return isa == FR_ISA_AVX512 ? &avx512 : isa == FR_ISA_AVX2 ? &avx2 : &scalar;
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
  d->mem = fr_alloc_aligned(d->plane * P_COUNT * sizeof(float) + 3 * d->plane * sizeof(int16_t), 64);
  d->row_lum = malloc((size_t)height * sizeof *d->row_lum);
  d->row_hits = malloc((size_t)height * sizeof *d->row_hits);
  if (!d->mem || !d->row_lum || !d->row_hits) {
    fr_denoiser_free(d);
    return fr_fail(FR_ERR_NOMEM, "out of memory for the denoiser");
  }
  for (int k = 0; k < P_COUNT; k++) d->p[k] = d->mem + (size_t)k * d->plane;
  for (int k = 0; k < 3; k++) d->nrm[k] = (int16_t *)(d->mem + (size_t)P_COUNT * d->plane) + (size_t)k * d->plane;
  /* the border: background, which no pixel blends with */
  memset(d->mem, 0, d->plane * P_COUNT * sizeof(float) + 3 * d->plane * sizeof(int16_t));
  for (size_t i = 0; i < d->plane; i++) d->p[P_Z][i] = MISS;
  *out = d;
  return FR_OK;
}

void fr_denoiser_free(fr_denoiser *d) {
  if (!d) return;
  fr_free_aligned(d->mem);
  free(d->row_lum);
  free(d->row_hits);
  free(d);
}

static size_t at(const fr_denoiser *d, int x, int y) {
  return (size_t)(y + FR_ATROUS_PAD) * d->stride + (size_t)(x + FR_ATROUS_PAD);
}

/* Row y of the image into the planes (film/denoise_planes.h, vector code
 * per ISA), and its summed illumination where it sees geometry. */
static void split_row(fr_denoiser *d, const denoise_kernels *k, const float *rgb, const float *albedo,
                      const float *normal, const float *depth, int y) {
  const size_t o = at(d, 0, y);
  float *const *p = d->p;
  float *in0 = p[P_IN0] + o, *in1 = p[P_IN1] + o, *in2 = p[P_IN2] + o, *z = p[P_Z] + o;
  int16_t *n0 = d->nrm[0] + o, *n1 = d->nrm[1] + o, *n2 = d->nrm[2] + o;
  k->split(rgb, albedo, normal, depth, d->width, in0, in1, in2, n0, n1, n2, z);
  double lum = 0.0;
  int hits = 0;
  for (int x = 0; x < d->width; x++)
    if (z[x] < 1e29f) lum += 0.2126 * in0[x] + 0.7152 * in1[x] + 0.0722 * in2[x], hits++;
  d->row_lum[y] = lum, d->row_hits[y] = hits;
}

/* The depth change per pixel step of row y (from the padded depth plane,
 * background MISS): on each axis the smaller one-sided difference (a
 * silhouette on one side does not count; background on both: none), the
 * larger axis. */
static void depth_gradient_row(const fr_denoiser *d, int y) {
  const float *z = d->p[P_Z] + at(d, 0, y);
  float *g = d->p[P_ZG] + at(d, 0, y);
  const ptrdiff_t st = (ptrdiff_t)d->stride;
  for (int x = 0; x < d->width; x++) {
    const float c = z[x];
    const float gx = minf(absf(z[x - 1] - c), absf(z[x + 1] - c));
    const float gy = minf(absf(z[x - st] - c), absf(z[x + st] - c));
    const float ax = gx < 1e28f ? gx : 0.0f, ay = gy < 1e28f ? gy : 0.0f;
    g[x] = c < 1e29f ? maxf(ax, ay) : 0.0f;
  }
}

void fr_denoise(fr_denoiser *d, const float *rgb, const float *albedo, const float *normal, const float *depth, int spp,
                int threads, float *out) {
  const int W = d->width, H = d->height;
  float **p = d->p;
  const denoise_kernels *k = kernels_of(fr_get_isa());
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < H; y++) {
    const size_t i = (size_t)y * W;
    split_row(d, k, rgb + 3 * i, albedo + 3 * i, normal + 3 * i, depth + i, y);
  }
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < H; y++) depth_gradient_row(d, y);
  /* luminance is trusted more as samples add up: noise falls as 1/sqrt(spp) */
  const float sigma_l0 = 4.0f / sqrtf((float)(spp > 1 ? spp : 1));
  /* the frame's mean illumination (rows summed in order: the same bits on
   * any number of threads) */
  double lum = 0.0, hits = 0.0;
  for (int y = 0; y < H; y++) lum += d->row_lum[y], hits += d->row_hits[y];
  const float mean = hits > 0.0 ? (float)(lum / hits) : 0.0f;
  /* a pixel with no light at all is likely at one sample and rare at many:
   * the mean's help falls as 1/spp */
  const float lum_floor = mean / (float)(spp > 1 ? spp : 1);
  float *src[3] = {p[P_IN0], p[P_IN1], p[P_IN2]}, *dst[3] = {p[P_TMP0], p[P_TMP1], p[P_TMP2]};
  for (int level = 0; level < FR_DENOISE_LEVELS; level++) {
    fr_atrous_level L = {{src[0], src[1], src[2]}, {dst[0], dst[1], dst[2]}, {d->nrm[0], d->nrm[1], d->nrm[2]},
                         p[P_Z], p[P_ZG], d->stride, d->row, 1 << level, sigma_l0 / (float)(1 << level), 2.0f, lum_floor};
    const int chunk = 8;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int y0 = 0; y0 < H; y0 += chunk) k->atrous_rows(&L, y0, y0 + chunk < H ? y0 + chunk : H);
    for (int c = 0; c < 3; c++) { float *t = src[c]; src[c] = dst[c]; dst[c] = t; }
  }
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < H; y++) {
    const size_t o = at(d, 0, y), i = 3 * (size_t)y * W;
    k->merge(src[0] + o, src[1] + o, src[2] + o, p[P_Z] + o, albedo + i, W, out + i);
  }
}
