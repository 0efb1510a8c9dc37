/*
 * N-wide BVHs, N = 4 or 8. A node holds its children's boxes as structure of
 * arrays, so one SIMD instruction tests one slab of all children: 4-wide is
 * the MIC paper's layout (and what the packet kernels use), 8-wide is what
 * single rays are fastest with on AVX2/AVX-512 (half the node visits, one
 * 256-bit test each). A leaf is a run of fr_tri4 blocks of at most four
 * triangles each, vertices as structure of arrays, each block tested at once
 * with the watertight test (geom/tri_watertight.h), as in the MIC paper.
 */
#ifndef FR_ACCEL_BVHN_H
#define FR_ACCEL_BVHN_H
#include <stddef.h>
#include <stdint.h>
#include "accel/bvh_build.h"
#include "geom/mesh.h"
#include "geom/tri_shevtsov.h"

/* A child ref is a node's byte offset in the node array in units of
 * FR_BVHN_NODE_UNIT, or FR_BVHN_LEAF | (blocks - 1) << 28 | the index of the
 * leaf's first tri4 block; its blocks are consecutive. An offset rather
 * than an index so that a node's address is one scaled-index addressing
 * mode (base + ref * 8) rather than a shift and an add on the path from a
 * node's child load to the next node's loads. */
#define FR_BVHN_LEAF 0x80000000u
#define FR_BVHN_NODE_UNIT 8u
#define FR_BVHN_NODE_AT(b, ref) ((const void *)((const char *)(b)->nodes + (size_t)(ref) * FR_BVHN_NODE_UNIT))
#define FR_BVHN_EMPTY 0x7FFFFFFFu  /* unused slot; its box is inverted and never hit */
#define FR_BVHN_MAX_LEAF_BLOCKS 8
/* The most blocks the builder puts in a leaf; it ends a node of up to 12
 * triangles as a leaf when that costs no more by SAH than splitting it
 * (docs/design.md, "Leaves by SAH"); 4 measured the same as 3. */
#define FR_BVHN_DEFAULT_LEAF_BLOCKS 3
#define FR_BVHN_MAX_BLOCKS (1u << 28)
#define FR_BVHN_LEAF_REF(first, blocks) (FR_BVHN_LEAF | ((uint32_t)(blocks) - 1u) << 28 | (uint32_t)(first))
#define FR_BVHN_LEAF_FIRST(ref) ((ref) & (FR_BVHN_MAX_BLOCKS - 1u))
#define FR_BVHN_LEAF_BLOCKS(ref) ((((ref) >> 28) & 7u) + 1u)

/* Node of width W: boxes at float offsets lo_x 0, hi_x W, lo_y 2W, hi_y 3W,
 * lo_z 4W, hi_z 5W, so a ray's near plane on an axis is at base or base ^ W. */
#define FR_BVHN_NODE(W)                                                        \
  struct {                                                                     \
    float lo_x[W], hi_x[W], lo_y[W], hi_y[W], lo_z[W], hi_z[W];                \
    uint32_t child[W];                                                         \
    uint32_t nchildren, pad[(W) == 4 ? 3 : 7];                                 \
  } __attribute__((aligned(64)))

typedef FR_BVHN_NODE(4) fr_bvh4_node;
typedef FR_BVHN_NODE(8) fr_bvh8_node;
_Static_assert(sizeof(fr_bvh4_node) == 128, "BVH4 node is two cache lines");
_Static_assert(sizeof(fr_bvh8_node) == 256, "BVH8 node is four cache lines");

/* Four triangles; unused lanes hold NaN vertices, which fail every test. */
typedef struct fr_tri4 {
  float v0[3][4], v1[3][4], v2[3][4];
  uint32_t prim[4]; /* the id, | FR_TRI4_THIN for a thin triangle; FR_INVALID_ID in an empty lane */
} __attribute__((aligned(16))) fr_tri4;

/* A thin triangle's hits take the plane's t in double (fr_tri_thin): the
 * flag rides in the id's top bit, read with the id's cache line (commit
 * refuses scenes of 2^31 triangles or more). */
#define FR_TRI4_THIN 0x80000000u
#define FR_TRI4_PRIM(id) ((id) == FR_INVALID_ID ? FR_INVALID_ID : (id) & ~FR_TRI4_THIN)
/* bit l set where lane l of block t holds a thin triangle (or none) */
static inline unsigned fr_tri4_thin_lanes(const fr_tri4 *t) {
  return (t->prim[0] >> 31) | (t->prim[1] >> 31) << 1 | (t->prim[2] >> 31) << 2 | (t->prim[3] >> 31) << 3;
}
_Static_assert(offsetof(fr_tri4, v1) == 48 && offsetof(fr_tri4, v2) == 96, "kernels address v1, v2 from v0");

typedef struct fr_bvhn {
  int width;          /* 4 or 8 */
  void *nodes;        /* fr_bvh4_node or fr_bvh8_node */
  size_t nnodes;
  fr_tri4 *tris;      /* the leaves' blocks */
  /* The same triangles as Shevtsov records, four per block (record 4 * block
   * + lane), for the packet kernels. A lane without a triangle has prim
   * FR_INVALID_ID; a triangle too thin for a float record never hits. */
  fr_tri_shevtsov *shev;
  size_t nleaves, nblocks;
  uint32_t root;
  aabb bounds;
  int depth;
  /* Traversals prefetch the children they push (trace/bvhn_node.h). That
   * hides memory latency once the tree outgrows the caches and only costs
   * instructions while it fits: by default (fr_bvhn_prefetch_auto) it is on
   * above FR_BVHN_PREFETCH_BYTES, the benchmark host's L3: dragon's 48 MB
   * tree gains on every workload, conference's and kitchen's lose. */
  int prefetch;
  /* The same for the packet kernels, whose leaves read the Shevtsov
   * records: on by default (fr_bvhn_packet_prefetch_auto) above
   * FR_BVHN_PACKET_PREFETCH_BYTES of nodes and records. */
  int packet_prefetch;
  /* the scene's planar occluders, which the packets' and single rays'
   * any-hit kernels test before the tree (accel/plane_occluders.h); NULL:
   * none. Not owned. */
  const struct fr_plane_occluders *planes;
} fr_bvhn;

#define FR_BVHN_PREFETCH_BYTES ((size_t)32 << 20)
#define FR_BVHN_PACKET_PREFETCH_BYTES ((size_t)32 << 20)

typedef struct fr_bvhn_stats {
  size_t inner, leaves, node_bytes, tri_bytes;
  double sah, sah_blocks;           /* per triangle test, per 4-wide block test */
  double node_fill, leaf_fill;      /* mean children per node, triangles per leaf */
  double block_fill;                /* triangles per tri4 block */
  size_t blocks;
  int depth;
  size_t packet_tri_bytes;
} fr_bvhn_stats;

fr_error fr_bvhn_from_build(const fr_build_tree *t, const fr_mesh *m, int width, fr_bvhn *out);
void fr_bvhn_free(fr_bvhn *b);
int fr_bvhn_prefetch_auto(const fr_bvhn *b);
int fr_bvhn_packet_prefetch_auto(const fr_bvhn *b);
/* SAH with a node visit (one SIMD box test) costing 1, and a triangle test or
 * a block test costing 1. */
void fr_bvhn_stats_get(const fr_bvhn *b, fr_bvhn_stats *st);
#endif
