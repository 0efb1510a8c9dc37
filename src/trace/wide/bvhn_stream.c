/*
 * Ray streams: up to 64 rays of one direction octant
 * traverse an N-wide BVH together, as a set of active-ray bits per node
 * (the stream traversal of Fuetterling et al., "Efficient Ray Tracing Kernels
 * for Modern CPU Architectures", which Embree's incoherent occlusion streams
 * use). Each ray meets a node's N boxes in the single-ray SIMD test and each
 * leaf block in the four-triangle test, so lanes are never spent on inactive
 * rays (a packet's cost), while a node is fetched and visited once for all the
 * rays that reach it (a single ray's cost is one fetch per ray). Compiled once
 * per ISA and width (FR_WIDTH). Any-hit (occlusion) and closest-hit groups.
 */
#include "base/simd.h"
#include "trace/wide/bvhn_single.h"
#include "trace/kernels.h"
#include "trace/wide/stream_rays.h"

/* Closest hits: a subtree only one of the stream's rays entered goes to the
 * single-ray traversal, which orders the children by that ray's own
 * distances rather than the group's least, with no node fetch left to share
 * (5-8% on diffuse8). Handing off at two or four rays, or occlusion rays
 * (unordered either way), measured slower. Out of line, so that the stream loop keeps its registers
 * (inlined, conference lost 6-11%). */
static __attribute__((noinline)) int single_closest(const fr_bvhn *b, const ray_pre *rp, uint32_t ref, float tfar,
                                                    fr_subtree_hit *best) {
  return closest(b, rp, ref, tfar, best);
}

/* A pending subtree and the rays that entered it. */
typedef struct stream_entry { uint64_t rays; uint32_t ref; } stream_entry;
/* ... and, for closest hits, a distance no ray enters it before */
typedef struct dist_entry { uint64_t rays; uint32_t ref; float dist; } dist_entry;

/* Closest hits: per child, the least entry distance of the rays tested and
 * the sum and count of the entry distances of those that hit it. */
typedef struct child_dists { vnode lo, sum, cnt; } child_dists;
FR_INLINE void child_dists_add(child_dists *d, vnode tn, int bits) {
  d->lo = VN_MIN(d->lo, tn);
  d->sum = VN_ADD_WHERE(d->sum, bits, tn);
  d->cnt = VN_ADD_WHERE(d->cnt, bits, VN(1.0f));
}

/* Tests the rays m against node n's boxes; *child_rays[c] gets those that
 * hit child c, the result the children some ray hit. With `uniform` every ray
 * has the first ray's direction signs, so the node's near and far planes are
 * loaded once for all. A non-NULL min_tn (closest hits; inlined, so the
 * any-hit loop has none of it) gets per child c the least entry distance over
 * the rays of m: no ray enters c before it (rays that miss c only lower the
 * bound); and mean_tn the mean entry distance of the rays that hit c.
 * Any-hit streams of one octant test their dense chunks of 16 (of the
 * stream's n_rays) child by child (chunk_node, stream_rays.h). */
FR_INLINE int stream_node(const node_t *n, const stream_rays *s, uint64_t m, int uniform,
                          uint64_t child_rays[8], float *min_tn, float *mean_tn, int n_rays) {
  if (W == 8) __builtin_prefetch(n->child);
  FR_COUNT(nodes, (uint64_t)__builtin_popcountll(m));
  FR_COUNT(box_tests, (uint64_t)n->nchildren * (uint64_t)__builtin_popcountll(m));
  vbits8 acc = vb8_zero();
  child_dists dists = {VN(INFINITY), VN(0.0f), VN(0.0f)};
  int hit = 0;
  uint64_t dense = 0; /* the rays of dense chunks, tested below */
  const ray_pre r0 = stream_ray(s, __builtin_ctzll(m));
  if (STREAM_DENSE && uniform && !min_tn && __builtin_popcountll(m) >= STREAM_DENSE) {
    for (int o = 0; o + 16 <= n_rays; o += 16) {
      const uint64_t lanes = m & 0xFFFFull << o;
      if (__builtin_popcountll(lanes) >= STREAM_DENSE) dense |= lanes;
    }
    m &= ~dense;
  }
  if (uniform) {
    const node_planes p = load_planes(n, &r0);
    for (; m; m &= m - 1) {
      int i = __builtin_ctzll(m), bits;
      const ray_pre ri = stream_ray(s, i);
      vnode tn = planes_test(&p, &ri, s->tfar[i], &bits);
      if (min_tn) child_dists_add(&dists, tn, bits);
      hit |= bits;
      acc = vb8_or_where(acc, bits, 1ull << i);
    }
  } else {
    for (; m; m &= m - 1) {
      int i = __builtin_ctzll(m), bits;
      const ray_pre ri = stream_ray(s, i);
      vnode tn = box_test(n, &ri, s->tfar[i], &bits);
      if (min_tn) child_dists_add(&dists, tn, bits);
      hit |= bits;
      acc = vb8_or_where(acc, bits, 1ull << i);
    }
  }
  if (min_tn) {
    VN_STORE(min_tn, dists.lo);
    VN_STORE(mean_tn, VN_DIV(dists.sum, dists.cnt)); /* 0 / 0 in the children no ray hit: never read */
  }
  vb8_store(child_rays, acc);
  for (int o = 0; dense; o += 16, dense >>= 16)
    if (dense & 0xFFFFu) chunk_node(n, s, o, (unsigned)dense & 0xFFFFu, &r0, child_rays, &hit);
  return hit;
}

/* Bits of the rays hit; rays[idx[0..n)], n <= FR_STREAM_MAX. */
static uint64_t occluded_group(const fr_bvhn *b, const fr_ray *rays, const uint32_t *idx, int n) {
  stream_rays s __attribute__((aligned(64)));
  int uniform;
  uint64_t active = stream_setup(rays, idx, n, &s, &uniform), occ = 0;
  stream_entry stack[STACK_SIZE];
  int sp = 0;
  stack[sp++] = (stream_entry){active, b->root};
  while (sp) {
    stream_entry top = stack[--sp];
    uint64_t m = top.rays & active; /* rays occluded since the push are done */
    if (!m) continue;
    uint32_t ref = top.ref;
    while (!(ref & FR_BVHN_LEAF)) {
      const node_t *nd = (const node_t *)FR_BVHN_NODE_AT(b, ref);
      uint64_t child_rays[8];
      int hit = stream_node(nd, &s, m, uniform, child_rays, NULL, NULL, n);
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
      /* block by block: chunks of 16 dense with rays ray-major
       * (chunk_block_any), the other rays two to a test (tri4_test2); a
       * ray leaves the leaf at its first hit, so each ray meets the same
       * blocks as when it went through them alone */
      const uint32_t first = FR_BVHN_LEAF_FIRST(ref), nb = FR_BVHN_LEAF_BLOCKS(ref);
      FR_COUNT(leaves, (uint64_t)__builtin_popcountll(m));
      for (uint32_t k = first; k < first + nb && m; k++) {
        FR_COUNT(tri_tests, 4 * (uint64_t)__builtin_popcountll(m));
        uint64_t mm = m;
#if LEAF_DENSE
        unsigned lanes, redo;
        for (int o = 0; __builtin_popcountll(m) >= LEAF_DENSE && (lanes = next_dense_chunk(m, n, &o)); o += 16) {
          occ |= (uint64_t)chunk_block_any(&b->tris[k], &s, o, lanes, &redo) << o;
          mm &= ~((uint64_t)(lanes & ~redo) << o);
        }
#endif
        while (mm) {
          const int i = __builtin_ctzll(mm);
          mm &= mm - 1;
          if (!mm) {
            tri4_result res;
            const ray_pre ri = stream_ray(&s, i);
            tri4_test(&b->tris[k], &ri, s.tfar[i], &res);
            if (res.mask) occ |= 1ull << i;
            break;
          }
          const int i2 = __builtin_ctzll(mm);
          mm &= mm - 1;
          tri4_result ra, rb;
          const ray_pre ri = stream_ray(&s, i), ri2 = stream_ray(&s, i2);
          tri4_test2(&b->tris[k], &ri, s.tfar[i], &ri2, s.tfar[i2], &ra, &rb);
          occ |= (uint64_t)(ra.mask != 0) << i | (uint64_t)(rb.mask != 0) << i2;
        }
        m &= ~occ;
      }
      active &= ~occ;
      if (!active) break;
    }
  next:;
  }
  return occ;
}

/* Closest hits of rays[idx[0..n)] into hits[idx[i]], n <= FR_STREAM_MAX.
 * Children are visited in the order of the mean entry distance of the
 * group's rays that hit them. The least entry distance, the order before,
 * sent a ray into its far children first whenever another ray was nearer to
 * them: hairball diffuse8 streams visited 17.9 nodes and tested 42 triangles
 * per ray, single rays 14.7 and 35; by the mean 15.9 and 36. The least
 * distance still drops a subtree for the rays whose hit
 * lies before it. Each ray runs exactly the single-ray box and triangle
 * tests, so it finds the same nearest hit. */
static void intersect_group(const fr_bvhn *b, const fr_ray *rays, const uint32_t *idx, int n, fr_hit *hits) {
  stream_rays s __attribute__((aligned(64)));
  float *const tfar = s.tfar; /* lowered at each hit */
  fr_subtree_hit best[FR_STREAM_MAX];
  /* the rays handed to single_closest, made once each (a ray can be handed
   * off many times where rays part ways early, as on the hairball) */
  ray_pre single_pre[FR_STREAM_MAX];
  uint64_t made = 0;
  int uniform;
  uint64_t active = stream_setup(rays, idx, n, &s, &uniform), found = 0;
  for (int i = 0; i < n; i++) fr_hit_miss(&hits[idx[i]]);
  dist_entry stack[STACK_SIZE];
  int sp = 0;
  if (active) stack[sp++] = (dist_entry){active, b->root, -INFINITY};
  while (sp) {
    dist_entry top = stack[--sp];
    uint64_t m = top.rays;
    /* rays whose hit since the push lies before the subtree: done with it */
    for (uint64_t f = m & found; f; f &= f - 1) {
      int i = __builtin_ctzll(f);
      if (top.dist > tfar[i] * ROUND_UP) m &= ~(1ull << i);
    }
    if (!m) continue;
    uint32_t ref = top.ref;
    while (!(ref & FR_BVHN_LEAF)) {
      if (!(m & (m - 1))) goto single;
      const node_t *nd = (const node_t *)FR_BVHN_NODE_AT(b, ref);
      uint64_t child_rays[8];
      float min_tn[W] __attribute__((aligned(32))), mean_tn[W] __attribute__((aligned(32)));
      int hit = stream_node(nd, &s, m, uniform, child_rays, min_tn, mean_tn, n);
      if (!hit) goto next;
      /* nearest first by mean_tn; slot order on ties */
      int order[W], k = 0;
      for (int h = hit; h; h &= h - 1) {
        int c = __builtin_ctz((unsigned)h), j = k++ - 1;
        while (j >= 0 && mean_tn[order[j]] > mean_tn[c]) { order[j + 1] = order[j]; j--; }
        order[j + 1] = c;
      }
      for (int j = k - 1; j > 0; j--) { /* farthest pushed first */
        int c = order[j];
        if (b->prefetch) prefetch_ref(b, nd->child[c]);
        stack[sp++] = (dist_entry){child_rays[c], nd->child[c], min_tn[c]};
      }
      ref = nd->child[order[0]];
      m = child_rays[order[0]];
    }
    {
      /* block by block, dense chunks ray-major (chunk_block_closest), the
       * other rays two to a test (tri4_test2): each ray meets the blocks in
       * the same order, with the same tfar, as alone; a leaf is reached by
       * two rays at least (one goes to single_closest) */
      const uint32_t first = FR_BVHN_LEAF_FIRST(ref), nb = FR_BVHN_LEAF_BLOCKS(ref);
      FR_COUNT(leaves, (uint64_t)__builtin_popcountll(m));
      FR_COUNT(tri_tests, 4 * (uint64_t)nb * (uint64_t)__builtin_popcountll(m));
      for (uint32_t k = first; k < first + nb; k++) {
        uint64_t rest = m;
#if LEAF_DENSE
        unsigned lanes, redo;
        for (int o = 0; __builtin_popcountll(m) >= LEAF_DENSE && (lanes = next_dense_chunk(m, n, &o)); o += 16) {
          found |= (uint64_t)chunk_block_closest(&b->tris[k], k, &s, o, lanes, best, &redo) << o;
          rest &= ~((uint64_t)(lanes & ~redo) << o);
        }
#endif
        for (uint64_t mm = rest; mm;) {
          const int i = __builtin_ctzll(mm);
          mm &= mm - 1;
          tri4_result ra, rb;
          if (!mm) {
            const ray_pre ri = stream_ray(&s, i);
            tri4_test(&b->tris[k], &ri, tfar[i], &ra);
            rb.mask = 0;
          } else {
            const int i2 = __builtin_ctzll(mm);
            mm &= mm - 1;
            const ray_pre ri = stream_ray(&s, i), ri2 = stream_ray(&s, i2);
            tri4_test2(&b->tris[k], &ri, tfar[i], &ri2, tfar[i2], &ra, &rb);
            if (rb.mask) {
              tfar[i2] = tri4_nearest(&rb, k, &best[i2]);
              found |= 1ull << i2;
            }
          }
          if (ra.mask) {
            tfar[i] = tri4_nearest(&ra, k, &best[i]);
            found |= 1ull << i;
          }
        }
      }
      continue;
    }
  single: {
      int i = __builtin_ctzll(m);
      if (!((made >> i) & 1)) single_pre[i] = stream_ray(&s, i), made |= 1ull << i;
      if (single_closest(b, &single_pre[i], ref, tfar[i], &best[i])) {
        tfar[i] = best[i].t;
        found |= 1ull << i;
      }
    }
  next:;
  }
  for (uint64_t f = found; f; f &= f - 1) {
    int i = __builtin_ctzll(f);
    const fr_ray *r = &rays[idx[i]];
    fr_hit_finish(b, &best[i], v3_load(r->org), v3_load(r->dir), r->tnear, r->tfar, &hits[idx[i]]);
  }
}

#define STREAM_NAME2(w, isa) fr_stream_w##w##_##isa
#define STREAM_NAME(w, isa) STREAM_NAME2(w, isa)
const fr_stream_fns STREAM_NAME(FR_WIDTH, FR_ISA_SUFFIX) = {occluded_group, intersect_group};
