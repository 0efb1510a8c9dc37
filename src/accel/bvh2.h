/*
 * Binary BVH in the multi-frusta layout: a node holds both children's boxes
 * (structure of arrays) and references, 64 bytes, one cache line, so one load
 * tests both children. The root's own box is kept beside the array.
 */
#ifndef FR_ACCEL_BVH2_H
#define FR_ACCEL_BVH2_H
#include <stddef.h>
#include <stdint.h>
#include "accel/bvh_build.h"

/* child reference: inner node index, or FR_BVH2_LEAF | count << 27 | first */
#define FR_BVH2_LEAF 0x80000000u
#define FR_BVH2_COUNT_SHIFT 27
#define FR_BVH2_FIRST_MASK ((1u << FR_BVH2_COUNT_SHIFT) - 1)

typedef struct fr_bvh2_node {
  float lo_x[2], hi_x[2], lo_y[2], hi_y[2], lo_z[2], hi_z[2];
  uint32_t child[2];
  uint32_t pad[2];
} __attribute__((aligned(64))) fr_bvh2_node;

_Static_assert(sizeof(fr_bvh2_node) == 64, "BVH2 node is one cache line");

typedef struct fr_bvh2 {
  fr_bvh2_node *nodes;
  size_t nnodes, nleaves;
  uint32_t root;     /* reference, as a child would be */
  aabb bounds;
  uint32_t *prims;   /* triangle ids in leaf order */
  size_t nprims;
} fr_bvh2;

fr_error fr_bvh2_from_build(const fr_build_tree *t, fr_bvh2 *out);
void fr_bvh2_free(fr_bvh2 *b);
double fr_bvh2_sah(const fr_bvh2 *b);
#endif
