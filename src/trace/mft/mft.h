/*
 * Multi-frusta tracing (Benthin & Wald, "Efficient Ray Traced Soft Shadows
 * using Multi-Frusta Tracing", HPG 2009): 16 frusta of 16 rays each traverse
 * the binary BVH together, one frustum per SIMD lane.
 *
 * A frustum is an origin o and 16 rays o + t (start + delta_k), t in
 * (tnear, tfar). The deltas come from a shared table of ray sets, so a ray is
 * made on demand from two vectors and never stored:
 *
 *   primary rays  o = eye, start = direction of the block's first pixel,
 *                 delta_k = i du + j dv for the 4x4 pixels (one set);
 *   soft shadows  o = hit point, start = light corner - o,
 *                 delta_k = s_k e1 + q_k e2 for the samples of the pixel's
 *                 set on the quad light (16 interleaved sets).
 *
 * Every delta is a * e1 + b * e2 with the ray's 2D parameters (a, b), so the
 * four corner rays of a frustum are the corners of the (a, b) box of its
 * rays; once a leaf has occluded enough of a frustum's shadow rays they
 * shrink to the box of the rays still active (the paper's "CR" shrinking,
 * §5.3; when: EAGER_FETCHED in mft_traverse.c).
 */
#ifndef FR_TRACE_MFT_H
#define FR_TRACE_MFT_H
#include <stddef.h>
#include <stdint.h>
#include "accel/bvh2.h"
#include "frusta.h"

#define FR_MFT_RAYS 16    /* rays per frustum */
#define FR_MFT_FRUSTA 16  /* frusta traced together */
#define FR_MFT_SETS 16    /* ray sets in a table */

typedef struct fr_mft_set {
  float a[FR_MFT_RAYS], b[FR_MFT_RAYS];              /* 2D parameters */
  float dx[FR_MFT_RAYS], dy[FR_MFT_RAYS], dz[FR_MFT_RAYS]; /* delta = a e1 + b e2, rounded once */
  float amin, amax, bmin, bmax;                      /* the box of (a, b) */
  float lo[3], hi[3];                                /* the box of the deltas */
} __attribute__((aligned(64))) fr_mft_set;

typedef struct fr_mft_sets {
  fr_mft_set set[FR_MFT_SETS];
  float e1[3], e2[3];
  int count;
} fr_mft_sets;

/* Fills the deltas of set s and their bounds from its (a, b) parameters. */
void fr_mft_set_finish(fr_mft_sets *t, int s);

/* 16 frusta. Lane f is frustum f; only frusta in `valid` are traced. */
typedef struct fr_mft_batch {
  float org[3][FR_MFT_FRUSTA] __attribute__((aligned(64)));
  float start[3][FR_MFT_FRUSTA] __attribute__((aligned(64)));
  float tnear[FR_MFT_FRUSTA] __attribute__((aligned(64)));
  float tfar[FR_MFT_FRUSTA] __attribute__((aligned(64)));
  uint8_t set[FR_MFT_FRUSTA];
  unsigned valid;
} fr_mft_batch;

/* Ray k of frustum f, exactly as the kernels make it (for tests and for the
 * tracers that trace the same rays one by one). */
static inline void fr_mft_ray(const fr_mft_batch *b, const fr_mft_sets *t, int f, int k, float org[3], float dir[3]) {
  const fr_mft_set *s = &t->set[b->set[f]];
  const float *dl[3] = {s->dx, s->dy, s->dz};
  for (int a = 0; a < 3; a++) {
    org[a] = b->org[a][f];
    dir[a] = b->start[a][f] + dl[a][k];
  }
}

/* Closest hits of the 256 rays: t in units of the ray's direction. */
typedef struct fr_mft_hits {
  float t[FR_MFT_FRUSTA][FR_MFT_RAYS] __attribute__((aligned(64)));
  float u[FR_MFT_FRUSTA][FR_MFT_RAYS] __attribute__((aligned(64)));
  float v[FR_MFT_FRUSTA][FR_MFT_RAYS] __attribute__((aligned(64)));
  uint32_t prim[FR_MFT_FRUSTA][FR_MFT_RAYS] __attribute__((aligned(64)));
} fr_mft_hits;

/* What a shadow frustum's bounds shrink to the rays still active (the
 * paper's Table 2): nothing, the corner rays (its "CR"), or the corner rays
 * and the direction intervals of the box test. */
enum { FR_MFT_SHRINK_OFF, FR_MFT_SHRINK_CORNERS, FR_MFT_SHRINK_ALL };

/* What to do (switches for measurement). */
typedef struct fr_mft_opts {
  int corner_rays;  /* cull frusta against a triangle's edges and plane with corner rays */
  int shrink;       /* shadows: shrink to the active rays (FR_MFT_SHRINK_...) */
  float corner_cost; /* ... only where it is expected to spare more 16-ray tests than this (see
                        mft_traverse.c); 0: for every triangle */
} fr_mft_opts;

/* corner rays and shrinking on, corner_cost FR_MFT_CORNER_COST */
fr_mft_opts fr_mft_opts_default(void);

/* Occluder caching for shadow frusta: the leaves that occluded the most
 * rays in a batch are tested first, with all of the next batch's rays and
 * no traversal, where neighbouring pixels' shadow rays often end in the
 * same large triangles (a table top): a frustum all of whose rays they
 * occlude never traverses. Answers do not change: occlusion is whether any
 * triangle is hit, whatever the order. A caller keeps one per run of
 * neighbouring batches on one tree, zeroed at its start. */
#define FR_MFT_OCCLUDERS 2 /* 4: conference -1% instructions, kitchen +0.6% */

/* A run of batches' shaft: every leaf of the tree that a segment from the
 * box of their origins to the box of their rays' ends may reach, as
 * parent node << 1 | slot, so a batch tests these leaves' boxes alone
 * instead of walking the tree from its root (fr_mft_shaft_build). */
#define FR_MFT_SHAFT_MAX 64
#define FR_MFT_SHAFT_STACK 128
#define FR_MFT_SHAFT_VISITS 256 /* inner nodes a build visits at most */
typedef struct fr_mft_shaft {
  unsigned n;
  uint32_t leaf[FR_MFT_SHAFT_MAX];
} fr_mft_shaft;

/* The leaves of b's tree that segments from box P (plo, phi) to box Q may
 * reach, for t in [0, 1], into *s. Returns 0 where the shaft meets more
 * than FR_MFT_SHAFT_MAX leaves or the root is a leaf (no list: walk). */
int fr_mft_shaft_build(const fr_bvh2 *b, const float plo[3], const float phi[3], const float qlo[3],
                       const float qhi[3], fr_mft_shaft *s);

/* The planar occluders of b (accel/plane_occluders.h) that segments from
 * box P to box Q cannot cross (bit i: occluder i; those past the 32nd are
 * not told apart): a ray one claims crosses its polygon, so these claim
 * none. */
uint32_t fr_mft_shaft_planes_off(const fr_bvh2 *b, const float plo[3], const float phi[3], const float qlo[3],
                                 const float qhi[3]);

typedef struct fr_mft_occluders {
  uint32_t leaf[FR_MFT_OCCLUDERS]; /* leaf references of the tree, best first */
  unsigned n;
  /* when not NULL, a shaft of this tree around every ray of the batch:
   * its leaves replace the walk */
  const fr_mft_shaft *shaft;
  /* planar occluders the batch's rays cannot cross, not tested
   * (fr_mft_shaft_planes_off) */
  uint32_t planes_off;
} fr_mft_occluders;

/* What a shadow batch may spend, and what it spent. A batch stops before
 * an inner-node visit once it has visited `nodes` nodes and fetched at
 * least `tris` triangles (both 0: no budget); then only the set bits of
 * occ are answers, and the other rays are still to be traced. Both counts
 * only grow, so a caller that would judge the batch by them afterwards
 * can have it stop as soon as the verdict is certain. */
typedef struct fr_mft_budget {
  unsigned nodes, tris; /* in */
  unsigned visited;     /* out: the inner nodes visited */
  int stopped;          /* out: stopped over budget */
  /* in: only the tree's planar occluders (accel/plane_occluders.h), no
   * traversal; the batch then always stops. For batches whose rays go to
   * ray streams anyway (soft shadows' fall-back), which do not test them. */
  int planes_only;
} fr_mft_budget;

typedef struct fr_mft_fns {
  /* occ[f]: bit k set when ray k of frustum f is occluded; returns the
   * triangles the batch's leaves fetched, what it cost. budget, when not
   * NULL: see fr_mft_budget. cache, when not NULL: the occluders to test
   * first, replaced by this batch's. */
  unsigned (*occluded)(const fr_bvh2 *b, const fr_mft_opts *o, const fr_mft_batch *batch, const fr_mft_sets *sets,
                       uint16_t occ[FR_MFT_FRUSTA], fr_mft_budget *budget, fr_mft_occluders *cache);
  /* returns the triangles fetched, as occluded does */
  unsigned (*intersect)(const fr_bvh2 *b, const fr_mft_opts *o, const fr_mft_batch *batch, const fr_mft_sets *sets,
                        fr_mft_hits *hits);
  /* rays[16 f + k] = ray k of frustum f with its direction normalized,
   * hits[16 f + k] its hit with t in units of that direction (ng zero), for
   * all 16 frusta (src/trace/mft_expand.c) */
  void (*expand)(const fr_mft_batch *batch, const fr_mft_sets *sets, const fr_mft_hits *hits, fr_ray *rays_out,
                 fr_hit *hits_out);
  /* 16 frusta around up to n <= 256 given rays, ray k of frustum f being
   * rays[16 f + k] (a last, partial frustum repeats its last ray), one set
   * per frustum in sets (src/trace/mft_from_rays.c). A frustum is made where
   * its rays share an origin, have finite ranges with 0 <= tnear <= tfar,
   * and lie within about 75 degrees of the batch's mean direction. Its rays,
   * as fr_mft_ray makes them, are the given directions times tfar, to within
   * rounding, over t in (the least tnear / tfar, 1). Returns the frusta made
   * (batch->valid); the rest are for the caller to trace as rays. */
  unsigned (*from_rays)(fr_mft_batch *batch, fr_mft_sets *sets, const fr_ray *rays, size_t n);
  /* expand's answers for the frusta in batch->valid as arrays (t, u, v,
   * prim, dir of out; ng is the caller's): ray k of frustum f is pixel
   * (4 (f & 3) + (k & 3), 4 (f >> 2) + (k >> 2)) of a 16x16 tile whose
   * top-left pixel is element `at`, `width` elements a row; only the
   * tile's first `rows` rows are written */
  void (*expand_arrays)(const fr_mft_batch *batch, const fr_mft_sets *sets, const fr_mft_hits *hits,
                        const fr_hit_arrays *out, size_t at, size_t width, int rows);
  /* rays[j]: the segment from light to points[j] (3 floats each) that a
   * point-light shadow ray tests, or an empty ray (src/trace/mft_from_rays.c) */
  void (*rays_to_points)(const float light[3], const float *points, size_t n, float eps, fr_ray *rays);
  /* from_rays on those segments, without making them as rays */
  unsigned (*from_points)(fr_mft_batch *batch, fr_mft_sets *sets, const float light[3], const float *points,
                          size_t n, float eps);
} fr_mft_fns;

extern const fr_mft_fns fr_mft_avx512, fr_mft_avx2, fr_mft_scalar;
#define FR_MFT_EXPAND_DECL(isa)                                                                            \
  void fr_mft_expand_##isa(const fr_mft_batch *batch, const fr_mft_sets *sets, const fr_mft_hits *hits, fr_ray *rays_out, \
                           fr_hit *hits_out);
#define FR_MFT_EXPAND_ARRAYS_DECL(isa)                                                                   \
  void fr_mft_expand_arrays_##isa(const fr_mft_batch *batch, const fr_mft_sets *sets, const fr_mft_hits *hits,   \
                                  const fr_hit_arrays *out, size_t at, size_t width, int rows);
#define FR_MFT_FROM_RAYS_DECL(isa) \
  unsigned fr_mft_from_rays_##isa(fr_mft_batch *batch, fr_mft_sets *sets, const fr_ray *rays, size_t n);
#define FR_MFT_OCCLUDED_DECL(isa)                                                                          \
  unsigned fr_mft_occluded_##isa(const fr_bvh2 *b, const fr_mft_opts *opt, const fr_mft_batch *B,            \
                                 const fr_mft_sets *T, uint16_t occ[16], fr_mft_budget *budget,             \
                                 fr_mft_occluders *cache);
FR_MFT_OCCLUDED_DECL(avx512)
FR_MFT_OCCLUDED_DECL(avx2)
FR_MFT_OCCLUDED_DECL(scalar)
FR_MFT_FROM_RAYS_DECL(avx512)
FR_MFT_FROM_RAYS_DECL(avx2)
FR_MFT_FROM_RAYS_DECL(scalar)
FR_MFT_EXPAND_DECL(avx512)
FR_MFT_EXPAND_DECL(avx2)
FR_MFT_EXPAND_DECL(scalar)
#define FR_MFT_RAYS_TO_POINTS_DECL(isa) \
  void fr_mft_rays_to_points_##isa(const float light[3], const float *points, size_t n, float eps, fr_ray *rays);
#define FR_MFT_FROM_POINTS_DECL(isa)                                                                      \
  unsigned fr_mft_from_points_##isa(fr_mft_batch *batch, fr_mft_sets *sets, const float light[3], const float *points, \
                                    size_t n, float eps);
FR_MFT_FROM_POINTS_DECL(avx512)
FR_MFT_FROM_POINTS_DECL(avx2)
FR_MFT_FROM_POINTS_DECL(scalar)
FR_MFT_RAYS_TO_POINTS_DECL(avx512)
FR_MFT_RAYS_TO_POINTS_DECL(avx2)
FR_MFT_RAYS_TO_POINTS_DECL(scalar)
FR_MFT_EXPAND_ARRAYS_DECL(avx512)
FR_MFT_EXPAND_ARRAYS_DECL(avx2)
FR_MFT_EXPAND_ARRAYS_DECL(scalar)

/* The kernels of the active ISA. */
const fr_mft_fns *fr_mft_active(void);
#endif
