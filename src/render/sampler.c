#include "render/sampler.h"
#include <string.h>
#include "frusta.h"

static const char *const names[FR_SAMPLER_COUNT] = {"hammersley", "sobol"};
const char *fr_sampler_name(fr_sampler_kind k) { return k < FR_SAMPLER_COUNT ? names[k] : "?"; }
int fr_sampler_parse(const char *name, fr_sampler_kind *k) {
  for (int i = 0; i < FR_SAMPLER_COUNT; i++)
    if (!strcmp(name, names[i])) { *k = (fr_sampler_kind)i; return 1; }
  return 0;
}

/* Sobol's second dimension: direction numbers of the polynomial x + 1,
 * v_0 = 2^31 and v_{k+1} = v_k ^ (v_k >> 1), the xor of v_k over the set
 * bits k of the index. Byte b of reverse(j) holds bits 31 - 8b - t of j
 * (t = 0..7), so its table xors their reversed direction numbers. */
uint32_t fr_sampler_rsobol1_bytes[4][256];

__attribute__((constructor)) static void sobol1_tables(void) {
  uint32_t v[32];
  v[0] = 1u << 31;
  for (int k = 1; k < 32; k++) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
  for (int b = 0; b < 4; b++)
    for (uint32_t x = 0; x < 256; x++) {
      uint32_t r = 0;
      for (int t = 0; t < 8; t++)
        if ((x >> t) & 1) r ^= fr_sampler_reverse(v[31 - 8 * b - t]);
      fr_sampler_rsobol1_bytes[b][x] = r;
    }
}

void fr_sample2d_batch(fr_sampler_kind k, const uint32_t *keys, const uint32_t *index, uint32_t n_spp, uint32_t d,
                       size_t n, float *u1, float *u2) {
  if (!fr_sampler_batches(k, n_spp)) {
    for (size_t i = 0; i < n; i++) fr_sample2d(k, keys[i], index[i], n_spp, d, &u1[i], &u2[i]);
    return;
  }
  const fr_isa isa = fr_get_isa();
  if (k == FR_SAMPLER_SOBOL) {
    if (isa == FR_ISA_AVX512) fr_sobol2d_batch_avx512(keys, index, d, n, u1, u2);
    else if (isa == FR_ISA_AVX2) fr_sobol2d_batch_avx2(keys, index, d, n, u1, u2);
    else fr_sobol2d_batch_scalar(keys, index, d, n, u1, u2);
  } else {
    if (isa == FR_ISA_AVX512) fr_hammersley2d_pow2_batch_avx512(keys, index, n_spp, d, n, u1, u2);
    else if (isa == FR_ISA_AVX2) fr_hammersley2d_pow2_batch_avx2(keys, index, n_spp, d, n, u1, u2);
    else fr_hammersley2d_pow2_batch_scalar(keys, index, n_spp, d, n, u1, u2);
  }
}
