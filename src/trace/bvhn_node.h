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
#define VN_LE_BITS vf8_le_bits
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
#define VN_LE_BITS(a, b) vm4_bits(vf4_le(a, b))
#endif
#define W FR_WIDTH

/* Entries a traversal can have pending: W - 1 per level, and the builder caps
 * the depth (FR_BUILD_MAX_DEPTH plus median splits of at most 2^27 triangles). */
#define STACK_SIZE ((W - 1) * (FR_BUILD_MAX_DEPTH + 32) + 4)
#endif
