#include "mft.h"
#include "trace/kernels.h"

void fr_mft_set_finish(fr_mft_sets *t, int s) {
  fr_mft_set *S = &t->set[s];
  for (int k = 0; k < FR_MFT_RAYS; k++) {
    S->dx[k] = S->a[k] * t->e1[0] + S->b[k] * t->e2[0];
    S->dy[k] = S->a[k] * t->e1[1] + S->b[k] * t->e2[1];
    S->dz[k] = S->a[k] * t->e1[2] + S->b[k] * t->e2[2];
  }
}

const fr_mft_fns *fr_mft_active(void) {
  switch (fr_kernels_active()->isa) {
  case FR_ISA_AVX512: return &fr_mft_avx512;
  case FR_ISA_AVX2: return &fr_mft_avx2;
  default: return &fr_mft_scalar;
  }
}
