#include "mft.h"
#include "trace/kernels.h"

void fr_mft_set_finish(fr_mft_sets *t, int s) {
  fr_mft_set *S = &t->set[s];
  for (int k = 0; k < FR_MFT_RAYS; k++) {
    S->dx[k] = S->a[k] * t->e1[0] + S->b[k] * t->e2[0];
    S->dy[k] = S->a[k] * t->e1[1] + S->b[k] * t->e2[1];
    S->dz[k] = S->a[k] * t->e1[2] + S->b[k] * t->e2[2];
  }
  S->amin = S->amax = S->a[0];
  S->bmin = S->bmax = S->b[0];
  const float *d[3] = {S->dx, S->dy, S->dz};
  for (int a = 0; a < 3; a++) S->lo[a] = S->hi[a] = d[a][0];
  for (int k = 1; k < FR_MFT_RAYS; k++) {
    if (S->a[k] < S->amin) S->amin = S->a[k];
    if (S->a[k] > S->amax) S->amax = S->a[k];
    if (S->b[k] < S->bmin) S->bmin = S->b[k];
    if (S->b[k] > S->bmax) S->bmax = S->b[k];
    for (int a = 0; a < 3; a++) {
      if (d[a][k] < S->lo[a]) S->lo[a] = d[a][k];
      if (d[a][k] > S->hi[a]) S->hi[a] = d[a][k];
    }
  }
}

/* The corner-ray cull of a triangle costs about as much as two or three
 * frusta's 16-ray tests, all 16 lanes at once: it pays where many frusta
 * reach a triangle and most miss it (conference primary: 8.8 frusta per
 * triangle, 78% culled), not where one or two do and most hit (dragon
 * primary: 1.6, 28%). */
#define FR_MFT_CORNER_COST 2.5f

fr_mft_opts fr_mft_opts_default(void) {
  fr_mft_opts o = {1, FR_MFT_SHRINK_ALL, FR_MFT_CORNER_COST};
  return o;
}

const fr_mft_fns *fr_mft_active(void) {
  switch (fr_kernels_active()->isa) {
  case FR_ISA_AVX512: return &fr_mft_avx512;
  case FR_ISA_AVX2: return &fr_mft_avx2;
  default: return &fr_mft_scalar;
  }
}
