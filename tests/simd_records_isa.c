/* The transposing record loads of base/simd_packet.h compiled for one ISA
 * (16 lanes), called by test_kernels through a plain-C signature: out8[k]
 * gets field k of the first n records `stride` floats apart at src, or of
 * records idx[0..n) where idx is not NULL (lanes past n: the n-th);
 * without idx, out4[k] gets field k of 16 records of 4 floats and back4
 * those 16 records stored again from out4's fields. */
#define FR_PACKET 16
#include "base/simd_packet.h"

#define NAME2(isa) fr_test_load_records_##isa
#define NAME(isa) NAME2(isa)
void NAME(FR_ISA_SUFFIX)(const float *src, size_t stride, const uint32_t *idx, int n, float (*out8)[16], float (*out4)[16],
                        float *back4);
void NAME(FR_ISA_SUFFIX)(const float *src, size_t stride, const uint32_t *idx, int n, float (*out8)[16], float (*out4)[16],
                        float *back4) {
  float R[16] __attribute__((aligned(64)));
  vpf f[8];
  if (idx) vp_load_records8_at(src, stride, idx, n, f);
  else vp_load_records8_rows(src, stride, n, f);
  for (int k = 0; k < 8; k++) {
    vp_store(R, f[k]);
    memcpy(out8[k], R, sizeof R);
  }
  if (n < 16 || idx) return; /* the 4-float records read all 16 */
  vp_load_records4(src, f);
  for (int k = 0; k < 4; k++) {
    vp_store(R, f[k]);
    memcpy(out4[k], R, sizeof R);
  }
  float B[64];
  vp_store_records4(B, f);
  memcpy(back4, B, sizeof B);
}
