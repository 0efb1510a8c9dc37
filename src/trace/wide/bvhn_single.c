/*
 * Single-ray traversal of an N-wide BVH (Benthin et al., MIC paper §IV, with
 * N = 4 as there or N = 8): one ray, all N child boxes in one SIMD test,
 * nearest child first for closest hits, and four triangles per SIMD test in the leaves
 * (watertight, see geom/tri_watertight.h). Compiled once per ISA and width
 * (FR_WIDTH) through base/simd.h.
 */
#include "base/simd.h"
#include "accel/plane_occluders.h"
#include "trace/wide/bvhn_single.h"
#include "trace/kernels.h"
#include "base/timer.h"
#include "trace/wide/anyhit_tune.h"

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

/* The occluder cache (fr_tuning.occluder_cache): consecutive shadow
 * rays of a stream mostly start near one another and end at the same light,
 * so the block that occluded one often occludes the next. A ray that ends
 * (finite tfar) tests that block before it traverses; a hit is a true
 * answer (the traversal's own test, on a block whose box the conservative
 * box tests would have entered), a miss costs one block test. Rays without
 * an end (ambient occlusion, bounces) spread over the hemisphere and do not
 * try it: their traversals are short. Where the block seldom occludes the
 * next ray (dragon soft16: 1% of its tries hit), the stream's first CACHE_PROBE
 * tries decide: fewer than one in CACHE_MIN_RATE hitting turns the cache
 * off for the rest of the stream, or of its CACHE_PERIOD rays when it is
 * longer (the workloads pass a tile's rays, up to 4,096, as one stream).
 * A window that pauses after every failing stretch would cut the
 * hairball's gain: its hits come in bursts, pixel by pixel, after
 * stretches of misses. */
#define CACHE_PROBE 64u
#define CACHE_MIN_RATE 16u
#define CACHE_PERIOD 4096u

/* The occluder cache across a stream. */
typedef struct occ_cache {
  uint32_t last;  /* 1 + the block that occluded the last ray the traversal found occluded */
  unsigned tries, hits;
  int cache, wanted;
} occ_cache;

/* Rays [i0, i1) of a stream, the hit children nearest first or by the
 * slots' occlusion rank (a constant where inlined). */
FR_INLINE void occluded_run(const fr_bvhn *b, const fr_ray *rays, uint8_t *occ, size_t i0, size_t i1, occ_cache *c,
                            int nearest) {
  uint32_t last = c->last;
  unsigned tries = c->tries, hits = c->hits;
  int cache = c->cache;
  for (size_t i = i0; i < i1; i++) {
    const fr_ray *ray = &rays[i];
    if (i % CACHE_PERIOD == 0) cache = c->wanted, tries = hits = 0; /* a long stream decides again */
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
    const uint32_t k = nearest ? any_hit_nearest(b, &r, b->root, ray->tfar) : any_hit(b, &r, b->root, ray->tfar);
    occ[i] = k != 0;
    if (k && cache) last = k;
  }
  c->last = last;
  c->tries = tries;
  c->hits = hits;
  c->cache = cache;
}

/* Out of line, so that the rank order's loop keeps its registers. */
static __attribute__((noinline)) void occluded_run_nearest(const fr_bvhn *b, const fr_ray *rays, uint8_t *occ,
                                                           size_t i0, size_t i1, occ_cache *c) {
  occluded_run(b, rays, occ, i0, i1, c, 1);
}

/* The any-hit order by measurement (trace/anyhit_tune.h). Which children
 * hold a ray's occluder first depends on the scene: among the hairball's
 * strands the nearest, elsewhere the occlusion rank (accel/bvhn.c) finds it
 * in fewer visits, and nearest-first costs kitchen ao16 43% and dragon
 * soft16 16%. So rays with an end (shadow rays) go in chunks of
 * ORDER_CHUNK, each walked by the order the thread's probes price lower.
 * Rays without one (ambient occlusion, bounces) keep the rank: there a
 * tuner costs more than it finds. Every order gives the same answers. */
#define ORDER_CHUNK 32u

static _Thread_local fr_anyhit_tune order_tune;

/* A probe: rays [i0, i1) by either order in turn, each timed, without the
 * occluder cache: which block each order finds decides which of the next
 * rays the cache answers, and so would bias the sums. */
static __attribute__((noinline)) void occluded_probe(const fr_bvhn *b, const fr_ray *rays, uint8_t *occ, size_t i0,
                                                     size_t i1) {
  occ_cache none = {0, 0, 0, 0, 0};
  for (size_t i = i0; i < i1; i++) {
    const int arm = (int)(i & 1);
    const uint64_t t0 = fr_cycles();
    if (arm) occluded_run_nearest(b, rays, occ, i, i + 1, &none);
    else occluded_run(b, rays, occ, i, i + 1, &none, 0);
    fr_anyhit_tune_record(&order_tune, arm, fr_cycles() - t0);
  }
}

static void occluded_stream(const fr_bvhn *b, const fr_ray *rays, uint8_t *occ, size_t n, int cache, int order) {
  occ_cache c = {0, 0, 0, cache, cache};
  for (size_t i0 = 0, i1; i0 < n; i0 = i1) {
    i1 = n - i0 > ORDER_CHUNK ? i0 + ORDER_CHUNK : n;
    const int how = order >= 0 ? order : rays[i0].tfar < INFINITY ? fr_anyhit_tune_pick(&order_tune, b) : 0;
    if (how == FR_ANYHIT_PROBE) occluded_probe(b, rays, occ, i0, i1);
    else if (how) occluded_run_nearest(b, rays, occ, i0, i1, &c);
    else occluded_run(b, rays, occ, i0, i1, &c, 0);
  }
}

#define TRACE_NAME2(w, isa) fr_trace_w##w##_##isa
#define TRACE_NAME(w, isa) TRACE_NAME2(w, isa)
#define TRACE_FNS TRACE_NAME(FR_WIDTH, FR_ISA_SUFFIX)
const fr_trace_fns TRACE_FNS = {intersect1, occluded1, intersect_stream, occluded_stream, intersect_subtree,
                                occluded_subtree};
