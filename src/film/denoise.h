/*
 * The denoiser of progressive images (path, ao, softshadow): colour is
 * divided by the albedo, filtered by FR_DENOISE_LEVELS levels of the
 * edge-avoiding à-trous wavelet filter guided by normal, depth and
 * luminance (film/atrous.h), and multiplied back, so texture and material
 * edges stay sharp whatever the filter does to the light.
 */
#ifndef FR_FILM_DENOISE_H
#define FR_FILM_DENOISE_H
#include "frusta.h"

#define FR_DENOISE_LEVELS 5

typedef struct fr_denoiser fr_denoiser;

/* A denoiser for width x height images; FR_ERR_ARG for a bad size,
 * FR_ERR_NOMEM without memory. Not thread-safe: one caller at a time. */
fr_error fr_denoiser_new(int width, int height, fr_denoiser **d);
void fr_denoiser_free(fr_denoiser *d);

/* out (W*H*3) from rgb (W*H*3 linear), guided by albedo (W*H*3), normal
 * (W*H*3, facing the camera; averaged normals are renormalized) and depth
 * (W*H, FR_DEPTH_MISS where the camera sees the background, whose pixels
 * are copied); colour that is not finite comes out 0, and no pixel comes
 * out NaN whatever the guides hold. spp, the samples per pixel behind rgb,
 * sets how far luminance differences are trusted. out may be rgb. Runs on
 * threads threads (OpenMP). */
void fr_denoise(fr_denoiser *d, const float *rgb, const float *albedo, const float *normal, const float *depth, int spp,
                int threads, float *out);
#endif
