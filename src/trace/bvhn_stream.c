/*
 * Ray streams for any-hit queries: up to 64 rays of one direction octant
 * traverse an N-wide BVH together, as a set of active-ray bits per node
 * (the stream traversal of Fuetterling et al., "Efficient Ray Tracing Kernels
 * for Modern CPU Architectures", which Embree's incoherent occlusion streams
 * use). Each ray meets a node's N boxes in the single-ray SIMD test and each
 * leaf block in the four-triangle test, so lanes are never spent on inactive
 * rays (a packet's cost), while a node is fetched and visited once for all the
 * rays that reach it (a single ray's cost is one fetch per ray). Compiled once
 * per ISA and width (FR_WIDTH).
 */
#include "base/simd.h"
#include "trace/bvhn_ray.h"
#include "trace/kernels.h"

/* A pending subtree and the rays that entered it. */
typedef struct stream_entry { uint64_t rays; uint32_t ref; } stream_entry;

/* Tests the rays m against node n's boxes; *child_rays[c] gets those that
 * hit child c, the result the children some ray hit. With `uniform` every ray
 * has the first ray's direction signs, so the node's near and far planes are
 * loaded once for all. */
FR_INLINE int stream_node(const node_t *n, const ray_pre *pre, const float *tfar, uint64_t m, int uniform,
                          uint64_t child_rays[8]) {
  if (W == 8) __builtin_prefetch(n->child);
  FR_COUNT(nodes, (uint64_t)__builtin_popcountll(m));
  FR_COUNT(box_tests, (uint64_t)n->nchildren * (uint64_t)__builtin_popcountll(m));
  vbits8 acc = vb8_zero();
  int hit = 0;
  if (uniform) {
    const node_planes p = load_planes(n, &pre[__builtin_ctzll(m)]);
    for (; m; m &= m - 1) {
      int i = __builtin_ctzll(m), bits;
      (void)planes_test(&p, &pre[i], tfar[i], &bits);
      hit |= bits;
      acc = vb8_or_where(acc, bits, 1ull << i);
    }
  } else {
    for (; m; m &= m - 1) {
      int i = __builtin_ctzll(m), bits;
      (void)box_test(n, &pre[i], tfar[i], &bits);
      hit |= bits;
      acc = vb8_or_where(acc, bits, 1ull << i);
    }
  }
  vb8_store(child_rays, acc);
  return hit;
}

/* Bits of the rays hit; rays[idx[0..n)], n <= FR_STREAM_MAX. */
static uint64_t occluded_group(const fr_bvhn *b, const fr_ray *rays, const uint32_t *idx, int n) {
  ray_pre pre[FR_STREAM_MAX];
  float tfar[FR_STREAM_MAX];
  uint64_t active = 0, occ = 0;
  int uniform = 1, near = -1;
  FR_COUNT(rays, (uint64_t)n);
  for (int i = 0; i < n; i++) {
    const fr_ray *r = &rays[idx[i]];
    if (fr_ray_invalid(r)) continue;
    ray_setup(&pre[i], r);
    tfar[i] = r->tfar;
    active |= 1ull << i;
    int ni = pre[i].near_x | pre[i].near_y << 8 | pre[i].near_z << 16;
    if (near >= 0 && ni != near) uniform = 0;
    near = ni;
  }
  stream_entry stack[STACK_SIZE];
  int sp = 0;
  stack[sp++] = (stream_entry){active, b->root};
  while (sp) {
    stream_entry top = stack[--sp];
    uint64_t m = top.rays & active; /* rays occluded since the push are done */
    if (!m) continue;
    uint32_t ref = top.ref;
    while (!(ref & FR_BVHN_LEAF)) {
      const node_t *nd = (const node_t *)b->nodes + ref;
      uint64_t child_rays[8];
      int hit = stream_node(nd, pre, tfar, m, uniform, child_rays);
      if (!hit) goto next;
      /* the last hit slot first, as the single-ray any-hit (bvhn_single.c) */
      int last = 31 - __builtin_clz((unsigned)hit);
      for (int h = hit & ~(1 << last); h; h &= h - 1) {
        int c = __builtin_ctz((unsigned)h);
        if (b->prefetch) prefetch_ref(b, nd->child[c]);
        stack[sp++] = (stream_entry){child_rays[c], nd->child[c]};
      }
      ref = nd->child[last];
      m = child_rays[last];
    }
    {
      const uint32_t first = FR_BVHN_LEAF_FIRST(ref), nb = FR_BVHN_LEAF_BLOCKS(ref);
      for (uint64_t mm = m; mm; mm &= mm - 1) {
        int i = __builtin_ctzll(mm);
        FR_COUNT(leaves, 1);
        for (uint32_t k = first; k < first + nb; k++) {
          FR_COUNT(tri_tests, 4);
          tri4_result res;
          tri4_test(&b->tris[k], &pre[i], tfar[i], &res);
          if (res.mask) { occ |= 1ull << i; break; }
        }
      }
      active &= ~occ;
      if (!active) break;
    }
  next:;
  }
  return occ;
}

#define STREAM_NAME2(w, isa) fr_stream_w##w##_##isa
#define STREAM_NAME(w, isa) STREAM_NAME2(w, isa)
const fr_stream_fns STREAM_NAME(FR_WIDTH, FR_ISA_SUFFIX) = {occluded_group};
