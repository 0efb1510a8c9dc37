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
 * tile order or trace mode. fr_sample2d is inline: a path takes three or
 * four points per bounce, and inlined their hash chains overlap.
 */
#ifndef FR_RENDER_SAMPLER_H
#define FR_RENDER_SAMPLER_H
#include <stddef.h>
#include <stdint.h>
#include "frusta.h"

typedef fr_render_sampler fr_sampler_kind; /* the public enum (frusta.h) */
#define FR_SAMPLER_COUNT 2

const char *fr_sampler_name(fr_sampler_kind k);
int fr_sampler_parse(const char *name, fr_sampler_kind *k);

static inline uint32_t fr_sampler_mix(uint32_t h) {
  h ^= h >> 16; h *= 0x21f0aaadu; h ^= h >> 15; h *= 0x735a2d97u; h ^= h >> 15;
  return h;
}

/* A pixel's key, made once per pixel from the seed. */
static inline uint32_t fr_sampler_pixel_key(uint32_t seed, uint32_t pixel) {
  return fr_sampler_mix(seed ^ fr_sampler_mix(pixel + 0x9e3779b9u));
}

static inline uint32_t fr_sampler_reverse(uint32_t x) {
  x = __builtin_bswap32(x); /* the bytes, then the bits within each */
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  return ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
}

static inline float fr_sampler_unit(uint32_t x) { return (float)(x >> 8) * (1.0f / 16777216.0f); }

/* One step of a bijection of [0, 2^bits) (bits in 1..32) keyed by key:
 * xor, odd multiply and xorshift, each invertible modulo 2^bits. */
static inline uint32_t fr_sampler_permute_step(uint32_t i, unsigned bits, uint32_t key) {
  const uint32_t mask = bits >= 32 ? 0xffffffffu : (1u << bits) - 1u;
  const unsigned sh = bits / 2u + 1u;
  i = (i ^ key) & mask;
  i = (i * 0x2c1b3c6du) & mask;
  i ^= i >> sh;
  i = (i * 0x297a2d39u) & mask;
  i ^= (i >> 3) & mask;
  return (i + (key >> 7)) & mask;
}

/* A bijection of [0, n) keyed by key: steps over the enclosing power of
 * two, walked until one lands below n (one step when n is a power of two). */
static inline uint32_t fr_sampler_permute(uint32_t i, uint32_t n, uint32_t key) {
  if (n <= 1) return 0;
  const unsigned bits = 32u - (unsigned)__builtin_clz(n - 1);
  do i = fr_sampler_permute_step(i, bits, key);
  while (i >= n);
  return i;
}

/* Owen scrambling of a base-2 fraction by a Laine-Karras style hash
 * (bit k's flip depends on the bits above it only), of x given with its
 * bits reversed: owen(x) = reverse(fr_sampler_owen_reversed(reverse(x))). */
static inline uint32_t fr_sampler_owen_reversed(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

/* Sobol's second dimension is linear in the index's bits, and so is its
 * bit reversal, which the Owen scramble takes: byte tables (sampler.c)
 * give reverse(sobol1(j)) from the bytes of jr = reverse(j), the shuffled
 * index as it comes, so neither is reversed on the way. */
extern uint32_t fr_sampler_rsobol1_bytes[4][256];
static inline uint32_t fr_sampler_rsobol1(uint32_t jr) {
  return fr_sampler_rsobol1_bytes[0][jr & 255u] ^ fr_sampler_rsobol1_bytes[1][(jr >> 8) & 255u] ^
         fr_sampler_rsobol1_bytes[2][(jr >> 16) & 255u] ^ fr_sampler_rsobol1_bytes[3][jr >> 24];
}

/* Point j of n of a scrambled Hammersley pattern keyed by key: (j + r) / n
 * with one random offset r per pattern, and the radical inverse with its
 * bits flipped by a random mask: both keep the pattern's strata. */
static inline void fr_hammersley_point(uint32_t j, uint32_t n, uint32_t key, float *u1, float *u2) {
  const float r = fr_sampler_unit(fr_sampler_mix(key ^ 0x1b56c4e9u));
  float x = ((float)j + r) / (float)n;
  *u1 = x < 1.0f ? x : 0.99999994f;
  *u2 = fr_sampler_unit(fr_sampler_reverse(j) ^ fr_sampler_mix(key ^ 0x7f4a7c15u));
}

/* The key of dimension pair d of a pixel's pattern. */
static inline uint32_t fr_sampler_pair_key(uint32_t pixel_key, uint32_t d) {
  return fr_sampler_mix(pixel_key + d * 0x51ed2705u);
}

static inline __attribute__((always_inline)) void fr_sample2d(fr_sampler_kind k, uint32_t pixel_key, uint32_t i,
                                                             uint32_t n, uint32_t d, float *u1, float *u2) {
  const uint32_t key = fr_sampler_pair_key(pixel_key, d);
  if (k == FR_SAMPLER_SOBOL) {
    /* the shuffled index j = owen(i, key), as its reversal jr */
    const uint32_t jr = fr_sampler_owen_reversed(fr_sampler_reverse(i), key);
    /* owen(reverse(j)) and owen(sobol1(j)) */
    *u1 = fr_sampler_unit(fr_sampler_reverse(
        fr_sampler_owen_reversed(fr_sampler_reverse(jr), fr_sampler_mix(key ^ 0x68e31da4u))));
    *u2 = fr_sampler_unit(
        fr_sampler_reverse(fr_sampler_owen_reversed(fr_sampler_rsobol1(jr), fr_sampler_mix(key ^ 0xb5297a4du))));
    return;
  }
  fr_hammersley_point(fr_sampler_permute(i, n, key), n, key, u1, u2);
}

/* Whether fr_sample2d_batch makes kind k's points of patterns of n_spp as
 * vector code: Sobol's always, Hammersley's where n_spp is a power of two
 * above 1 (its shuffle is then one step; otherwise it walks a loop per
 * point). */
static inline int fr_sampler_batches(fr_sampler_kind k, uint32_t n_spp) {
  return k == FR_SAMPLER_SOBOL || (n_spp > 1 && (n_spp & (n_spp - 1)) == 0);
}

/* fr_sample2d for n paths of one dimension pair d: path i's pixel key
 * keys[i] and sample index[i] (of n_spp) give (u1[i], u2[i]), the same
 * bits; as vector code where fr_sampler_batches (render/sampler_batch.c). */
void fr_sample2d_batch(fr_sampler_kind k, const uint32_t *keys, const uint32_t *index, uint32_t n_spp, uint32_t d,
                       size_t n, float *u1, float *u2);
#define FR_SAMPLER_BATCH_FNS(isa)                                                                                    \
  void fr_sobol2d_batch_##isa(const uint32_t *keys, const uint32_t *index, uint32_t d, size_t n, float *u1, float *u2); \
  void fr_hammersley2d_pow2_batch_##isa(const uint32_t *keys, const uint32_t *index, uint32_t n_spp, uint32_t d, size_t n, \
                                        float *u1, float *u2);
FR_SAMPLER_BATCH_FNS(scalar)
FR_SAMPLER_BATCH_FNS(avx2)
FR_SAMPLER_BATCH_FNS(avx512)
#endif
