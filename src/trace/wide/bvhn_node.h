/*
 * What the single-ray and packet kernels share about an N-wide BVH, for the
 * width FR_WIDTH a kernel is compiled for: its node type, the SIMD type that
 * holds one slab of all N children, and the traversal stack bound. Include
 * after base/simd.h.
 */
#ifndef FR_TRACE_BVHN_NODE_H
#define FR_TRACE_BVHN_NODE_H
#include "accel/bvhn.h"
#include "base/simd.h"

#ifndef FR_WIDTH
#error "define FR_WIDTH (4 or 8)"
#endif

/* Conservative slab test (Ize, "Robust BVH Ray Traversal"): distances are
 * (plane - org) * rdir, whose rounding errs by a few ulps of t, and the far
 * distance is widened by more than that, so no box a triangle hit lies in is
 * ever culled: the traversal stays as watertight as the triangle test. (The
 * FMA form plane * rdir - org * rdir errs by ulps of |org * rdir| instead,
 * unbounded for axis-parallel rays; it measured no faster here.) */
#define ROUND_UP (1.0f + 0x1p-20f)

#if FR_WIDTH == 8
typedef fr_bvh8_node node_t;
typedef vfloat8 vnode;
#define VN(x) vf8(x)
#define VN_LOAD vf8_load
#define VN_STORE vf8_store
#define VN_SUB vf8_sub
#define VN_MUL vf8_mul
#define VN_MIN vf8_min
#define VN_MAX vf8_max
#define VN_IMIN vf8_imin
#define VN_IMAX vf8_imax
#define VN_LE_BITS vf8_le_bits
#define VN_DIV vf8_div
#define VN_ADD_WHERE vf8_add_where
#else
typedef fr_bvh4_node node_t;
typedef vfloat4 vnode;
#define VN(x) vf4(x)
#define VN_LOAD vf4_load
#define VN_STORE vf4_store
#define VN_SUB vf4_sub
#define VN_MUL vf4_mul
#define VN_MIN vf4_min
#define VN_MAX vf4_max
#define VN_IMIN vf4_imin
#define VN_IMAX vf4_imax
#define VN_LE_BITS(a, b) vm4_bits(vf4_le(a, b))
#define VN_DIV vf4_div
#define VN_ADD_WHERE vf4_add_where
#endif
#define W FR_WIDTH

/* Starts loading a pushed child while the nearer one is traversed: its first
 * four lines, a node's all or a leaf's first block and a half (every line:
 * the adjacent-line prefetcher does not make every other line enough). It
 * pays on trees beyond the caches (hairball, dragon) and costs on trees
 * that fit, and on coherent rays, which find the tree in the caches: hence
 * on only above FR_BVHN_PREFETCH_BYTES. The packet kernels prefetch the
 * children they push too, above a bound of their own
 * (fr_bvhn.packet_prefetch). */
FR_INLINE void prefetch_ref(const fr_bvhn *b, uint32_t ref) {
  const char *p = (ref & FR_BVHN_LEAF) ? (const char *)&b->tris[FR_BVHN_LEAF_FIRST(ref)]
                                       : (const char *)FR_BVHN_NODE_AT(b, ref);
  __builtin_prefetch(p);
  __builtin_prefetch(p + 64);
  __builtin_prefetch(p + 128);
  __builtin_prefetch(p + 192);
}

/* The child a walk visits next, all its lines (a node's four, a leaf's
 * blocks), as Embree's single-ray traversal does: its loads then start
 * before the ordering and pushes of this node are done, and a leaf's later
 * blocks do not wait for its first block's test. It rides on b->prefetch,
 * so trees that fit in the caches never pay. */
FR_INLINE void prefetch_next(const fr_bvhn *b, uint32_t ref) {
  if (ref & FR_BVHN_LEAF) {
    const char *p = (const char *)&b->tris[FR_BVHN_LEAF_FIRST(ref)];
    const uint32_t bytes = (uint32_t)sizeof(fr_tri4) * FR_BVHN_LEAF_BLOCKS(ref);
    for (uint32_t k = 0; k < bytes; k += 64) __builtin_prefetch(p + k);
  } else {
    const char *p = (const char *)FR_BVHN_NODE_AT(b, ref);
    for (int k = 0; k < (int)sizeof(node_t); k += 64) __builtin_prefetch(p + k);
  }
}

/* Entries a traversal can have pending: W - 1 per level, and the builder caps
 * the depth (FR_BUILD_MAX_DEPTH plus median splits of at most 2^27 triangles). */
#define STACK_SIZE ((W - 1) * (FR_BUILD_MAX_DEPTH + 32) + 4)
#endif
