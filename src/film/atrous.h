/*
 * One level of the edge-avoiding à-trous wavelet filter (Dammertz et al.,
 * 2010) over padded planes, compiled once per ISA (film/atrous.c). The
 * denoiser (film/denoise.c) runs the levels; this is the inner loop.
 */
#ifndef FR_FILM_ATROUS_H
#define FR_FILM_ATROUS_H
#include <stddef.h>
#include <stdint.h>

#define FR_ATROUS_PAD 16   /* border of every plane: the widest step, so taps never leave the plane */
#define FR_ATROUS_LANES 16 /* pixels per vector; a row's length is padded to a multiple */
#define FR_ATROUS_NORMAL_ONE 32767.0f /* a unit normal's component of 1 in the 16-bit normal planes */

typedef struct fr_atrous_level {
  /* planes of the same padded layout: element (x, y) of the image at
   * plane[(y + PAD) * stride + x + PAD] */
  const float *in[3];  /* illumination (colour divided by albedo) */
  float *out[3];
  const int16_t *nrm[3]; /* unit normals times FR_ATROUS_NORMAL_ONE; 0 in the border (16 bits: the
                           filter's levels are bound by memory traffic) */
  const float *z;      /* depth; FR_DEPTH_MISS where the camera sees the background and in the border */
  const float *zgrad;  /* depth change per pixel step */
  size_t stride;       /* a multiple of FR_ATROUS_LANES; planes 64-byte aligned, so each row's vectors are */
  int width;           /* pixels per row to filter (a multiple of FR_ATROUS_LANES) */
  int step;            /* 1, 2, 4, ...: the distance between taps */
  float sigma_l;       /* relative luminance difference that stops blending */
  float sigma_z;       /* depth difference, in units of the expected change, that stops blending */
  float lum_floor;     /* added to each pixel's luminance where sigma_l scales it: a black pixel may blend */
} fr_atrous_level;

/* Rows [y0, y1) of one level: each pixel that sees geometry becomes the
 * weighted mean of its 3x3 taps step apart; background pixels are copied. */
void fr_atrous_rows(const fr_atrous_level *L, int y0, int y1);
void fr_atrous_rows_scalar(const fr_atrous_level *L, int y0, int y1);
void fr_atrous_rows_avx2(const fr_atrous_level *L, int y0, int y1);
void fr_atrous_rows_avx512(const fr_atrous_level *L, int y0, int y1);
#endif
