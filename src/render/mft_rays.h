/*
 * Ray sets and frusta for the multi-frusta kernels (trace/mft.h): 4x4 pixel
 * blocks of a camera, and interleaved sample sets on a quad light.
 */
#ifndef FR_RENDER_MFT_RAYS_H
#define FR_RENDER_MFT_RAYS_H
#include <stdint.h>
#include "render/camera.h"
#include "trace/mft/mft.h"

/* One set: the 4x4 pixels of a block, ray k = pixel (k % 4, k / 4). */
void fr_mft_sets_camera(fr_mft_sets *t, const fr_camera *c);

/* 16 frusta for the 16x16 pixels at (x0, y0): frustum f is the 4x4 block
 * (f % 4, f / 4); blocks outside the image are left out of valid. */
void fr_mft_batch_camera(fr_mft_batch *b, const fr_camera *c, int x0, int y0);

/* 16 interleaved sample sets on the quad light c + s e1 + q e2 (s, q in
 * [0,1)), made from the first 256 points of the Sobol (0,2)-sequence,
 * scrambled by a random xor per frame (seed): a (0,8,2)-net, so a 4x4 block
 * of pixels, one set each, covers the light with 256 well spread samples
 * (Keller & Heidrich's interleaved sampling). Two ways to deal them out:
 *
 *   SPREAD  set j = points 16j .. 16j+15, itself a (0,4,2)-net: every pixel
 *           sees the whole light, stratified 4x4 (the soft16 workload);
 *   CELLS   set j = the 16 points in cell j of the light's 4x4 grid
 *           (stratified 4x4 within it): each frustum is 1/16 of the light,
 *           and the 4x4 filter gathers the whole light back (the renderer). */
typedef enum fr_light_sets { FR_LIGHT_SETS_SPREAD, FR_LIGHT_SETS_CELLS } fr_light_sets;
void fr_mft_sets_light(fr_mft_sets *t, const float e1[3], const float e2[3], uint64_t seed, fr_light_sets kind);

/* The set pixel (x, y) uses. */
static inline int fr_mft_light_set(int x, int y) { return (y & 3) * 4 + (x & 3); }
#endif
