/* PCG32: small, fast, good enough for sampling; seeded per pixel. */
#ifndef FR_BASE_RNG_H
#define FR_BASE_RNG_H
#include <stdint.h>

typedef struct fr_rng { uint64_t state, inc; } fr_rng;

static inline uint32_t fr_rng_u32(fr_rng *r) {
  uint64_t old = r->state;
  r->state = old * 6364136223846793005ULL + r->inc;
  uint32_t xs = (uint32_t)(((old >> 18u) ^ old) >> 27u);
  uint32_t rot = (uint32_t)(old >> 59u);
  return (xs >> rot) | (xs << ((-rot) & 31));
}
static inline fr_rng fr_rng_seed(uint64_t seed, uint64_t stream) {
  fr_rng r = {0, (stream << 1u) | 1u};
  fr_rng_u32(&r);
  r.state += seed;
  fr_rng_u32(&r);
  return r;
}
/* uniform in [0,1) */
static inline float fr_rng_float(fr_rng *r) { return (float)(fr_rng_u32(r) >> 8) * (1.0f / 16777216.0f); }
#endif
