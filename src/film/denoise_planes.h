/*
 * A row of an image into the denoiser's planes and back (film/denoise.c
 * drives them), compiled once per ISA (film/denoise_planes.c): plain loops
 * over a row that the compiler turns into vector code, the same bits on
 * every level.
 */
#ifndef FR_FILM_DENOISE_PLANES_H
#define FR_FILM_DENOISE_PLANES_H
#include <stdint.h>

#define FR_DENOISE_ALBEDO_MIN 0.01f /* dividing by less would amplify noise on black surfaces */
#define FR_DENOISE_MISS 1e30f       /* depth of the background in the planes: past 1e29, as the filter tests */

/* fr_denoise_split_ISA: n pixels of rgb, albedo, normal (3 floats each)
 * and depth: illumination (colour over albedo; background pixels keep
 * their colour; non-finite colour as 0, so that no tap spreads NaN) into
 * in0..in2, unit normals (0 for
 * background, times FR_ATROUS_NORMAL_ONE and rounded) into n0..n2, depth (FR_DENOISE_MISS for background) into z.
 * fr_denoise_merge_ISA: n pixels back: illumination s0..s2 times albedo
 * where z sees geometry, the colour itself elsewhere, into out (3 floats
 * each). No two arrays overlap. */
#define FR_DENOISE_PLANES_FNS(isa)                                                                                     \
  void fr_denoise_split_##isa(const float *rgb, const float *albedo, const float *normal, const float *depth, int n,   \
                              float *in0, float *in1, float *in2, int16_t *n0, int16_t *n1, int16_t *n2, float *z);    \
  void fr_denoise_merge_##isa(const float *s0, const float *s1, const float *s2, const float *z, const float *albedo, \
                              int n, float *out);
FR_DENOISE_PLANES_FNS(scalar)
FR_DENOISE_PLANES_FNS(avx2)
FR_DENOISE_PLANES_FNS(avx512)
#endif
