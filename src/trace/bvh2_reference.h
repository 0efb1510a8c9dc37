/* Plain scalar traversal of the binary BVH: the reference the SIMD kernels are
 * tested against. Clarity over speed. */
#ifndef FR_TRACE_BVH2_REFERENCE_H
#define FR_TRACE_BVH2_REFERENCE_H
#include "accel/bvh2.h"
#include "geom/mesh.h"

void fr_bvh2_intersect_reference(const fr_bvh2 *b, const fr_mesh *m, const fr_ray *ray, fr_hit *hit);
int fr_bvh2_occluded_reference(const fr_bvh2 *b, const fr_mesh *m, const fr_ray *ray);
#endif
