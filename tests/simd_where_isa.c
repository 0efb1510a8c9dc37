/* The masked adds of base/simd.h compiled for one ISA, called by
 * test_kernels through a plain-C signature: out8 = a + b in the lanes set in
 * `lanes`, a in the others, for eight lanes and for the first four. */
#include "base/simd.h"

#define NAME2(isa) fr_test_add_where_##isa
#define NAME(isa) NAME2(isa)
void NAME(FR_ISA_SUFFIX)(const float *a, int lanes, const float *b, float *out8, float *out4);
void NAME(FR_ISA_SUFFIX)(const float *a, int lanes, const float *b, float *out8, float *out4) {
  float A[8] __attribute__((aligned(32))), B[8] __attribute__((aligned(32))), R[8] __attribute__((aligned(32)));
  for (int i = 0; i < 8; i++) { A[i] = a[i]; B[i] = b[i]; }
  vf8_store(R, vf8_add_where(vf8_load(A), lanes, vf8_load(B)));
  for (int i = 0; i < 8; i++) out8[i] = R[i];
  vf4_store(R, vf4_add_where(vf4_load(A), lanes & 0xF, vf4_load(B)));
  for (int i = 0; i < 4; i++) out4[i] = R[i];
}
