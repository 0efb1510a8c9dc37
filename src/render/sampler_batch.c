/*
 * Sample points for many paths at once (render/sampler.h), compiled once
 * per ISA: fr_sample2d's own arithmetic lane by lane, which the compiler
 * turns into vector code (byte swaps as shuffles, the tables as gathers),
 * so the points are the same bits as one at a time.
 */
#include "base/simd.h"
#include "render/sampler.h"

void FR_ISA_FN(fr_sobol2d_batch)(const uint32_t *restrict keys, const uint32_t *restrict index, uint32_t dim, size_t n,
                                 float *restrict u1, float *restrict u2) {
  for (size_t i = 0; i < n; i++) fr_sample2d(FR_SAMPLER_SOBOL, keys[i], index[i], 0, dim, &u1[i], &u2[i]);
}

/* n_spp a power of two (> 1): the shuffle is one step of its bijection */
void FR_ISA_FN(fr_hammersley2d_pow2_batch)(const uint32_t *restrict keys, const uint32_t *restrict index, uint32_t n_spp,
                                           uint32_t dim, size_t n, float *restrict u1, float *restrict u2) {
  const unsigned bits = 32u - (unsigned)__builtin_clz(n_spp - 1);
  for (size_t i = 0; i < n; i++) {
    const uint32_t key = fr_sampler_pair_key(keys[i], dim);
    fr_hammersley_point(fr_sampler_permute_step(index[i], bits, key), n_spp, key, &u1[i], &u2[i]);
  }
}
