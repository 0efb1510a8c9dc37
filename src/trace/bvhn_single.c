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

/* A ray's occlusion where no traversal is needed: 0 for an invalid ray, 1
 * where a planar occluder blocks it; else -1, with *r set up. */
static inline int occluded_before(const fr_bvhn *b, const fr_ray *ray, ray_pre *r) {
  FR_COUNT(rays, 1);
  if (fr_ray_invalid(ray)) return 0;
  if (b->planes && fr_plane_occluders_hit(b->planes, ray->org, ray->dir, ray->tnear, ray->tfar)) return 1;
  ray_setup(r, ray);
  return -1;
}

static int occluded1(const fr_bvhn *b, const fr_ray *ray) {
  ray_pre r;
  const int known = occluded_before(b, ray, &r);
  return known >= 0 ? known : any_hit(b, &r, b->root, ray->tfar) != 0;
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
 * Where the block seldom occludes the next ray (dragon soft16: 1% of its
 * tries hit, 0.980x when every ray tried), the stream's first CACHE_PROBE
 * tries decide: fewer than one in CACHE_MIN_RATE hitting turns the cache
 * off for the rest of the stream, or of its CACHE_PERIOD rays when it is
 * longer (the workloads pass a tile's rays, up to 4,096, as one stream).
 * Pausing after each failing window of 64 tries instead kept dragon at
 * 0.994x but cut the hairball's gain to 1.018x: its hits come in bursts,
 * pixel by pixel, after stretches of misses.
 * Interleaved pairs, 2 threads, 1024x1024, single rays, on against off (3
 * pairs each, docs/performance-log.md): conference soft16 1.234x, shadow
 * 1.095x, sibenik soft16 1.149x, hairball soft16 1.046x, shadow 1.061x,
 * kitchen soft16 1.031x, shadow 1.029x, dragon soft16 1.011x, shadow
 * 0.991x. */
#define CACHE_PROBE 64u
#define CACHE_MIN_RATE 16u
#define CACHE_PERIOD 4096u

static void occluded_stream(const fr_bvhn *b, const fr_ray *rays, uint8_t *occ, size_t n, int cache) {
  uint32_t last = 0; /* 1 + the block that occluded the last ray the traversal found occluded */
  unsigned tries = 0, hits = 0;
  const int wanted = cache;
  for (size_t i = 0; i < n; i++) {
    const fr_ray *ray = &rays[i];
    if (i % CACHE_PERIOD == 0) cache = wanted, tries = hits = 0; /* a long stream decides again */
    ray_pre r;
    const int known = occluded_before(b, ray, &r);
    if (known >= 0) {
      occ[i] = (uint8_t)known;
      continue;
    }
    if (last && ray->tfar < INFINITY) {
      tri4_result res;
      tri4_test(&b->tris[last - 1], &r, ray->tfar, &res);
      FR_COUNT(cache_tries, 1);
      const unsigned hit = res.mask != 0;
      FR_COUNT(cache_hits, hit);
      hits += hit;
      /* the first CACHE_PROBE tries decide for the rest of the period */
      if (++tries == CACHE_PROBE && hits * CACHE_MIN_RATE < tries) cache = 0, last = 0;
      if (hit) {
        occ[i] = 1;
        continue;
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
