/* Embree's own tree for a scene: the statistics its verbose build log prints
 * (BVHNStatistics), so that `frusta stats --embree` compares frusta's BVH8
 * with the BVH8 Embree traces, not only with what rtcBuildBVH makes. */
#ifndef FR_TOOL_EMBREE_TREE_H
#define FR_TOOL_EMBREE_TREE_H
#include <stddef.h>
#include "frusta.h"

typedef struct ebr_tree {
  char accel[64];     /* e.g. BVH8<triangle4> */
  char builder[96];   /* e.g. avx::BVH8BuilderFastSpatialSAH */
  int width, depth;
  /* SAH as fr_bvhn_stats' sah_blocks: a node visit and a block test cost 1
   * each, weighted by box area over the root's; nodes and leaves apart */
  double sah, node_sah, leaf_sah;
  size_t inner, leaves;
  double node_fill;   /* mean children per inner node */
  double block_fill;  /* mean triangles per block of block_size */
  int block_size;     /* from the accel name: triangle4 -> 4 */
  double one_block;   /* share of leaves that are one block */
} ebr_tree;

/* Commits the scene as `bench --tracer embree` does (high quality) with the
 * device's log on, captured from stdout, and reads the triangle tree's
 * statistics out of it. FR_ERR_UNSUPPORTED when Embree printed none. */
fr_error ebr_tree_stats(const fr_scene *s, int threads, ebr_tree *out);

/* The same from a log already captured (NUL-terminated); for the tests. */
fr_error ebr_tree_parse(const char *log, ebr_tree *out);
#endif
