#include "bvh2.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"

typedef struct conv { const fr_build_tree *t; fr_bvh2 *b; const uint8_t *leaf; } conv;

/* Where a triangle tree's leaves are cut, by SAH: a node visit costs 1 per
 * unit of its box's half area, a leaf LEAF_COST plus a cost per triangle,
 * and a subtree of at most max_leaf triangles becomes a leaf only where
 * that costs no more than its nodes. Without it (a cost of 0 per
 * triangle), conference's room box (ceiling and one wall, four triangles)
 * was one leaf whose box held every hit point, and most of its shadow
 * batches fetched it.
 * TRI_COST cuts the shadow frusta's tree; SHALLOW_TRI_COST the camera
 * frusta's shallow tree (fr_bvh2_shallow), where a larger leaf pays. Both
 * are where soft16 and primary mft measured fastest across the shared
 * scenes. */
#define LEAF_COST 1.0f
#define TRI_COST 0.5f
#define SHALLOW_TRI_COST 0.2f

/* Marks leaf[bi] for the subtrees at bi that become leaves; returns the
 * subtree's cost. A tri_cost of 0 makes every subtree of at most max_leaf
 * a leaf (its nodes cost at least its own visit): the sphere tree's rule,
 * whose kernels were tuned on it. */
static float plan_leaves(const fr_build_tree *t, int32_t bi, uint32_t max_leaf, float tri_cost, uint8_t *leaf) {
  const fr_build_node *n = &t->nodes[bi];
  const float a = aabb_half_area(n->box);
  const float as_leaf = n->count <= max_leaf ? (LEAF_COST + tri_cost * (float)n->count) * a : INFINITY;
  if (n->left < 0) {
    leaf[bi] = 1;
    return as_leaf;
  }
  const float split = a + plan_leaves(t, n->left, max_leaf, tri_cost, leaf) + plan_leaves(t, n->right, max_leaf, tri_cost, leaf);
  /* the count too: with boxes too large for a float area both are inf */
  leaf[bi] = n->count <= max_leaf && as_leaf <= split;
  return leaf[bi] ? as_leaf : split;
}

static uint32_t convert(conv *c, int32_t bi) {
  const fr_build_node *n = &c->t->nodes[bi];
  if (c->leaf[bi]) {
    c->b->nleaves++;
    return FR_BVH2_LEAF | (n->count << FR_BVH2_COUNT_SHIFT) | n->first;
  }
  uint32_t self = (uint32_t)c->b->nnodes++;
  int32_t kids[2] = {n->left, n->right};
  for (int k = 0; k < 2; k++) {
    aabb bx = c->t->nodes[kids[k]].box;
    fr_bvh2_node *d = &c->b->nodes[self];
    d->lo_x[k] = bx.lo.x; d->hi_x[k] = bx.hi.x;
    d->lo_y[k] = bx.lo.y; d->hi_y[k] = bx.hi.y;
    d->lo_z[k] = bx.lo.z; d->hi_z[k] = bx.hi.z;
    uint32_t r = convert(c, kids[k]);
    c->b->nodes[self].child[k] = r;
  }
  return self;
}

/* inner nodes of the tree at bi with the leaves marked in leaf */
static size_t count_inner(const fr_build_tree *t, int32_t bi, const uint8_t *leaf) {
  const fr_build_node *n = &t->nodes[bi];
  if (leaf[bi]) return 0;
  return 1 + count_inner(t, n->left, leaf) + count_inner(t, n->right, leaf);
}

/* out's nodes, root and bounds from the build tree; a leaf is a range of
 * the build's leaf order (out's prims and tris), whatever its size */
static fr_error make_nodes(const fr_build_tree *t, int max_leaf, float tri_cost, fr_bvh2 *out) {
  uint8_t *leaf = malloc(t->nnodes);
  if (!leaf) return fr_fail(FR_ERR_NOMEM, "BVH2: out of memory");
  plan_leaves(t, 0, (uint32_t)max_leaf, tri_cost, leaf);
  size_t inner = count_inner(t, 0, leaf);
  if (!inner) inner = 1; /* the root a leaf: no node is used, but keep an array */
  out->nodes = fr_alloc_aligned(fr_mul_size(inner, sizeof(fr_bvh2_node)), 64);
  if (!out->nodes) {
    free(leaf);
    return fr_fail(FR_ERR_NOMEM, "BVH2: out of memory");
  }
  memset(out->nodes, 0, inner * sizeof(fr_bvh2_node));
  out->max_leaf = max_leaf;
  out->bounds = t->nodes[0].box;
  conv c = {t, out, leaf};
  out->root = convert(&c, 0);
  free(leaf);
  return FR_OK;
}

fr_error fr_bvh2_from_build(const fr_build_tree *t, const fr_mesh *m, int max_leaf, fr_bvh2 *out) {
  memset(out, 0, sizeof *out);
  if (max_leaf < 1 || max_leaf > FR_BVH2_MAX_LEAF) return fr_fail(FR_ERR_ARG, "BVH2: leaf size %d", max_leaf);
  out->prims = fr_alloc_aligned(fr_mul_size(t->nprims, sizeof(uint32_t)), 64);
  if (m) out->tris = fr_alloc_aligned(fr_mul_size(t->nprims, sizeof(fr_bvh2_tri)), 64);
  if (!out->prims || (m && !out->tris)) {
    fr_bvh2_free(out);
    return fr_fail(FR_ERR_NOMEM, "BVH2: out of memory");
  }
  if (t->nprims) memcpy(out->prims, t->prims, t->nprims * sizeof(uint32_t));
  out->nprims = t->nprims;
  for (size_t i = 0; m && i < t->nprims; i++) {
    fr_bvh2_tri *r = &out->tris[i];
    const uint32_t *ix = m->idx + 3 * (size_t)t->prims[i];
    float *dst[3] = {r->v0, r->v1, r->v2};
    for (int k = 0; k < 3; k++) memcpy(dst[k], m->pos + 3 * (size_t)ix[k], 3 * sizeof(float));
    r->prim = t->prims[i];
    r->edge_flip = 0;
    const float *ends[3][2] = {{r->v1, r->v2}, {r->v2, r->v0}, {r->v0, r->v1}};
    for (int e = 0; e < 3; e++) {
      const float *p = ends[e][0], *q = ends[e][1];
      int gt = p[0] != q[0] ? p[0] > q[0] : p[1] != q[1] ? p[1] > q[1] : p[2] > q[2];
      r->edge_flip |= (uint32_t)gt << e;
    }
    r->pad = 0;
  }
  fr_error e = make_nodes(t, max_leaf, m ? TRI_COST : 0.0f, out);
  if (e) fr_bvh2_free(out);
  return e;
}

fr_error fr_bvh2_shallow(const fr_build_tree *t, const fr_bvh2 *full, int max_leaf, fr_bvh2 *out) {
  memset(out, 0, sizeof *out);
  if (max_leaf < 1 || max_leaf > FR_BVH2_MAX_LEAF) return fr_fail(FR_ERR_ARG, "BVH2: leaf size %d", max_leaf);
  out->prims = full->prims;
  out->tris = full->tris;
  out->nprims = full->nprims;
  out->borrowed = 1;
  fr_error e = make_nodes(t, max_leaf, full->tris ? SHALLOW_TRI_COST : 0.0f, out);
  if (e) fr_bvh2_free(out);
  return e;
}

void fr_bvh2_free(fr_bvh2 *b) {
  fr_free_aligned(b->nodes);
  if (!b->borrowed) {
    fr_free_aligned(b->prims);
    fr_free_aligned(b->tris);
    fr_free_aligned(b->spheres);
  }
  memset(b, 0, sizeof *b);
}

static double child_area(const fr_bvh2_node *n, int k) {
  double dx = n->hi_x[k] - n->lo_x[k], dy = n->hi_y[k] - n->lo_y[k], dz = n->hi_z[k] - n->lo_z[k];
  return dx * dy + dy * dz + dz * dx;
}

/* SAH with a node visit and a triangle test both costing 1. */
double fr_bvh2_sah(const fr_bvh2 *b) {
  double root = aabb_half_area(b->bounds);
  if (!(root > 0.0)) return 0.0;
  double cost = (b->root & FR_BVH2_LEAF) ? (double)FR_BVH2_LEAF_COUNT(b->root) : 1.0;
  for (size_t i = 0; i < b->nnodes; i++) {
    const fr_bvh2_node *n = &b->nodes[i];
    for (int k = 0; k < 2; k++) {
      double w = child_area(n, k) / root;
      uint32_t r = n->child[k];
      cost += (r & FR_BVH2_LEAF) ? w * (double)FR_BVH2_LEAF_COUNT(r) : w;
    }
  }
  return cost;
}
