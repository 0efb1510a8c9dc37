#include "render/sampler.h"
#include <string.h>

static const char *const names[FR_SAMPLER_COUNT] = {"hammersley", "sobol"};
const char *fr_sampler_name(fr_sampler_kind k) { return k < FR_SAMPLER_COUNT ? names[k] : "?"; }
int fr_sampler_parse(const char *name, fr_sampler_kind *k) {
  for (int i = 0; i < FR_SAMPLER_COUNT; i++)
    if (!strcmp(name, names[i])) { *k = (fr_sampler_kind)i; return 1; }
  return 0;
}

static uint32_t mix(uint32_t h) {
  h ^= h >> 16; h *= 0x21f0aaadu; h ^= h >> 15; h *= 0x735a2d97u; h ^= h >> 15;
  return h;
}
uint32_t fr_sampler_pixel_key(uint32_t seed, uint32_t pixel) { return mix(seed ^ mix(pixel + 0x9e3779b9u)); }
static uint32_t reverse(uint32_t x) {
  x = __builtin_bswap32(x); /* the bytes, then the bits within each */
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  return ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
}
static float to_unit(uint32_t x) { return (float)(x >> 8) * (1.0f / 16777216.0f); }

/* A bijection of [0, n) keyed by key: a bijection of the enclosing power of
 * two (xor, odd multiply and xorshift, each invertible modulo it), walked
 * until it lands below n. */
static uint32_t permute(uint32_t i, uint32_t n, uint32_t key) {
  if (n <= 1) return 0;
  const unsigned bits = 32u - (unsigned)__builtin_clz(n - 1);
  const uint32_t mask = bits >= 32 ? 0xffffffffu : (1u << bits) - 1u;
  const unsigned sh = bits / 2u + 1u;
  do {
    i = (i ^ key) & mask;
    i = (i * 0x2c1b3c6du) & mask;
    i ^= i >> sh;
    i = (i * 0x297a2d39u) & mask;
    i ^= (i >> 3) & mask;
    i = (i + (key >> 7)) & mask;
  } while (i >= n);
  return i;
}

/* Owen scrambling of a base-2 fraction by a Laine-Karras style hash
 * (bit k's flip depends on the bits above it only), of x given with its
 * bits reversed: owen(x) = reverse(owen_reversed(reverse(x))). */
static uint32_t owen_reversed(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}
static uint32_t owen(uint32_t x, uint32_t seed) { return reverse(owen_reversed(reverse(x), seed)); }

/* Sobol's second dimension: direction numbers of the polynomial x + 1,
 * v_0 = 2^31 and v_{k+1} = v_k ^ (v_k >> 1), the xor of v_k over the set
 * bits k of i. It is linear in i, so four tables of a byte each give it:
 * the scrambled indices it takes have all 32 bits, where a loop over the
 * bits took a quarter of a viewer's path frame. */
static uint32_t sobol1_bytes[4][256];

__attribute__((constructor)) static void sobol1_tables(void) {
  uint32_t v[32];
  v[0] = 1u << 31;
  for (int k = 1; k < 32; k++) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
  for (int b = 0; b < 4; b++)
    for (uint32_t x = 0; x < 256; x++) {
      uint32_t r = 0;
      for (int k = 0; k < 8; k++)
        if ((x >> k) & 1) r ^= v[8 * b + k];
      sobol1_bytes[b][x] = r;
    }
}

static uint32_t sobol1(uint32_t i) {
  return sobol1_bytes[0][i & 255u] ^ sobol1_bytes[1][(i >> 8) & 255u] ^ sobol1_bytes[2][(i >> 16) & 255u] ^
         sobol1_bytes[3][i >> 24];
}

void fr_sample2d(fr_sampler_kind k, uint32_t pixel_key, uint32_t i, uint32_t n, uint32_t d, float *u1, float *u2) {
  const uint32_t key = mix(pixel_key + d * 0x51ed2705u);
  if (k == FR_SAMPLER_SOBOL) {
    const uint32_t j = owen(i, key);
    *u1 = to_unit(reverse(owen_reversed(j, mix(key ^ 0x68e31da4u)))); /* owen(reverse(j), ...) */
    *u2 = to_unit(owen(sobol1(j), mix(key ^ 0xb5297a4du)));
    return;
  }
  const uint32_t j = permute(i, n, key);
  /* (j + r) / n with one random offset r per pattern, and the radical
   * inverse with its bits flipped by a random mask: both keep the
   * pattern's strata */
  const float r = to_unit(mix(key ^ 0x1b56c4e9u));
  float x = ((float)j + r) / (float)n;
  *u1 = x < 1.0f ? x : 0.99999994f;
  *u2 = to_unit(reverse(j) ^ mix(key ^ 0x7f4a7c15u));
}
