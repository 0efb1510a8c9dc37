/*
 * Sixteen rays at a time through the sphere tree (accel/sphere_bvh.h),
 * compiled once per ISA: a node's two boxes and a leaf's spheres meet all
 * of the packet's active rays in one vector test each, where the single-ray
 * walk (sphere_traverse.c) tests them ray by ray. Each lane runs that
 * walk's box test (the same reciprocals, slabs and widened exit) and its
 * sphere test (trace/sphere16.h), and keeps its own nearest distance, so it
 * finds the single-ray walk's sphere and distance bit for bit (on an exact
 * tie in t between two spheres, possibly the other one). The streams and
 * packets of the public calls run their rays through here after the
 * triangles.
 */
#include "base/simd.h"
#include "trace/counters.h"
#include "trace/kernels.h"
#include "trace/sphere16.h"
#include "trace/sphere_traverse.h"

#define STACK 128

/* The lanes of m whose slab test reaches box k of node n before tf (the
 * single-ray walk's box_enter); their entry distances in *enter. */
FR_INLINE unsigned box16(const fr_bvh2_node *n, int k, const vpf o[3], const vpf rd[3], const vpm neg[3], vpf tnear,
                         vpf tf, unsigned m, vpf *enter) {
  const float lo[3] = {n->lo_x[k], n->lo_y[k], n->lo_z[k]}, hi[3] = {n->hi_x[k], n->hi_y[k], n->hi_z[k]};
  vpf tn = tnear;
  for (int a = 0; a < 3; a++) {
    const vpf t0 = vp_mul(vp_sub(vp(lo[a]), o[a]), rd[a]), t1 = vp_mul(vp_sub(vp(hi[a]), o[a]), rd[a]);
    const vpf near = vp_select(neg[a], t1, t0), far = vp_select(neg[a], t0, t1);
    tn = vp_select(vp_gt(near, tn), near, tn);
    tf = vp_select(vp_lt(far, tf), far, tf);
  }
  *enter = tn;
  const vpf widened = vp_add(tf, vp_mul(vp_abs(tf), vp(0x1p-20f))); /* fr_widen_exit */
  return m & vpm_bits(vp_le(tn, widened));
}

unsigned FR_ISA_FN(fr_spheres16)(const fr_bvh2 *b, fr_sphere_rays16 *r, unsigned active, int any) {
  if (!b->nprims || !active) return 0;
  vpf o[3], d[3], rd[3];
  vpm neg[3];
  for (int a = 0; a < 3; a++) {
    o[a] = vp_load(r->o[a]);
    d[a] = vp_load(r->d[a]);
    /* the single-ray walk's reciprocal: tiny components kept at 1e-18 */
    const vpf tiny = vp(1e-18f), dd = vp_select(vp_lt(vp_abs(d[a]), tiny), vp_copysign(tiny, d[a]), d[a]);
    rd[a] = vp_div(vp(1.0f), dd);
    neg[a] = vp_lt(rd[a], vp(0.0f));
  }
  const vpf tnear = vp_load(r->tnear);
  vpf tfar = vp_load(r->tfar);
  unsigned found = 0;
  struct { uint32_t ref; unsigned m; } stack[STACK];
  int sp = 0;
  stack[sp].ref = b->root, stack[sp++].m = active;
  while (sp) {
    sp--;
    const uint32_t ref = stack[sp].ref;
    const unsigned m = stack[sp].m & active;
    if (!m) continue;
    if (ref & FR_BVH2_LEAF) {
      const uint32_t first = FR_BVH2_LEAF_FIRST(ref), count = FR_BVH2_LEAF_COUNT(ref);
      for (uint32_t i = first; i < first + count; i++) {
        vpf t;
        FR_COUNT(sp_tests, (uint64_t)__builtin_popcount(m & active));
        const unsigned h = fr_sphere16_hit(&b->spheres[i], o, d, tnear, tfar, m & active, &t);
        if (!h) continue;
        found |= h;
        if (any) {
          active &= ~h;
          if (!(m & active)) break;
          continue;
        }
        tfar = vp_select(vpm_bits_to(h), t, tfar);
        for (unsigned hh = h; hh; hh &= hh - 1) r->li[__builtin_ctz(hh)] = i;
      }
      continue;
    }
    const fr_bvh2_node *n = &b->nodes[ref];
    FR_COUNT(sp_box_tests, 2 * (uint64_t)__builtin_popcount(m));
    vpf e0, e1;
    const unsigned h0 = box16(n, 0, o, rd, neg, tnear, tfar, m, &e0), h1 = box16(n, 1, o, rd, neg, tnear, tfar, m, &e1);
    /* the child most of the rays in both enter first goes on top */
    const unsigned both = h0 & h1;
    const int first1 = 2 * __builtin_popcount(both & vpm_bits(vp_lt(e1, e0))) > __builtin_popcount(both);
    const uint32_t far = n->child[!first1], near = n->child[first1];
    const unsigned hf = first1 ? h0 : h1, hn = first1 ? h1 : h0;
    if (hf && sp < STACK) stack[sp].ref = far, stack[sp++].m = hf;
    if (hn && sp < STACK) stack[sp].ref = near, stack[sp++].m = hn;
  }
  if (!any) vp_store(r->tfar, tfar);
  return found;
}
