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
  return any_hit(b, &r, b->root, ray->tfar) != 0;
}

static int occluded_subtree(const fr_bvhn *b, uint32_t ref, const fr_ray *ray) {
  ray_pre r;
  ray_setup(&r, ray);
  return any_hit(b, &r, ref, ray->tfar) != 0;
}

static void intersect_stream(const fr_bvhn *b, const fr_ray *rays, fr_hit *hits, size_t n) {
  for (size_t i = 0; i < n; i++) intersect1(b, &rays[i], &hits[i]);
}

/* The occluder cache (fr_trace_options.occluder_cache): consecutive shadow
 * rays of a stream mostly start near one another and end at the same light,
 * so the block that occluded one often occludes the next. A ray that ends
 * (finite tfar) tests that block before it traverses; a hit is a true
 * answer (the traversal's own test, on a block whose box the conservative
 * box tests would have entered), a miss costs one block test. Rays without
 * an end (ambient occlusion, bounces) spread over the hemisphere: kitchen
 * ao16 hit 28% of its tries but ran 0.956x, as its traversals are short.
 * Where it stops paying, fewer than one in CACHE_MIN_RATE of a window of
 * CACHE_WINDOW tries hitting (dragon soft16: 1% of its tries hit, 0.980x
 * without this rule), the stream stops trying for CACHE_PAUSE rays.
 * Interleaved pairs, 2 threads, 1024x1024, single rays, on against off (3
 * pairs each, docs/performance-log.md): conference soft16 1.235x, shadow
 * 1.073x, sibenik soft16 1.148x, hairball soft16 1.077x, shadow 1.055x,
 * kitchen soft16 1.020x, dragon soft16 0.990x (its pauses' windows). Doubling
 * the pause after each failed window in a row brought dragon to 0.996x but
 * cost the hairball, whose windows fail now and then, most of its gain. */
#define CACHE_WINDOW 64u
#define CACHE_MIN_RATE 16u
#define CACHE_PAUSE 1024u

static void occluded_stream(const fr_bvhn *b, const fr_ray *rays, uint8_t *occ, size_t n, int cache) {
  uint32_t last = 0; /* 1 + the block that occluded the last ray the traversal found occluded */
  unsigned tries = 0, hits = 0;
  size_t resume = 0;
  for (size_t i = 0; i < n; i++) {
    const fr_ray *ray = &rays[i];
    FR_COUNT(rays, 1);
    occ[i] = 0;
    if (fr_ray_invalid(ray)) continue;
    if (b->planes && fr_plane_occluders_hit(b->planes, ray->org, ray->dir, ray->tnear, ray->tfar)) {
      occ[i] = 1;
      continue;
    }
    ray_pre r;
    ray_setup(&r, ray);
    if (last && ray->tfar < INFINITY && i >= resume) {
      tri4_result res;
      FR_COUNT(cache_tries, 1);
      tri4_test(&b->tris[last - 1], &r, ray->tfar, &res);
      tries++;
      if (res.mask) {
        FR_COUNT(cache_hits, 1);
        occ[i] = 1;
        hits++;
        continue;
      }
      if (tries == CACHE_WINDOW) {
        if (hits * CACHE_MIN_RATE < tries) resume = i + CACHE_PAUSE;
        tries = hits = 0;
      }
    }
    const uint32_t k = any_hit(b, &r, b->root, ray->tfar);
    occ[i] = k != 0;
    if (k && cache) last = k;
  }
}

#define TRACE_NAME2(w, isa) fr_trace_w##w##_##isa
#define TRACE_NAME(w, isa) TRACE_NAME2(w, isa)
#define TRACE_FNS TRACE_NAME(FR_WIDTH, FR_ISA_SUFFIX)
const fr_trace_fns TRACE_FNS = {intersect1, occluded1, intersect_stream, occluded_stream, intersect_subtree,
                                occluded_subtree};
