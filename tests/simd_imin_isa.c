/* The integer-order min and max of base/simd.h compiled for one ISA, called
 * by test_kernels through a plain-C signature: min8/max8 of eight lanes,
 * min4/max4 of the first four. */
#include "base/simd.h"

#define NAME2(isa) fr_test_imin_imax_##isa
#define NAME(isa) NAME2(isa)
void NAME(FR_ISA_SUFFIX)(const float *a, const float *b, float *min8, float *max8, float *min4, float *max4);
void NAME(FR_ISA_SUFFIX)(const float *a, const float *b, float *min8, float *max8, float *min4, float *max4) {
  float A[8] __attribute__((aligned(32))), B[8] __attribute__((aligned(32))), R[8] __attribute__((aligned(32)));
  for (int i = 0; i < 8; i++) { A[i] = a[i]; B[i] = b[i]; }
  vf8_store(R, vf8_imin(vf8_load(A), vf8_load(B)));
  for (int i = 0; i < 8; i++) min8[i] = R[i];
  vf8_store(R, vf8_imax(vf8_load(A), vf8_load(B)));
  for (int i = 0; i < 8; i++) max8[i] = R[i];
  vf4_store(R, vf4_imin(vf4_load(A), vf4_load(B)));
  for (int i = 0; i < 4; i++) min4[i] = R[i];
  vf4_store(R, vf4_imax(vf4_load(A), vf4_load(B)));
  for (int i = 0; i < 4; i++) max4[i] = R[i];
}
