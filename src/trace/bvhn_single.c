/*
 * Single-ray traversal of an N-wide BVH (Benthin et al., MIC paper §IV, with
 * N = 4 as there or N = 8): one ray, all N child boxes in one SIMD test,
 * nearest child first for closest hits, and four triangles per SIMD test in the leaves
 * (watertight, see geom/tri_watertight.h). Compiled once per ISA and width
 * (FR_WIDTH) through base/simd.h.
 */
#include "base/simd.h"
#include "accel/plane_occluders.h"
#include "trace/bvhn_single.h"
#include "trace/kernels.h"

static __attribute__((noinline)) int intersect_subtree(const fr_bvhn *b, uint32_t ref, const fr_ray *ray, fr_subtree_hit *best) {
  ray_pre r;
  ray_setup(&r, ray);
  return closest(b, &r, ref, ray->tfar, best);
}

static void intersect1(const fr_bvhn *b, const fr_ray *ray, fr_hit *hit) {
  fr_hit_miss(hit);
  FR_COUNT(rays, 1);
  if (fr_ray_invalid(ray)) return;
  fr_subtree_hit best = {0.0f, 0.0f, 0.0f, 0};
  if (intersect_subtree(b, b->root, ray, &best))
    fr_hit_finish(b, &best, v3_load(ray->org), v3_load(ray->dir), ray->tnear, ray->tfar, hit);
}

static int occluded1(const fr_bvhn *b, const fr_ray *ray) {
  FR_COUNT(rays, 1);
  if (fr_ray_invalid(ray)) return 0;
  if (b->planes && fr_plane_occluders_hit(b->planes, ray->org, ray->dir, ray->tnear, ray->tfar)) return 1;
  ray_pre r;
  ray_setup(&r, ray);
  return any_hit(b, &r, b->root, ray->tfar);
}

static int occluded_subtree(const fr_bvhn *b, uint32_t ref, const fr_ray *ray) {
  ray_pre r;
  ray_setup(&r, ray);
  return any_hit(b, &r, ref, ray->tfar);
}

static void intersect_stream(const fr_bvhn *b, const fr_ray *rays, fr_hit *hits, size_t n) {
  for (size_t i = 0; i < n; i++) intersect1(b, &rays[i], &hits[i]);
}

static void occluded_stream(const fr_bvhn *b, const fr_ray *rays, uint8_t *occ, size_t n) {
  for (size_t i = 0; i < n; i++) occ[i] = (uint8_t)occluded1(b, &rays[i]);
}

#define TRACE_NAME2(w, isa) fr_trace_w##w##_##isa
#define TRACE_NAME(w, isa) TRACE_NAME2(w, isa)
#define TRACE_FNS TRACE_NAME(FR_WIDTH, FR_ISA_SUFFIX)
const fr_trace_fns TRACE_FNS = {intersect1, occluded1, intersect_stream, occluded_stream, intersect_subtree,
                                occluded_subtree};
