/* fr_child_sort8 compiled for one ISA (FR_BUILD_ISA_AVX2 or _AVX512), called
 * by test_kernels through a plain-C signature. */
#include "trace/wide/child_sort8.h"

#define NAME2(isa) fr_test_child_sort8_##isa
#define NAME(isa) NAME2(isa)
uint32_t NAME(FR_ISA_SUFFIX)(const uint32_t *child, int mask, const float *dist, void *out);
uint32_t NAME(FR_ISA_SUFFIX)(const uint32_t *child, int mask, const float *dist, void *out) {
  return fr_child_sort8(child, mask, _mm256_loadu_ps(dist), out);
}
