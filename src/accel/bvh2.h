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
#include "base/vec3.h"
#include "geom/mesh.h"
#include "geom/sphere.h"

/* child reference: inner node index, or FR_BVH2_LEAF | count << 27 | first */
#define FR_BVH2_LEAF 0x80000000u
#define FR_BVH2_COUNT_SHIFT 27
#define FR_BVH2_FIRST_MASK ((1u << FR_BVH2_COUNT_SHIFT) - 1)
/* a leaf reference's triangles: count of them from index first */
#define FR_BVH2_LEAF_FIRST(ref) ((ref) & FR_BVH2_FIRST_MASK)
#define FR_BVH2_LEAF_COUNT(ref) (((ref) & ~FR_BVH2_LEAF) >> FR_BVH2_COUNT_SHIFT)

typedef struct fr_bvh2_node {
  float lo_x[2], hi_x[2], lo_y[2], hi_y[2], lo_z[2], hi_z[2];
  uint32_t child[2];
  uint32_t pad[2];
} __attribute__((aligned(64))) fr_bvh2_node;

_Static_assert(sizeof(fr_bvh2_node) == 64, "BVH2 node is one cache line");

/* A triangle as the multi-frusta kernels read it, in leaf order: the
 * vertices in mesh order and per edge i (v1->v2, v2->v0, v0->v1) whether its
 * first vertex is the lexicographically larger one (bit i of edge_flip): the
 * kernels compute an edge's cross product from its smaller vertex, so the
 * neighbouring triangle gets exactly the negated value (watertight). 48
 * bytes, four to three cache lines: the kernels make the normal themselves
 * (fr_bvh2_tri_normal). */
typedef struct fr_bvh2_tri {
  float v0[3], v1[3], v2[3];
  uint32_t prim;
  uint32_t edge_flip;
  uint32_t pad;
} __attribute__((aligned(16))) fr_bvh2_tri;

_Static_assert(sizeof(fr_bvh2_tri) == 48, "BVH2 triangle is 48 bytes");

/* The unnormalized normal (v1 - v0) x (v2 - v0), made in double and
 * rounded once: a float cross product turns it by 2^-24 over the sine of
 * the angle at v0, and with it the plane's distance (a ray leaving a sliver
 * met it again 1e-3 on). On plain floats and without branches, so that a
 * loop over a leaf's triangles vectorizes; IEEE double operations give the
 * same bits in every kernel and at every ISA level. */
static inline void fr_tri_normal_lane(float ax, float ay, float az, float bx, float by, float bz, float cx, float cy,
                                      float cz, float *nx, float *ny, float *nz) {
  double e1x = (double)bx - ax, e1y = (double)by - ay, e1z = (double)bz - az;
  double e2x = (double)cx - ax, e2y = (double)cy - ay, e2z = (double)cz - az;
  *nx = (float)(e1y * e2z - e1z * e2y);
  *ny = (float)(e1z * e2x - e1x * e2z);
  *nz = (float)(e1x * e2y - e1y * e2x);
}
static inline void fr_bvh2_tri_normal(const fr_bvh2_tri *r, float n[3]) {
  fr_tri_normal_lane(r->v0[0], r->v0[1], r->v0[2], r->v1[0], r->v1[1], r->v1[2], r->v2[0], r->v2[1], r->v2[2], &n[0],
                     &n[1], &n[2]);
}

/* leaves hold at most this many triangles (the count field has 4 bits) */
#define FR_BVH2_MAX_LEAF 15

typedef struct fr_bvh2 {
  fr_bvh2_node *nodes;
  size_t nnodes, nleaves;
  uint32_t root;     /* reference, as a child would be */
  aabb bounds;
  uint32_t *prims;   /* triangle ids in leaf order */
  fr_bvh2_tri *tris; /* the same triangles, ready for the frusta kernels */
  fr_sphere *spheres; /* a sphere tree (accel/sphere_bvh.h) has these instead */
  size_t nprims;
  int max_leaf;
  int borrowed;      /* prims and tris belong to another tree (fr_bvh2_shallow) */
  /* the scene's planar occluders, which shadow frusta test before the tree
   * (accel/plane_occluders.h); NULL: none. Not owned. */
  const struct fr_plane_occluders *planes;
} fr_bvh2;

/* Leaves hold at most max_leaf triangles (4: the regular tree; more: the
 * shallow tree the frusta kernels may prefer), cut where the SAH says a
 * subtree costs no more as a leaf (bvh2.c). Without a mesh (m NULL) only
 * the nodes and prims are made, every subtree of at most max_leaf a leaf. */
fr_error fr_bvh2_from_build(const fr_build_tree *t, const fr_mesh *m, int max_leaf, fr_bvh2 *out);
/* The tree of the same build with leaves of up to max_leaf triangles,
 * sharing full's prims and triangles (full, made from t, must outlive it):
 * only the nodes are its own. */
fr_error fr_bvh2_shallow(const fr_build_tree *t, const fr_bvh2 *full, int max_leaf, fr_bvh2 *out);
void fr_bvh2_free(fr_bvh2 *b);
double fr_bvh2_sah(const fr_bvh2 *b);

/* Starts loading what child reference ref will be read for: its node, or
 * the first max_lines cache lines of its leaf's triangles (spheres in a
 * sphere tree). A traversal calls it on children it means to visit soon. */
static inline void fr_bvh2_prefetch(const fr_bvh2 *b, uint32_t ref, uint32_t max_lines) {
  if (!(ref & FR_BVH2_LEAF)) {
    __builtin_prefetch(&b->nodes[ref]);
    return;
  }
  uint32_t first = FR_BVH2_LEAF_FIRST(ref), count = FR_BVH2_LEAF_COUNT(ref);
  if (b->tris) { /* the lines the records span, up to max_lines */
    const uintptr_t lo = (uintptr_t)&b->tris[first] & ~(uintptr_t)63, hi = (uintptr_t)&b->tris[first + count];
    for (uintptr_t a = lo; a < hi && a < lo + 64u * max_lines; a += 64) __builtin_prefetch((const void *)a);
  }
  else if (b->spheres) /* four to a line */
    for (uint32_t i = 0; i < count && i < 4 * max_lines; i += 4) __builtin_prefetch(&b->spheres[first + i]);
}
#endif
