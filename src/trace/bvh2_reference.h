/* Plain scalar traversal of the binary BVH: the reference the SIMD kernels are
 * tested against. Clarity over speed. */
#ifndef FR_TRACE_BVH2_REFERENCE_H
#define FR_TRACE_BVH2_REFERENCE_H
#include <math.h>
#include "accel/bvh2.h"
#include "geom/mesh.h"
#include "trace/kernels.h"

/* The reference walk's box test of child k of n: the slab test with the
 * exit widened by 2^-20, so that rounding never drops a box a hit lies in
 * (also the all-hits walk's, trace/all_hits.c). rd: the direction's
 * reciprocal as fr_bvh2_rcp makes it. */
static inline int fr_bvh2_box_hit(const fr_bvh2_node *n, int k, const float o[3], const float rd[3], float tnear,
                                  float tfar) {
  const float lo[3] = {n->lo_x[k], n->lo_y[k], n->lo_z[k]}, hi[3] = {n->hi_x[k], n->hi_y[k], n->hi_z[k]};
  float tn = tnear, tf = tfar;
  for (int a = 0; a < 3; a++) {
    float t0 = (lo[a] - o[a]) * rd[a], t1 = (hi[a] - o[a]) * rd[a];
    if (rd[a] < 0.0f) { float t = t0; t0 = t1; t1 = t; }
    tn = t0 > tn ? t0 : tn;
    tf = t1 < tf ? t1 : tf;
  }
  return tn <= fr_widen_exit(tf);
}

/* 1 / d, a zero (or tiny) component taken as +-1e-18 so the slabs stay finite. */
static inline float fr_bvh2_rcp(float d) { return 1.0f / (fabsf(d) < 1e-18f ? copysignf(1e-18f, d) : d); }

void fr_bvh2_intersect_reference(const fr_bvh2 *b, const fr_mesh *m, const fr_ray *ray, fr_hit *hit);
int fr_bvh2_occluded_reference(const fr_bvh2 *b, const fr_mesh *m, const fr_ray *ray);
#endif
