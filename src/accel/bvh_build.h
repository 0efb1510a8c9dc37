/*
 * Binned SAH builder (32 bins per axis, Wald 2007; exact sweeps for small
 * nodes), parallel with OpenMP: large nodes are binned by all threads
 * together, smaller subtrees are built as independent jobs. The result is a
 * binary tree split down to single primitives, each node knowing its range of
 * primitives, so bvh2.c and bvhn.c can each choose their own leaves (the wide
 * collapse opens small leaves to fill empty child slots, as Embree does).
 */
#ifndef FR_ACCEL_BVH_BUILD_H
#define FR_ACCEL_BVH_BUILD_H
#include <stddef.h>
#include <stdint.h>
#include "base/vec3.h"
#include "frusta.h"

#define FR_BUILD_MAX_LEAF 4   /* triangles per leaf: one 4-wide test */
#define FR_BUILD_MAX_DEPTH 64 /* deeper subtrees fall back to median splits */

/* SAH cost of testing n primitives: one per 4-wide block, the unit both the
 * binary build and the wide leaves' termination rule (bvhn.c) price in. */
static inline float fr_build_blocks(uint32_t n) { return (float)((n + FR_BUILD_MAX_LEAF - 1) / FR_BUILD_MAX_LEAF); }

typedef struct fr_build_node {
  aabb box;
  int32_t left, right;     /* children, or -1 for a single primitive */
  uint32_t first, count;   /* the node's range in fr_build_tree.prims */
} fr_build_node;

typedef struct fr_build_tree {
  fr_build_node *nodes;    /* nodes[0] is the root */
  size_t nnodes;
  uint32_t *prims;         /* primitive ids in leaf order */
  size_t nprims;
} fr_build_tree;

/* boxes: one per primitive; ids: the primitive id of each box. */
fr_error fr_build_sah(const aabb *boxes, const uint32_t *ids, size_t n, fr_build_tree *out);
void fr_build_tree_free(fr_build_tree *t);
/* The tree's SAH cost relative to its root box: a node visit and a
 * primitive test each cost 1 (its leaves are single primitives). */
double fr_build_tree_sah(const fr_build_tree *t);
#endif
