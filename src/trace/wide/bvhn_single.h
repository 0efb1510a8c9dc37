/*
 * The single-ray traversal loops over an N-wide BVH: closest hit (nearest
 * child first) and any hit (early exit) in one subtree, for a ray already
 * set up (ray_pre). The single-ray kernels (bvhn_single.c) run them from the
 * root; the closest-hit ray streams (bvhn_stream.c) hand `closest` a subtree
 * once only one of their rays is left in it. Include after base/simd.h with
 * FR_WIDTH defined.
 */
#ifndef FR_TRACE_BVHN_SINGLE_H
#define FR_TRACE_BVHN_SINGLE_H
#include "trace/wide/bvhn_ray.h"
#include "trace/wide/child_sort8.h"

typedef struct entry { uint32_t ref; float dist; } entry;

/* Pushes the hit children farthest first and returns the nearest. */
#if defined(FR_HAVE_CHILD_SORT8) && FR_WIDTH == 8
#define STACK_SLACK W /* the network stores all eight entries */
FR_INLINE uint32_t order_children(const node_t *n, int mask, vnode tn, entry *stack, int *spp) {
  if (!(mask & (mask - 1))) return n->child[__builtin_ctz((unsigned)mask)];
  uint32_t nearest = fr_child_sort8(n->child, mask, tn.v, stack + *spp);
  *spp += __builtin_popcount((unsigned)mask) - 1;
  return nearest;
}
#else
/* Three or more are insertion-sorted straight into the stack (building a
 * local array and copying it over cost ~15% of a diffuse ray's
 * instructions). */
#define STACK_SLACK 0
FR_INLINE uint32_t order_children(const node_t *n, int mask, vnode tn, entry *stack, int *spp) {
  float dist[W] __attribute__((aligned(32)));
  VN_STORE(dist, tn);
  int i0 = __builtin_ctz(mask);
  int rest = mask & (mask - 1);
  if (!rest) return n->child[i0];
  int i1 = __builtin_ctz(rest);
  int sp = *spp;
  if (!(rest & (rest - 1))) {
    if (dist[i1] < dist[i0]) { int t = i0; i0 = i1; i1 = t; }
    stack[sp] = (entry){n->child[i1], dist[i1]};
    *spp = sp + 1;
    return n->child[i0];
  }
  entry *e = stack + sp;
  int k = 0;
  for (; mask; mask &= mask - 1) { /* in slot order; ties keep it */
    int i = __builtin_ctz(mask);
    entry x = {n->child[i], dist[i]};
    int j = k++ - 1;
    while (j >= 0 && e[j].dist < x.dist) { e[j + 1] = e[j]; j--; }
    e[j + 1] = x;
  }
  *spp = sp + k - 1; /* the nearest, last, is not pushed but returned */
  return e[k - 1].ref;
}
#endif

/* An any-hit walk's leaf: 1 + the index of its first block with a hit, or 0. */
FR_INLINE uint32_t any_hit_leaf(const fr_bvhn *b, const ray_pre *rp, uint32_t ref, float tfar) {
  const uint32_t first = FR_BVHN_LEAF_FIRST(ref), nb = FR_BVHN_LEAF_BLOCKS(ref);
  FR_COUNT(leaves, 1);
  for (uint32_t k = first; k < first + nb; k++) {
    FR_COUNT(tri_tests, 4);
    tri4_result res;
    tri4_test(&b->tris[k], rp, tfar, &res);
    if (res.mask) return k + 1;
  }
  return 0;
}

/* From *ref down the nearest hit children to a leaf, into *ref, the other
 * hit children pushed farthest first; 0 where a node has no hit child. */
FR_INLINE int descend_nearest(const fr_bvhn *b, const ray_pre *rp, float tfar, uint32_t *ref, entry *stack, int *spp) {
  uint32_t r = *ref;
  int sp = *spp;
  while (!(r & FR_BVHN_LEAF)) {
    const node_t *n = (const node_t *)FR_BVHN_NODE_AT(b, r);
    int mask;
    vnode tn = visit_node(n, rp, tfar, &mask);
    if (!mask) {
      *spp = sp;
      return 0;
    }
    int sp0 = sp;
    r = order_children(n, mask, tn, stack, &sp);
    if (b->prefetch) {
      prefetch_next(b, r);
      for (int i = sp0; i < sp; i++) prefetch_ref(b, stack[i].ref);
    }
  }
  *ref = r;
  *spp = sp;
  return 1;
}

/* Closest hit in the subtree at root before *tfar; fills *best on a hit. */
FR_INLINE int closest(const fr_bvhn *b, const ray_pre *rp, uint32_t root, float tfar, fr_subtree_hit *best) {
  entry stack[STACK_SIZE + STACK_SLACK];
  int sp = 0, found = 0;
  stack[sp++] = (entry){root, -INFINITY};
  while (sp) {
    entry top = stack[--sp];
    if (top.dist > tfar * ROUND_UP) continue;
    uint32_t ref = top.ref;
    if (!descend_nearest(b, rp, tfar, &ref, stack, &sp)) continue;
    {
      const uint32_t first = FR_BVHN_LEAF_FIRST(ref), nb = FR_BVHN_LEAF_BLOCKS(ref);
      FR_COUNT(leaves, 1);
      FR_COUNT(tri_tests, 4 * nb);
      for (uint32_t k = first; k < first + nb; k++) {
        tri4_result res;
        tri4_test(&b->tris[k], rp, tfar, &res);
        if (!res.mask) continue;
        tfar = tri4_nearest(&res, k, best);
        found = 1;
      }
    }
  }
  return found;
}

/* any_hit with the hit children visited nearest first, as `closest` orders
 * them: on the hairball's soft shadows, whose occluders mostly lie near the
 * ray's start among strands whose boxes overlap, it visits fewer nodes than
 * the occlusion rank; on most scenes more (occluded_stream picks). */
FR_INLINE uint32_t any_hit_nearest(const fr_bvhn *b, const ray_pre *rp, uint32_t root, const float tfar) {
  entry stack[STACK_SIZE + STACK_SLACK];
  int sp = 0;
  stack[sp++] = (entry){root, -INFINITY};
  while (sp) {
    uint32_t ref = stack[--sp].ref;
    if (!descend_nearest(b, rp, tfar, &ref, stack, &sp)) continue;
    const uint32_t k = any_hit_leaf(b, rp, ref, tfar);
    if (k) return k;
  }
  return 0;
}

/* Any hit in the subtree at root before tfar: 1 + the index of the block
 * that has it, or 0. */
FR_INLINE uint32_t any_hit(const fr_bvhn *b, const ray_pre *rp, uint32_t root, const float tfar) {
  entry stack[STACK_SIZE];
  int sp = 0;
  stack[sp++] = (entry){root, -INFINITY};
  while (sp) {
    uint32_t ref = stack[--sp].ref;
    while (!(ref & FR_BVHN_LEAF)) {
      const node_t *n = (const node_t *)FR_BVHN_NODE_AT(b, ref);
      int mask;
      (void)visit_node(n, rp, tfar, &mask);
      if (!mask) goto next;
      /* Any hit ends the search, so no sorting: descend into the last hit
       * slot, push the others. The build put the children most likely to
       * occlude per unit of work last (accel/bvhn.c, occlusion_rank); with
       * the collapse's own order, going to slot 0 first was up to 2x
       * slower (kitchen ao16). Nearest-first pays only among hairball's
       * strands, where anyhit_tune.h chooses it. */
      {
        int last = 31 - __builtin_clz((unsigned)mask);
        ref = n->child[last];
        /* the child visited next too, all its lines, as the deferred
         * children's */
        if (b->prefetch) prefetch_next(b, ref);
        for (int m = mask & ~(1 << last); m; m &= m - 1) {
          uint32_t c = n->child[__builtin_ctz(m)];
          if (b->prefetch) prefetch_ref(b, c);
          stack[sp++] = (entry){c, 0.0f};
        }
      }
    }
    {
      const uint32_t k = any_hit_leaf(b, rp, ref, tfar);
      if (k) return k;
    }
  next:;
  }
  return 0;
}
#endif
