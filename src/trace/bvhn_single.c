/*
 * Single-ray traversal of an N-wide BVH (Benthin et al., MIC paper §IV, with
 * N = 4 as there or N = 8): one ray, all N child boxes in one SIMD test,
 * nearest child first for closest hits, and four triangles per SIMD test in the leaves
 * (watertight, see geom/tri_watertight.h). Compiled once per ISA and width
 * (FR_WIDTH) through base/simd.h.
 */
#include <math.h>
#include "base/simd.h"
#include "geom/tri_watertight.h"
#include "trace/bvhn_node.h"
#include "trace/child_sort8.h"
#include "trace/counters.h"
#include "trace/kernels.h"

/* What a ray precomputes once for all its node and triangle tests. Both
 * tests subtract node or vertex coordinates from the origin rather than the
 * origin from them, so the load folds into the subtraction; the negated
 * reciprocals and shear make every result bit-identical to the textbook
 * order (IEEE subtraction and products are exactly sign-symmetric). */
typedef struct ray_pre {
  vnode ox, oy, oz, nrx, nry, nrz; /* origin, -1/dir: node tests */
  vfloat4 o_k[3];             /* origin in the shear frame: kx, ky, kz */
  vfloat4 sx, sy, nsz;        /* the watertight test's shear; nsz = -sz */
  int kx4, ky4, kz4;          /* 4 * kx...: float offsets of an axis in a block */
  int near_x, near_y, near_z; /* float offsets of the near planes in a node */
  float tnear;
} ray_pre;

static inline float safe_rcp(float d) {
  /* a zero direction component would give inf * 0 = NaN at a box plane */
  if (fabsf(d) < 1e-18f) d = copysignf(1e-18f, d);
  return 1.0f / d;
}

static inline void ray_setup(ray_pre *r, const fr_ray *ray) {
  float rx = safe_rcp(ray->dir[0]), ry = safe_rcp(ray->dir[1]), rz = safe_rcp(ray->dir[2]);
  r->ox = VN(ray->org[0]); r->oy = VN(ray->org[1]); r->oz = VN(ray->org[2]);
  fr_wt_ray w = fr_wt_setup(v3_load(ray->dir));
  r->kx4 = 4 * w.kx; r->ky4 = 4 * w.ky; r->kz4 = 4 * w.kz;
  r->o_k[0] = vf4(ray->org[w.kx]); r->o_k[1] = vf4(ray->org[w.ky]); r->o_k[2] = vf4(ray->org[w.kz]);
  r->sx = vf4(w.sx); r->sy = vf4(w.sy); r->nsz = vf4(-w.sz);
  r->nrx = VN(-rx); r->nry = VN(-ry); r->nrz = VN(-rz);
  /* node layout (accel/bvhn.h): lo_x 0, hi_x W, lo_y 2W, hi_y 3W, lo_z 4W, hi_z 5W */
  r->near_x = rx >= 0.0f ? 0 : W;
  r->near_y = ry >= 0.0f ? 2 * W : 3 * W;
  r->near_z = rz >= 0.0f ? 4 * W : 5 * W;
  r->tnear = ray->tnear;
}

/* Returns the children's entry distances; *mask gets those hit within
 * [tnear, tfar]. (o - plane) * -rdir is (plane - o) * rdir exactly. */
FR_INLINE vnode box_test(const node_t *n, const ray_pre *r, float tfar, int *mask) {
  const float *f = (const float *)n;
  vnode tnx = VN_MUL(VN_SUB(r->ox, VN_LOAD(f + r->near_x)), r->nrx);
  vnode tny = VN_MUL(VN_SUB(r->oy, VN_LOAD(f + r->near_y)), r->nry);
  vnode tnz = VN_MUL(VN_SUB(r->oz, VN_LOAD(f + r->near_z)), r->nrz);
  vnode tfx = VN_MUL(VN_SUB(r->ox, VN_LOAD(f + (r->near_x ^ W))), r->nrx);
  vnode tfy = VN_MUL(VN_SUB(r->oy, VN_LOAD(f + (r->near_y ^ W))), r->nry);
  vnode tfz = VN_MUL(VN_SUB(r->oz, VN_LOAD(f + (r->near_z ^ W))), r->nrz);
  vnode tn = VN_MAX(VN_MAX(tnx, tny), VN_MAX(tnz, VN(r->tnear)));
  vnode tf = VN_MIN(VN_MIN(tfx, tfy), VN_MIN(tfz, VN(tfar)));
  *mask = VN_LE_BITS(tn, VN_MUL(tf, VN(ROUND_UP)));
  return tn;
}

/* A BVH8 node's child references are its fourth line, read only once the
 * box test is done: fetching that line alongside the planes measured +5%
 * (hairball) and +11% (dragon) on diffuse8 single rays, +1% on conference. */
FR_INLINE vnode visit_node(const node_t *n, const ray_pre *r, float tfar, int *mask) {
  if (W == 8) __builtin_prefetch(n->child);
  FR_COUNT(nodes, 1);
  FR_COUNT(box_tests, n->nchildren);
  return box_test(n, r, tfar, mask);
}

typedef struct tri4_result { vfloat4 t, e1, e2, inv; int mask; } tri4_result;

/* Edge values of exactly zero are recomputed in double, lane by lane (rare). */
static void exact_edges(vfloat4 *e0, vfloat4 *e1, vfloat4 *e2, vfloat4 ax, vfloat4 ay, vfloat4 bx, vfloat4 by,
                        vfloat4 cx, vfloat4 cy, int lanes) {
  float E0[4] __attribute__((aligned(16))), E1[4] __attribute__((aligned(16))), E2[4] __attribute__((aligned(16)));
  float AX[4] __attribute__((aligned(16))), AY[4] __attribute__((aligned(16))), BX[4] __attribute__((aligned(16)));
  float BY[4] __attribute__((aligned(16))), CX[4] __attribute__((aligned(16))), CY[4] __attribute__((aligned(16)));
  vf4_store(E0, *e0); vf4_store(E1, *e1); vf4_store(E2, *e2);
  vf4_store(AX, ax); vf4_store(AY, ay); vf4_store(BX, bx); vf4_store(BY, by); vf4_store(CX, cx); vf4_store(CY, cy);
  for (int i = 0; i < 4; i++) {
    if (!((lanes >> i) & 1)) continue;
    E0[i] = (float)((double)CX[i] * BY[i] - (double)CY[i] * BX[i]);
    E1[i] = (float)((double)AX[i] * CY[i] - (double)AY[i] * CX[i]);
    E2[i] = (float)((double)BX[i] * AY[i] - (double)BY[i] * AX[i]);
  }
  *e0 = vf4_load(E0); *e1 = vf4_load(E1); *e2 = vf4_load(E2);
}

/* Four triangles against one ray; mask of lanes hit in (tnear, tfar). The
 * same operations as fr_tri_watertight, lane by lane, on negated vertex
 * coordinates (o - v, so the loads fold): the edge values come out identical
 * and t does too, with the shear's sz negated. */
FR_INLINE void tri4_test(const fr_tri4 *tr, const ray_pre *r, float tfar, tri4_result *res) {
  /* One pointer per permuted axis, the three vertices at fixed offsets from
   * it: three address registers rather than nine (nine spilled the node
   * loop's registers at every leaf). */
  const float *X = tr->v0[0] + r->kx4, *Y = tr->v0[0] + r->ky4, *Z = tr->v0[0] + r->kz4;
  enum { V1 = 12, V2 = 24 }; /* fr_tri4: v1 and v2 follow v0, 12 floats apart */
  vfloat4 az = vf4_sub(r->o_k[2], vf4_load(Z));
  vfloat4 bz = vf4_sub(r->o_k[2], vf4_load(Z + V1));
  vfloat4 cz = vf4_sub(r->o_k[2], vf4_load(Z + V2));
  vfloat4 ax = vf4_sub(vf4_sub(r->o_k[0], vf4_load(X)), vf4_mul(r->sx, az));
  vfloat4 ay = vf4_sub(vf4_sub(r->o_k[1], vf4_load(Y)), vf4_mul(r->sy, az));
  vfloat4 bx = vf4_sub(vf4_sub(r->o_k[0], vf4_load(X + V1)), vf4_mul(r->sx, bz));
  vfloat4 by = vf4_sub(vf4_sub(r->o_k[1], vf4_load(Y + V1)), vf4_mul(r->sy, bz));
  vfloat4 cx = vf4_sub(vf4_sub(r->o_k[0], vf4_load(X + V2)), vf4_mul(r->sx, cz));
  vfloat4 cy = vf4_sub(vf4_sub(r->o_k[1], vf4_load(Y + V2)), vf4_mul(r->sy, cz));
  vfloat4 e0 = vf4_sub(vf4_mul(cx, by), vf4_mul(cy, bx));
  vfloat4 e1 = vf4_sub(vf4_mul(ax, cy), vf4_mul(ay, cx));
  vfloat4 e2 = vf4_sub(vf4_mul(bx, ay), vf4_mul(by, ax));
  vfloat4 zero = vf4(0.0f);
  int zeros = vm4_bits(vm4_or(vm4_or(vf4_eq(e0, zero), vf4_eq(e1, zero)), vf4_eq(e2, zero)));
  if (__builtin_expect(zeros != 0, 0)) exact_edges(&e0, &e1, &e2, ax, ay, bx, by, cx, cy, zeros);
  vfloat4 lo = vf4_min(e0, vf4_min(e1, e2)), hi = vf4_max(e0, vf4_max(e1, e2));
  vmask4 inside = vm4_or(vf4_ge(lo, zero), vf4_le(hi, zero));
  res->mask = 0;
  if (!vm4_bits(inside)) return; /* most leaf tests end here, before the division */
  vfloat4 det = vf4_add(vf4_add(e0, e1), e2);
  vfloat4 inv = vf4_div(vf4(1.0f), det);
  vfloat4 tz = vf4_add(vf4_add(vf4_mul(e0, vf4_mul(r->nsz, az)), vf4_mul(e1, vf4_mul(r->nsz, bz))), vf4_mul(e2, vf4_mul(r->nsz, cz)));
  vfloat4 t = vf4_mul(tz, inv);
  /* NaN (unused lanes, det == 0) fails the ordered compares on t */
  vmask4 ok = vm4_and(vm4_and(inside, vf4_ne(det, zero)),
                      vm4_and(vf4_gt(t, vf4(r->tnear)), vf4_lt(t, vf4(tfar))));
  res->t = t; res->e1 = e1; res->e2 = e2; res->inv = inv;
  res->mask = vm4_bits(ok);
}

static inline float lane(vfloat4 v, int i) {
  float f[4] __attribute__((aligned(16)));
  vf4_store(f, v);
  return f[i];
}

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

/* Closest hit in the subtree at root before *tfar; fills *best on a hit. */
FR_INLINE int closest(const fr_bvhn *b, const ray_pre *rp, uint32_t root, float tfar, fr_subtree_hit *best) {
  entry stack[STACK_SIZE + STACK_SLACK];
  int sp = 0, found = 0;
  stack[sp++] = (entry){root, -INFINITY};
  while (sp) {
    entry top = stack[--sp];
    if (top.dist > tfar * ROUND_UP) continue;
    uint32_t ref = top.ref;
    while (!(ref & FR_BVHN_LEAF)) {
      const node_t *n = (const node_t *)b->nodes + ref;
      int mask;
      vnode tn = visit_node(n, rp, tfar, &mask);
      if (!mask) goto next;
      int sp0 = sp;
      ref = order_children(n, mask, tn, stack, &sp);
      if (b->prefetch)
        for (int i = sp0; i < sp; i++) prefetch_ref(b, stack[i].ref);
    }
    {
      const uint32_t first = FR_BVHN_LEAF_FIRST(ref), nb = FR_BVHN_LEAF_BLOCKS(ref);
      FR_COUNT(leaves, 1);
      FR_COUNT(tri_tests, 4 * nb);
      for (uint32_t k = first; k < first + nb; k++) {
        tri4_result res;
        tri4_test(&b->tris[k], rp, tfar, &res);
        if (!res.mask) continue;
        int m = res.mask, bl = __builtin_ctz(m);
        float bt = lane(res.t, bl);
        for (m &= m - 1; m; m &= m - 1) {
          int i = __builtin_ctz(m);
          float ti = lane(res.t, i);
          if (ti < bt) { bt = ti; bl = i; }
        }
        tfar = bt;
        float inv = lane(res.inv, bl);
        best->t = bt;
        best->u = lane(res.e1, bl) * inv;
        best->v = lane(res.e2, bl) * inv;
        best->id = 4 * k + (uint32_t)bl;
        found = 1;
      }
    }
  next:;
  }
  return found;
}

static void intersect1(const fr_bvhn *b, const fr_ray *ray, fr_hit *hit) {
  fr_hit_miss(hit);
  FR_COUNT(rays, 1);
  if (fr_ray_invalid(ray)) return;
  ray_pre r;
  ray_setup(&r, ray);
  fr_subtree_hit best = {0.0f, 0.0f, 0.0f, 0};
  if (closest(b, &r, b->root, ray->tfar, &best))
    fr_hit_finish(b, &best, v3_load(ray->org), v3_load(ray->dir), ray->tnear, ray->tfar, hit);
}

static int intersect_subtree(const fr_bvhn *b, uint32_t ref, const fr_ray *ray, fr_subtree_hit *best) {
  ray_pre r;
  ray_setup(&r, ray);
  return closest(b, &r, ref, ray->tfar, best);
}

FR_INLINE int any_hit(const fr_bvhn *b, const ray_pre *rp, uint32_t root, const float tfar) {
  entry stack[STACK_SIZE];
  int sp = 0;
  stack[sp++] = (entry){root, -INFINITY};
  while (sp) {
    uint32_t ref = stack[--sp].ref;
    while (!(ref & FR_BVHN_LEAF)) {
      const node_t *n = (const node_t *)b->nodes + ref;
      int mask;
      (void)visit_node(n, rp, tfar, &mask);
      if (!mask) goto next;
      /* Any hit ends the search, so no sorting: descend into the last hit
       * slot, push the others. Last-first is not arbitrary: the collapse puts
       * the left child of the original split in slot 0, and going there first
       * measured up to 2x slower for hemisphere rays leaving a surface
       * (kitchen ao16: 7.9 -> 13.0 Mrays/s); nearest-first was no faster. */
      {
        int last = 31 - __builtin_clz((unsigned)mask);
        ref = n->child[last];
        for (int m = mask & ~(1 << last); m; m &= m - 1) {
          uint32_t c = n->child[__builtin_ctz(m)];
          if (b->prefetch) prefetch_ref(b, c);
          stack[sp++] = (entry){c, 0.0f};
        }
      }
    }
    {
      const uint32_t first = FR_BVHN_LEAF_FIRST(ref), nb = FR_BVHN_LEAF_BLOCKS(ref);
      FR_COUNT(leaves, 1);
      for (uint32_t k = first; k < first + nb; k++) {
        FR_COUNT(tri_tests, 4);
        tri4_result res;
        tri4_test(&b->tris[k], rp, tfar, &res);
        if (res.mask) return 1;
      }
    }
  next:;
  }
  return 0;
}

static int occluded1(const fr_bvhn *b, const fr_ray *ray) {
  FR_COUNT(rays, 1);
  if (fr_ray_invalid(ray)) return 0;
  ray_pre r;
  ray_setup(&r, ray);
  return any_hit(b, &r, b->root, ray->tfar);
}

static int occluded_subtree(const fr_bvhn *b, uint32_t ref, const fr_ray *ray) {
  ray_pre r;
  ray_setup(&r, ray);
  return any_hit(b, &r, ref, ray->tfar);
}

static void intersect_stream(const fr_bvhn *b, const fr_ray *rays, fr_hit *hits, size_t n) {
  for (size_t i = 0; i < n; i++) intersect1(b, &rays[i], &hits[i]);
}

static void occluded_stream(const fr_bvhn *b, const fr_ray *rays, uint8_t *occ, size_t n) {
  for (size_t i = 0; i < n; i++) occ[i] = (uint8_t)occluded1(b, &rays[i]);
}

#define TRACE_NAME2(w, isa) fr_trace_w##w##_##isa
#define TRACE_NAME(w, isa) TRACE_NAME2(w, isa)
#define TRACE_FNS TRACE_NAME(FR_WIDTH, FR_ISA_SUFFIX)
const fr_trace_fns TRACE_FNS = {intersect1, occluded1, intersect_stream, occluded_stream, intersect_subtree,
                                occluded_subtree};
