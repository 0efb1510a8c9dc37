/*
 * Sample points of the path tracer: for pixel p, sample i of n and
 * dimension pair d, a point in [0, 1)^2. Two generators:
 *   - hammersley: padded replication of a scrambled Hammersley pattern of n
 *     points, as in the MIC paper: every dimension pair of every pixel takes
 *     the same n-point pattern, its order shuffled and its bits scrambled
 *     by a hash of (seed, pixel, pair), so pairs do not correlate;
 *   - sobol: the first two Sobol dimensions, Owen-scrambled and shuffled by
 *     hashing (Burley, "Practical Hash-based Owen Scrambling", 2020).
 * Points depend on (seed, pixel, i, n, d) only: the same for any thread,
 * tile order or trace mode.
 */
#ifndef FR_RENDER_SAMPLER_H
#define FR_RENDER_SAMPLER_H
#include <stdint.h>

typedef enum fr_sampler_kind { FR_SAMPLER_HAMMERSLEY, FR_SAMPLER_SOBOL, FR_SAMPLER_COUNT } fr_sampler_kind;

/* A pixel's key, made once per pixel from the seed. */
uint32_t fr_sampler_pixel_key(uint32_t seed, uint32_t pixel);
void fr_sample2d(fr_sampler_kind k, uint32_t pixel_key, uint32_t i, uint32_t n, uint32_t d, float *u1, float *u2);
const char *fr_sampler_name(fr_sampler_kind k);
int fr_sampler_parse(const char *name, fr_sampler_kind *k);
#endif
