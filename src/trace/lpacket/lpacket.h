/*
 * Large ray packets (Overbeck, Ramamoorthi, Mark, "Large Ray Packets for
 * Real-time Whitted Ray Tracing"): up to 32x32 rays traverse the binary BVH
 * together, as chunks of 16 rays tested with 16-wide SIMD. Before any ray
 * is tested, a node's box (and a leaf's triangles) may be culled for the
 * whole packet by its bounds (trace/packet_bounds.h). Three ways to keep
 * track of which chunks are still worth testing below a node:
 *
 *   masked     a 16-bit mask per chunk, narrowed to the rays that hit the
 *              box, one frame of masks per depth;
 *   ranged     the first and last chunk with a ray that hits the box; the
 *              search stops at the first hit from each end, so a node most
 *              rays hit costs two chunk tests;
 *   partition  a list of the chunks with a ray that hits the box, split in
 *              place into hit and missed at each node (children keep a
 *              prefix of their parent's list).
 *
 * Rays need not share an origin; any direction signs. Rays with NaN fields,
 * a zero direction or tnear > tfar never hit.
 */
#ifndef FR_TRACE_LPACKET_H
#define FR_TRACE_LPACKET_H
#include <stdint.h>
#include "accel/bvh2.h"
#include "frusta.h"
#include "trace/lpacket/packet_bounds.h"

#define FR_LP_MAX 1024             /* rays in a packet (32x32) */
#define FR_LP_CHUNKS (FR_LP_MAX / 16)
#define FR_LP_FRAMES 160           /* depth of the masked traversal's frames */

typedef enum fr_lp_traversal { FR_LP_MASKED, FR_LP_RANGED, FR_LP_PARTITION, FR_LP_TRAVERSAL_COUNT } fr_lp_traversal;

const char *fr_lp_traversal_name(fr_lp_traversal t);
int fr_lp_traversal_parse(const char *name, fr_lp_traversal *out);

typedef struct fr_lp_opts {
  fr_lp_traversal traversal;
  fr_cull cull;
} fr_lp_opts;

/* A packet in structure-of-arrays form with the kernels' scratch; about
 * 100 KB, so keep one per thread. */
typedef struct fr_lpacket {
  float o[3][FR_LP_MAX] __attribute__((aligned(64)));
  float d[3][FR_LP_MAX] __attribute__((aligned(64)));
  float rd[3][FR_LP_MAX] __attribute__((aligned(64)));
  float tnear[FR_LP_MAX] __attribute__((aligned(64)));
  float tfar[FR_LP_MAX] __attribute__((aligned(64)));  /* closest hit: becomes the hit's t */
  float u[FR_LP_MAX] __attribute__((aligned(64)));
  float v[FR_LP_MAX] __attribute__((aligned(64)));
  uint32_t tri[FR_LP_MAX] __attribute__((aligned(64))); /* hit in leaf order (| FR_LP_SPHERE), or FR_INVALID_ID */
  uint16_t valid[FR_LP_CHUNKS];
  uint16_t alive[FR_LP_CHUNKS];  /* valid and not yet occluded */
  uint16_t occ[FR_LP_CHUNKS];    /* any hit: bit set when occluded */
  uint16_t frames[FR_LP_FRAMES][FR_LP_CHUNKS];
  uint8_t list[FR_LP_CHUNKS];
  int n, nchunks;
  fr_pbounds bounds;
} fr_lpacket;

#define FR_LP_SPHERE 0x80000000u /* fr_lpacket.tri: a sphere's leaf-order index */

/* What a packet traverses: the triangles' binary BVH, then the spheres'
 * (NULL or empty if none; sphere prims count from sphere_base). */
typedef struct fr_lp_scene {
  const fr_bvh2 *tris;
  const fr_bvh2 *spheres;
  uint32_t sphere_base;
} fr_lp_scene;

/* Loads n <= FR_LP_MAX rays; the rest of the last chunk is invalid. */
void fr_lpacket_load(fr_lpacket *p, const fr_ray *rays, int n);
/* Closest hits (after intersect) as fr_hit, with the geometric normal. */
void fr_lpacket_hits(const fr_lpacket *p, const fr_lp_scene *g, fr_hit *hits);

typedef struct fr_lp_fns {
  void (*intersect)(const fr_lp_scene *g, const fr_lp_opts *o, fr_lpacket *p);
  void (*occluded)(const fr_lp_scene *g, const fr_lp_opts *o, fr_lpacket *p);
  void (*bounds)(const fr_lp_opts *o, fr_lpacket *p); /* p->bounds as traversal makes them for o->cull */
} fr_lp_fns;

extern const fr_lp_fns fr_lp_avx512, fr_lp_avx2, fr_lp_scalar;
const fr_lp_fns *fr_lp_active(void);
#endif
