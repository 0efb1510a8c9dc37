/*
 * 4-wide BVH (the MIC paper's layout): a node holds its four children's boxes
 * as structure of arrays, so one SIMD instruction tests all four slabs of an
 * axis. Leaves hold at most four triangles in one fr_tri4 block, vertices as
 * structure of arrays, tested four at once with the watertight test (geom/tri_watertight.h).
 */
#ifndef FR_ACCEL_BVH4_H
#define FR_ACCEL_BVH4_H
#include <stddef.h>
#include <stdint.h>
#include "accel/bvh_build.h"
#include "geom/mesh.h"

#define FR_BVH4_LEAF 0x80000000u   /* child ref: FR_BVH4_LEAF | tri4 block index */
#define FR_BVH4_EMPTY 0x7FFFFFFFu  /* unused slot; its box is inverted and never hit */

typedef struct fr_bvh4_node {
  float lo_x[4], hi_x[4], lo_y[4], hi_y[4], lo_z[4], hi_z[4];
  uint32_t child[4];
  uint32_t nchildren, pad[3];
} __attribute__((aligned(64))) fr_bvh4_node;

_Static_assert(sizeof(fr_bvh4_node) == 128, "BVH4 node is two cache lines");

/* Four triangles; unused lanes hold NaN vertices, which fail every test. */
typedef struct fr_tri4 {
  float v0[3][4], v1[3][4], v2[3][4];
  uint32_t prim[4];
} __attribute__((aligned(16))) fr_tri4;

typedef struct fr_bvh4 {
  fr_bvh4_node *nodes;
  size_t nnodes;
  fr_tri4 *tris;      /* one block per leaf */
  size_t nleaves;
  uint32_t root;
  aabb bounds;
  int depth;
} fr_bvh4;

fr_error fr_bvh4_from_build(const fr_build_tree *t, const fr_mesh *m, fr_bvh4 *out);
void fr_bvh4_free(fr_bvh4 *b);
double fr_bvh4_sah(const fr_bvh4 *b, double *node_fill, double *leaf_fill);
#endif
