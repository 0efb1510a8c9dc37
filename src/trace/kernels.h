/* The table of per-ISA kernels and the run-time choice between them. */
#ifndef FR_TRACE_KERNELS_H
#define FR_TRACE_KERNELS_H
#include <stddef.h>
#include <stdint.h>
#include "accel/bvhn.h"
#include "frusta.h"

/* Single-ray kernels for one BVH width. */
typedef struct fr_trace_fns {
  void (*intersect1)(const fr_bvhn *b, const fr_ray *ray, fr_hit *hit);
  int (*occluded1)(const fr_bvhn *b, const fr_ray *ray);
  void (*intersect_stream)(const fr_bvhn *b, const fr_ray *rays, fr_hit *hits, size_t n);
  void (*occluded_stream)(const fr_bvhn *b, const fr_ray *rays, uint8_t *occ, size_t n);
} fr_trace_fns;

typedef struct fr_kernels {
  fr_isa isa;
  const fr_trace_fns *w4, *w8;
} fr_kernels;

extern const fr_trace_fns fr_trace_w4_avx512, fr_trace_w4_avx2, fr_trace_w4_scalar;
extern const fr_trace_fns fr_trace_w8_avx512, fr_trace_w8_avx2, fr_trace_w8_scalar;

/* The kernels in use: the best the CPU has, unless FRUSTA_ISA or fr_set_isa
 * chose another. */
const fr_kernels *fr_kernels_active(void);

/* Shared by the kernels and the reference path: the hit of a miss. */
static inline void fr_hit_miss(fr_hit *h) {
  h->t = __builtin_inff();
  h->u = h->v = 0.0f;
  h->prim = FR_INVALID_ID;
  h->ng[0] = h->ng[1] = h->ng[2] = 0.0f;
}

/* Rays that cannot hit anything: NaN or Inf in origin or direction, a zero
 * direction, NaN in tnear/tfar, or tnear > tfar. */
static inline int fr_ray_invalid(const fr_ray *r) {
  int bad = !(r->tnear <= r->tfar) || (r->dir[0] == 0.0f && r->dir[1] == 0.0f && r->dir[2] == 0.0f);
  for (int i = 0; i < 3; i++)
    bad |= !(__builtin_fabsf(r->org[i]) < __builtin_inff()) || !(__builtin_fabsf(r->dir[i]) < __builtin_inff());
  return bad;
}
#endif
