/* The table of per-ISA kernels and the run-time choice between them. */
#ifndef FR_TRACE_KERNELS_H
#define FR_TRACE_KERNELS_H
#include <stddef.h>
#include <stdint.h>
#include "accel/bvhn.h"
#include "frusta.h"
#include "geom/tri_watertight.h"

/* A closest hit found inside a subtree, before it becomes an fr_hit: the
 * triangle as 4 * leaf block + lane, t as the test computed it. */
typedef struct fr_subtree_hit { float t, u, v; uint32_t id; } fr_subtree_hit;

/* The scalar traversals' box test (the reference, spheres): an exit
 * distance widened by 2^-20 of itself, as the SIMD kernels' tf * (1 +
 * 2^-20) but by |tf|, so that it widens behind the origin too (the API
 * sends rays with tnear < 0 to the reference). */
static inline float fr_widen_exit(float tf) { return tf + (tf < 0.0f ? -tf : tf) * 0x1p-20f; }

/* Single-ray kernels for one BVH width. */
typedef struct fr_trace_fns {
  void (*intersect1)(const fr_bvhn *b, const fr_ray *ray, fr_hit *hit);
  int (*occluded1)(const fr_bvhn *b, const fr_ray *ray);
  void (*intersect_stream)(const fr_bvhn *b, const fr_ray *rays, fr_hit *hits, size_t n);
  /* cache: the stream's shadow rays try its last occluder first (fr_tuning.occluder_cache);
   * order: the any-hit walk's order (fr_tuning.anyhit_order) */
  void (*occluded_stream)(const fr_bvhn *b, const fr_ray *rays, uint8_t *occ, size_t n, int cache, int order);
  /* The hybrid's single-ray phase: one valid ray through the subtree at ref.
   * intersect_subtree looks for hits before ray->tfar; on one it fills *best
   * and returns 1. */
  int (*intersect_subtree)(const fr_bvhn *b, uint32_t ref, const fr_ray *ray, fr_subtree_hit *best);
  int (*occluded_subtree)(const fr_bvhn *b, uint32_t ref, const fr_ray *ray);
} fr_trace_fns;

/* Ray-stream kernels for one ISA and BVH width (bvhn_stream.c). */
#define FR_STREAM_MAX 64 /* rays in a stream group: one bit each */
typedef struct fr_stream_fns {
  /* Any hit for rays[idx[0..n)], 1 <= n <= FR_STREAM_MAX, all of one
   * direction octant for speed (any rays give correct answers); returns the
   * bits i of the rays occluded. */
  uint64_t (*occluded)(const fr_bvhn *b, const fr_ray *rays, const uint32_t *idx, int n);
  /* Closest hit for the same groups, into hits[idx[i]]: per ray the answer
   * of the single-ray kernel (on exact ties in t, possibly another triangle). */
  void (*intersect)(const fr_bvhn *b, const fr_ray *rays, const uint32_t *idx, int n, fr_hit *hits);
} fr_stream_fns;

/* How any-hit packets meet the leaves: the leaves they visit, and those of
 * them that at most half of a packet's rays reach, summed over the packets
 * that count into it. */
typedef struct fr_packet_use {
  uint64_t leaves, sparse_leaves;
} fr_packet_use;

/* How the packet kernels run (the switches exist for measurement). */
typedef struct fr_packet_opts {
  int hybrid_threshold;   /* trace a popped subtree ray by ray when at most this many rays are active; 0: never */
  int uniform_threshold;  /* the same for packets whose rays share a direction octant */
  int mailbox;            /* inverse mailboxing: skip triangles this packet tested already */
  int axis_aligned;       /* Shevtsov's fast path for axis-aligned triangles */
  int ia_cull;            /* cull nodes for the whole packet by interval arithmetic first */
  int quad_leaves;        /* leaves reached by a few rays: four rays by four triangles a test */
  const fr_trace_fns *single; /* the single-ray kernels of the same ISA and width */
  fr_packet_use *use;     /* where not NULL, any-hit packets add their leaf visits to it */
} fr_packet_opts;

/* Packet kernels for one ISA, packet size and BVH width. valid: bit i for ray i. */
typedef struct fr_packet_fns {
  void (*intersect)(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const fr_ray16 *rays, fr_hit16 *hits);
  unsigned (*occluded)(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const fr_ray16 *rays);
  /* The same on rays[idx[0..n)] of a stream (1 <= n <= packet size, each
   * idx[i] < 2^27), answers to hits[idx[i]] / bit i: gathered and scattered
   * in registers, with no fr_ray16 in between. */
  void (*intersect_idx)(const fr_bvhn *b, const fr_packet_opts *o, const fr_ray *rays, const uint32_t *idx, int n,
                        fr_hit *hits);
  unsigned (*occluded_idx)(const fr_bvhn *b, const fr_packet_opts *o, const fr_ray *rays, const uint32_t *idx, int n);
} fr_packet_fns;

/* Sixteen rays through the sphere tree (trace/sphere_packet.c): the lanes
 * of active (valid rays) that hit a sphere in (tnear, tfar); for closest
 * hits (any 0) their tfar lowered to the hit and li set, each lane the
 * single-ray walk's answer. */
struct fr_bvh2;
struct fr_sphere_rays16;
typedef unsigned (*fr_spheres16_fn)(const struct fr_bvh2 *b, struct fr_sphere_rays16 *r, unsigned active, int any);

typedef struct fr_kernels {
  fr_isa isa;
  const fr_trace_fns *w4, *w8;
  const fr_packet_fns *p8w4, *p16w4, *p8w8, *p16w8;
  const fr_stream_fns *s4, *s8;
  fr_spheres16_fn spheres16;
} fr_kernels;

extern const fr_trace_fns fr_trace_w4_avx512, fr_trace_w4_avx2, fr_trace_w4_scalar;
extern const fr_trace_fns fr_trace_w8_avx512, fr_trace_w8_avx2, fr_trace_w8_scalar;
extern const fr_stream_fns fr_stream_w4_avx512, fr_stream_w4_avx2, fr_stream_w4_scalar;
extern const fr_stream_fns fr_stream_w8_avx512, fr_stream_w8_avx2, fr_stream_w8_scalar;
#define FR_DECLARE_PACKET(isa)                                                                    \
  extern const fr_packet_fns fr_packet_p8_w4_##isa, fr_packet_p16_w4_##isa, fr_packet_p8_w8_##isa, \
      fr_packet_p16_w8_##isa;
FR_DECLARE_PACKET(avx512)
FR_DECLARE_PACKET(avx2)
FR_DECLARE_PACKET(scalar)
unsigned fr_spheres16_avx512(const struct fr_bvh2 *b, struct fr_sphere_rays16 *r, unsigned active, int any);
unsigned fr_spheres16_avx2(const struct fr_bvh2 *b, struct fr_sphere_rays16 *r, unsigned active, int any);
unsigned fr_spheres16_scalar(const struct fr_bvh2 *b, struct fr_sphere_rays16 *r, unsigned active, int any);

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

/* The fr_hit of a closest hit: barycentrics as found, t recomputed in double
 * from the triangle's plane (see fr_tri_refine_t), the geometric normal. */
static inline void fr_hit_finish(const fr_bvhn *b, const fr_subtree_hit *best, vec3 org, vec3 dir, float tnear,
                                 float tfar, fr_hit *hit) {
  const fr_tri4 *blk = &b->tris[best->id >> 2];
  int l = (int)(best->id & 3);
  vec3 p0 = v3(blk->v0[0][l], blk->v0[1][l], blk->v0[2][l]);
  vec3 p1 = v3(blk->v1[0][l], blk->v1[1][l], blk->v1[2][l]);
  vec3 p2 = v3(blk->v2[0][l], blk->v2[1][l], blk->v2[2][l]);
  vec3 ng = v3_cross(v3_sub(p1, p0), v3_sub(p2, p0));
  hit->prim = FR_TRI4_PRIM(blk->prim[l]);
  hit->ng[0] = ng.x; hit->ng[1] = ng.y; hit->ng[2] = ng.z;
  hit->u = best->u;
  hit->v = best->v;
  hit->t = fr_tri_refine_t(org, dir, tnear, tfar, p0, p1, p2, best->t);
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
