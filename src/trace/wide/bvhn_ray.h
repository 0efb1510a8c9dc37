/*
 * One ray against an N-wide BVH's nodes and four-triangle blocks: what the
 * ray precomputes, the N-box slab test and the watertight four-triangle test.
 * Shared by the single-ray kernels (bvhn_single.c) and the ray-stream kernels
 * (bvhn_stream.c); include after base/simd.h with FR_WIDTH defined.
 */
#ifndef FR_TRACE_BVHN_RAY_H
#define FR_TRACE_BVHN_RAY_H
#include <math.h>
#include "geom/tri_watertight.h"
#include "trace/wide/bvhn_node.h"
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
  const fr_ray *src;         /* the ray as given: a thin triangle's plane t (tri4_plane_t) */
  vnode nrx_w, nry_w, nrz_w; /* the same times ROUND_UP: far distances (planes_test) */
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
  r->nrx_w = VN(-rx * ROUND_UP); r->nry_w = VN(-ry * ROUND_UP); r->nrz_w = VN(-rz * ROUND_UP);
  /* node layout (accel/bvhn.h): lo_x 0, hi_x W, lo_y 2W, hi_y 3W, lo_z 4W, hi_z 5W */
  r->near_x = rx >= 0.0f ? 0 : W;
  r->near_y = ry >= 0.0f ? 2 * W : 3 * W;
  r->near_z = rz >= 0.0f ? 4 * W : 5 * W;
  r->tnear = ray->tnear;
  r->src = ray;
}

/* A node's near and far planes as ray r meets them (its direction signs). */
typedef struct node_planes { vnode nx, ny, nz, fx, fy, fz; } node_planes;

FR_INLINE node_planes load_planes(const node_t *n, const ray_pre *r) {
  const float *f = (const float *)n;
  node_planes p = {VN_LOAD(f + r->near_x), VN_LOAD(f + r->near_y), VN_LOAD(f + r->near_z),
                   VN_LOAD(f + (r->near_x ^ W)), VN_LOAD(f + (r->near_y ^ W)), VN_LOAD(f + (r->near_z ^ W))};
  return p;
}

/* Returns the children's entry distances; *mask gets those hit within
 * [tnear, tfar]. (o - plane) * -rdir is (plane - o) * rdir exactly. The
 * exit distances come out widened (ROUND_UP) by reciprocals widened once
 * per ray, rather than by a product after their min: (1 + 2^-20) less a few
 * 2^-24 roundings either way, and one multiply less on the path from a
 * node's loads to the next node's address, which the walk waits on.
 * The min and max are taken on the distances' bit patterns as integers, a
 * cycle each rather than two. With tnear >= +0, tn is the float max
 * exactly, and tf the float min where that is >= +0, else another value
 * < +0: the same mask as the float forms', but for a box left exactly at
 * t = 0. With tnear < 0 both only loosen (among negatives the integer order
 * is reversed): tn is never above the float max nor tf below the float min,
 * so no box is lost. */
FR_INLINE vnode planes_test(const node_planes *p, const ray_pre *r, float tfar, int *mask) {
  vnode tnx = VN_MUL(VN_SUB(r->ox, p->nx), r->nrx);
  vnode tny = VN_MUL(VN_SUB(r->oy, p->ny), r->nry);
  vnode tnz = VN_MUL(VN_SUB(r->oz, p->nz), r->nrz);
  vnode tfx = VN_MUL(VN_SUB(r->ox, p->fx), r->nrx_w);
  vnode tfy = VN_MUL(VN_SUB(r->oy, p->fy), r->nry_w);
  vnode tfz = VN_MUL(VN_SUB(r->oz, p->fz), r->nrz_w);
  vnode tn = VN_IMAX(VN_IMAX(tnx, tny), VN_IMAX(tnz, VN(r->tnear)));
  vnode tf = VN_IMIN(VN_IMIN(tfx, tfy), VN_IMIN(tfz, VN(tfar * ROUND_UP)));
  *mask = VN_LE_BITS(tn, tf);
  return tn;
}

FR_INLINE vnode box_test(const node_t *n, const ray_pre *r, float tfar, int *mask) {
  node_planes p = load_planes(n, r);
  return planes_test(&p, r, tfar, mask);
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

typedef struct tri4_edges { vfloat4 e0, e1, e2; } tri4_edges;

/* Edge values of exactly zero are recomputed in double, lane by lane (rare).
 * The edges go in and come back by value: passing their addresses kept them
 * in memory, three stores per block on the hot path of every leaf. */
static __attribute__((noinline, cold)) tri4_edges exact_edges(tri4_edges e, vfloat4 ax, vfloat4 ay, vfloat4 bx,
                                                              vfloat4 by, vfloat4 cx, vfloat4 cy, int lanes) {
  float E0[4] __attribute__((aligned(16))), E1[4] __attribute__((aligned(16))), E2[4] __attribute__((aligned(16)));
  float AX[4] __attribute__((aligned(16))), AY[4] __attribute__((aligned(16))), BX[4] __attribute__((aligned(16)));
  float BY[4] __attribute__((aligned(16))), CX[4] __attribute__((aligned(16))), CY[4] __attribute__((aligned(16)));
  vf4_store(E0, e.e0); vf4_store(E1, e.e1); vf4_store(E2, e.e2);
  vf4_store(AX, ax); vf4_store(AY, ay); vf4_store(BX, bx); vf4_store(BY, by); vf4_store(CX, cx); vf4_store(CY, cy);
  for (int i = 0; i < 4; i++) {
    if (!((lanes >> i) & 1)) continue;
    fr_wt_edges_exact(AX[i], AY[i], BX[i], BY[i], CX[i], CY[i], &E0[i], &E1[i], &E2[i]);
  }
  tri4_edges out = {vf4_load(E0), vf4_load(E1), vf4_load(E2)};
  return out;
}

/* The hit lanes `thin` of res again with the plane's t in double, dropped
 * where it falls outside (tnear, tfar) (fr_tri_thin). */
static __attribute__((noinline, cold)) void tri4_plane_t(const fr_tri4 *tr, const fr_ray *ray, float tnear, float tfar,
                                                         tri4_result *res, int thin) {
  float T[4] __attribute__((aligned(16)));
  vf4_store(T, res->t);
  for (; thin; thin &= thin - 1) {
    const int i = __builtin_ctz((unsigned)thin);
    const float t = fr_tri_plane_t(ray->org[0], ray->org[1], ray->org[2], ray->dir[0], ray->dir[1], ray->dir[2],
                                   tr->v0[0][i], tr->v0[1][i], tr->v0[2][i], tr->v1[0][i], tr->v1[1][i], tr->v1[2][i],
                                   tr->v2[0][i], tr->v2[1][i], tr->v2[2][i]);
    if (t > tnear && t < tfar) T[i] = t;
    else res->mask &= ~(1 << i);
  }
  res->t = vf4_load(T);
}

/* The hit lanes of res on thin triangles (FR_TRI4_THIN) take the plane's
 * t: fr_tri_watertight's rule, lane by lane. */
FR_INLINE void tri4_check_thin(const fr_tri4 *tr, const ray_pre *r, float tfar, tri4_result *res) {
  const int thin = res->mask & (int)fr_tri4_thin_lanes(tr);
  FR_COUNT(tri_hit_tests, 1);
  FR_COUNT(tri_plane_t, __builtin_popcount((unsigned)thin));
  if (__builtin_expect(thin != 0, 0))
    tri4_plane_t(tr, r->src, r->tnear, tfar, res, thin);
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
  if (__builtin_expect(zeros != 0, 0)) {
    tri4_edges in = {e0, e1, e2};
    tri4_edges ex = exact_edges(in, ax, ay, bx, by, cx, cy, zeros);
    e0 = ex.e0; e1 = ex.e1; e2 = ex.e2;
  }
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
  if (res->mask) tri4_check_thin(tr, r, tfar, res);
}

/* Two rays against one block: *ra and *rb as tri4_test gives them for ray
 * a and ray b. Lanes 0-3 are ray a's, 4-7 ray b's, each lane the same
 * operations as tri4_test, so the answers are its own; a ray with an edge
 * value of exactly zero takes tri4_test itself (its exact path). For ray
 * streams, whose leaves are mostly reached by several rays: a block's test
 * costs little more for two rays than for one. */
FR_INLINE void tri4_test2(const fr_tri4 *tr, const ray_pre *a, float tfa, const ray_pre *b, float tfb,
                          tri4_result *ra, tri4_result *rb) {
  const float *p = tr->v0[0];
  enum { V1 = 12, V2 = 24 };
#define TRI4_LOAD2(off) vf8_join(vf4_load(p + a->off), vf4_load(p + b->off))
  const vfloat8 okx = vf8_join(a->o_k[0], b->o_k[0]), oky = vf8_join(a->o_k[1], b->o_k[1]);
  const vfloat8 okz = vf8_join(a->o_k[2], b->o_k[2]);
  const vfloat8 sx = vf8_join(a->sx, b->sx), sy = vf8_join(a->sy, b->sy);
  vfloat8 az = vf8_sub(okz, TRI4_LOAD2(kz4));
  vfloat8 bz = vf8_sub(okz, TRI4_LOAD2(kz4 + V1));
  vfloat8 cz = vf8_sub(okz, TRI4_LOAD2(kz4 + V2));
  vfloat8 ax = vf8_sub(vf8_sub(okx, TRI4_LOAD2(kx4)), vf8_mul(sx, az));
  vfloat8 ay = vf8_sub(vf8_sub(oky, TRI4_LOAD2(ky4)), vf8_mul(sy, az));
  vfloat8 bx = vf8_sub(vf8_sub(okx, TRI4_LOAD2(kx4 + V1)), vf8_mul(sx, bz));
  vfloat8 by = vf8_sub(vf8_sub(oky, TRI4_LOAD2(ky4 + V1)), vf8_mul(sy, bz));
  vfloat8 cx = vf8_sub(vf8_sub(okx, TRI4_LOAD2(kx4 + V2)), vf8_mul(sx, cz));
  vfloat8 cy = vf8_sub(vf8_sub(oky, TRI4_LOAD2(ky4 + V2)), vf8_mul(sy, cz));
#undef TRI4_LOAD2
  vfloat8 e0 = vf8_sub(vf8_mul(cx, by), vf8_mul(cy, bx));
  vfloat8 e1 = vf8_sub(vf8_mul(ax, cy), vf8_mul(ay, cx));
  vfloat8 e2 = vf8_sub(vf8_mul(bx, ay), vf8_mul(by, ax));
  const vfloat8 zero = vf8(0.0f);
  const int zeros = vf8_eq_bits(e0, zero) | vf8_eq_bits(e1, zero) | vf8_eq_bits(e2, zero);
  const int exact = (zeros & 0x0F ? 0x0F : 0) | (zeros & 0xF0 ? 0xF0 : 0);
  vfloat8 lo = vf8_min(e0, vf8_min(e1, e2)), hi = vf8_max(e0, vf8_max(e1, e2));
  const int inside = (vf8_ge_bits(lo, zero) | vf8_le_bits(hi, zero)) & ~exact;
  vfloat8 t = zero, inv = zero;
  int ok = 0;
  if (inside) {
    vfloat8 det = vf8_add(vf8_add(e0, e1), e2);
    inv = vf8_div(vf8(1.0f), det);
    vfloat8 nsz = vf8_join(a->nsz, b->nsz);
    vfloat8 tz = vf8_add(vf8_add(vf8_mul(e0, vf8_mul(nsz, az)), vf8_mul(e1, vf8_mul(nsz, bz))), vf8_mul(e2, vf8_mul(nsz, cz)));
    t = vf8_mul(tz, inv);
    vfloat8 tn = vf8_join(vf4(a->tnear), vf4(b->tnear)), tf = vf8_join(vf4(tfa), vf4(tfb));
    ok = inside & vf8_ne_bits(det, zero) & vf8_gt_bits(t, tn) & vf8_lt_bits(t, tf);
  }
  ra->t = vf8_lo(t); ra->e1 = vf8_lo(e1); ra->e2 = vf8_lo(e2); ra->inv = vf8_lo(inv); ra->mask = ok & 0x0F;
  rb->t = vf8_hi(t); rb->e1 = vf8_hi(e1); rb->e2 = vf8_hi(e2); rb->inv = vf8_hi(inv); rb->mask = ok >> 4;
  if (ra->mask) tri4_check_thin(tr, a, tfa, ra);
  if (rb->mask) tri4_check_thin(tr, b, tfb, rb);
  if (__builtin_expect(exact != 0, 0)) {
    if (exact & 0x0F) tri4_test(tr, a, tfa, ra);
    if (exact & 0xF0) tri4_test(tr, b, tfb, rb);
  }
}

static inline float tri4_lane(vfloat4 v, int i) {
  float f[4] __attribute__((aligned(16)));
  vf4_store(f, v);
  return f[i];
}

/* The nearest of the hit lanes of res (res->mask != 0; the first on ties)
 * into *best, for block k; returns its t, the ray's new tfar. */
FR_INLINE float tri4_nearest(const tri4_result *res, uint32_t k, fr_subtree_hit *best) {
  int m = res->mask, bl = __builtin_ctz((unsigned)m);
  float bt = tri4_lane(res->t, bl);
  for (m &= m - 1; m; m &= m - 1) {
    int i = __builtin_ctz((unsigned)m);
    float ti = tri4_lane(res->t, i);
    if (ti < bt) { bt = ti; bl = i; }
  }
  float inv = tri4_lane(res->inv, bl);
  best->t = bt;
  best->u = tri4_lane(res->e1, bl) * inv;
  best->v = tri4_lane(res->e2, bl) * inv;
  best->id = 4 * k + (uint32_t)bl;
  return bt;
}
#endif
