/*
 * A few rays against one four-triangle block in one packet-wide test: lane
 * 4j + i is ray j against triangle i, so a 16-lane packet tests four rays
 * (an 8-lane one two) against a whole block at once. For a packet's leaves
 * reached by only a few of its rays: testing the leaf's triangles one at a
 * time against all P lanes leaves most of each test idle (dragon shadow
 * packets had 3.5 active rays per triangle test).
 *
 * Each lane makes exactly the operations of tri4_test (bvhn_ray.h), the
 * single-ray kernel's watertight test, so a ray gets the single-ray
 * kernel's answer at every ISA level. That needs the same permuted axes
 * for all rays (the shear frame is chosen per ray by its largest direction
 * component); a packet whose rays disagree keeps the one-triangle test.
 * Include after base/simd_packet.h.
 */
#ifndef FR_TRACE_TRI4_QUAD_H
#define FR_TRACE_TRI4_QUAD_H
#include "accel/bvhn.h"
#include "base/simd_packet.h"
#include "geom/tri_watertight.h"

enum { QUAD_RAYS = P / 4 }; /* rays per test */

/* The watertight test's per-ray setup for all P lanes (fr_wt_setup, lane by
 * lane): origin in the shear frame, shear, -sz. ok: 1 when the valid lanes
 * share the permuted axes, 0 when not, -1 before quad_setup. */
typedef struct quad_rays {
  vpf okx, oky, okz, sx, sy, nsz;
  const float (*o)[P], (*d)[P]; /* the packet's rays as given: a thin triangle's plane t (quad_plane_t) */
  int kx4, ky4, kz4; /* float offsets of an axis in a block, as ray_pre's */
  int ok;
} quad_rays;

/* o, d: the packet's origins and directions by axis; valid: its lanes. */
FR_INLINE void quad_setup(quad_rays *q, const float (*o)[P], const float (*d)[P], unsigned valid) {
  const vpf dv[3] = {vp_load(d[0]), vp_load(d[1]), vp_load(d[2])};
  const vpf ax = vp_abs(dv[0]), ay = vp_abs(dv[1]), az = vp_abs(dv[2]);
  const unsigned a = vpm_bits(vp_gt(ax, ay)), b = vpm_bits(vp_gt(ax, az)), c = vpm_bits(vp_gt(ay, az));
  /* fr_wt_setup: kz = a ? (b ? 0 : 2) : (c ? 1 : 2) */
  const unsigned k0 = a & b, k1 = ~a & c;
  int kz;
  q->ok = 0;
  q->o = o;
  q->d = d;
  if ((k0 & valid) == valid) kz = 0;
  else if ((k1 & valid) == valid) kz = 1;
  else if (((k0 | k1) & valid) == 0) kz = 2;
  else return;
  int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  const unsigned neg = vpm_bits(vp_lt(dv[kz], vp(0.0f))) & valid;
  if (neg && neg != valid) return;
  if (neg) { int t = kx; kx = ky; ky = t; } /* keep the winding */
  q->sx = vp_div(dv[kx], dv[kz]);
  q->sy = vp_div(dv[ky], dv[kz]);
  q->nsz = vp_sub(vp(0.0f), vp_div(vp(1.0f), dv[kz]));
  q->okx = vp_load(o[kx]);
  q->oky = vp_load(o[ky]);
  q->okz = vp_load(o[kz]);
  q->kx4 = 4 * kx; q->ky4 = 4 * ky; q->kz4 = 4 * kz;
  q->ok = 1;
}

/* The rays of one test, each spread over its four lanes. */
typedef struct quad_group {
  vpf okx, oky, okz, sx, sy, nsz, tnear, tfar;
  int lane[QUAD_RAYS], n; /* their packet lanes */
} quad_group;

/* The first up to QUAD_RAYS rays of `rays` (packet lanes) into g; returns
 * the rays left. Lanes of absent rays repeat the first and are left out of
 * quad_live. */
FR_INLINE unsigned quad_gather(const quad_rays *q, const float *tnear, const float *tfar, unsigned rays,
                               quad_group *g) {
  int32_t idx[P] __attribute__((aligned(64)));
  g->n = 0;
  for (; rays && g->n < QUAD_RAYS; rays &= rays - 1) g->lane[g->n++] = __builtin_ctz(rays);
  for (int i = 0; i < P; i++) idx[i] = g->lane[i / 4 < g->n ? i / 4 : 0];
  g->okx = vp_permute(q->okx, idx);
  g->oky = vp_permute(q->oky, idx);
  g->okz = vp_permute(q->okz, idx);
  g->sx = vp_permute(q->sx, idx);
  g->sy = vp_permute(q->sy, idx);
  g->nsz = vp_permute(q->nsz, idx);
  g->tnear = vp_permute(vp_load(tnear), idx);
  g->tfar = vp_permute(vp_load(tfar), idx);
  return rays;
}

FR_INLINE unsigned quad_live(const quad_group *g) { return (unsigned)((1ull << (4 * g->n)) - 1u); }

/* exact_edges of bvhn_ray.h for P lanes: edge values of exactly zero
 * recomputed in double in the lanes of `lanes` (rare). */
static __attribute__((noinline, cold)) void quad_exact_edges(vpf *e, const vpf *v, unsigned lanes) {
  float E[3][P] __attribute__((aligned(64))), V[6][P] __attribute__((aligned(64))); /* ax ay bx by cx cy */
  for (int k = 0; k < 3; k++) vp_store(E[k], e[k]);
  for (int k = 0; k < 6; k++) vp_store(V[k], v[k]);
  for (int i = 0; i < P; i++) {
    if (!((lanes >> i) & 1)) continue;
    fr_wt_edges_exact(V[0][i], V[1][i], V[2][i], V[3][i], V[4][i], V[5][i], &E[0][i], &E[1][i], &E[2][i]);
  }
  for (int k = 0; k < 3; k++) e[k] = vp_load(E[k]);
}

/* The hit lanes `thin` again with the plane's t in double, dropped where it
 * falls outside (tnear, tfar): tri4_plane_t lane by lane. Returns the hit
 * lanes left. */
static __attribute__((noinline, cold)) unsigned quad_plane_t(const fr_tri4 *tr, const quad_rays *q,
                                                             const quad_group *r, unsigned hit, unsigned thin, vpf *t) {
  float T[P] __attribute__((aligned(64))), tn[P] __attribute__((aligned(64))), tf[P] __attribute__((aligned(64)));
  vp_store(T, *t);
  vp_store(tn, r->tnear);
  vp_store(tf, r->tfar);
  for (; thin; thin &= thin - 1) {
    const int l = __builtin_ctz(thin), i = l % 4, k = r->lane[l / 4];
    const float tt = fr_tri_plane_t(q->o[0][k], q->o[1][k], q->o[2][k], q->d[0][k], q->d[1][k], q->d[2][k],
                                    tr->v0[0][i], tr->v0[1][i], tr->v0[2][i], tr->v1[0][i], tr->v1[1][i],
                                    tr->v1[2][i], tr->v2[0][i], tr->v2[1][i], tr->v2[2][i]);
    if (tt > tn[l] && tt < tf[l]) T[l] = tt;
    else hit &= ~(1u << l);
  }
  *t = vp_load(T);
  return hit;
}

/* What a closest-hit caller needs of the hit lanes. */
typedef struct quad_hit { vpf t, e1, e2, inv; } quad_hit;

/* Block tr against the group's rays in the lanes of live; returns the lanes
 * hit in (tnear, tfar), their t, edge values and 1 / det in *h if h is not
 * NULL. The operations and their order are tri4_test's. */
FR_INLINE unsigned quad_test(const fr_tri4 *tr, const quad_rays *q, const quad_group *r, unsigned live, quad_hit *h) {
  const float *X = tr->v0[0] + q->kx4, *Y = tr->v0[0] + q->ky4, *Z = tr->v0[0] + q->kz4;
  enum { V1 = 12, V2 = 24 };
  const vpf az = vp_sub(r->okz, vp_bcast4(Z));
  const vpf bz = vp_sub(r->okz, vp_bcast4(Z + V1));
  const vpf cz = vp_sub(r->okz, vp_bcast4(Z + V2));
  vpf v[6]; /* ax ay bx by cx cy */
  v[0] = vp_sub(vp_sub(r->okx, vp_bcast4(X)), vp_mul(r->sx, az));
  v[1] = vp_sub(vp_sub(r->oky, vp_bcast4(Y)), vp_mul(r->sy, az));
  v[2] = vp_sub(vp_sub(r->okx, vp_bcast4(X + V1)), vp_mul(r->sx, bz));
  v[3] = vp_sub(vp_sub(r->oky, vp_bcast4(Y + V1)), vp_mul(r->sy, bz));
  v[4] = vp_sub(vp_sub(r->okx, vp_bcast4(X + V2)), vp_mul(r->sx, cz));
  v[5] = vp_sub(vp_sub(r->oky, vp_bcast4(Y + V2)), vp_mul(r->sy, cz));
  vpf e[3];
  e[0] = vp_sub(vp_mul(v[4], v[3]), vp_mul(v[5], v[2]));
  e[1] = vp_sub(vp_mul(v[0], v[5]), vp_mul(v[1], v[4]));
  e[2] = vp_sub(vp_mul(v[2], v[1]), vp_mul(v[3], v[0]));
  const vpf zero = vp(0.0f);
  const unsigned zeros = live & (vpm_bits(vp_eq(e[0], zero)) | vpm_bits(vp_eq(e[1], zero)) | vpm_bits(vp_eq(e[2], zero)));
  if (__builtin_expect(zeros != 0, 0)) quad_exact_edges(e, v, zeros);
  const vpf lo = vp_min(e[0], vp_min(e[1], e[2])), hi = vp_max(e[0], vp_max(e[1], e[2]));
  const unsigned inside = live & (vpm_bits(vp_ge(lo, zero)) | vpm_bits(vp_le(hi, zero)));
  if (!inside) return 0; /* most tests end here, before the division */
  const vpf det = vp_add(vp_add(e[0], e[1]), e[2]);
  const vpf inv = vp_div(vp(1.0f), det);
  const vpf tz = vp_add(vp_add(vp_mul(e[0], vp_mul(r->nsz, az)), vp_mul(e[1], vp_mul(r->nsz, bz))),
                        vp_mul(e[2], vp_mul(r->nsz, cz)));
  vpf t = vp_mul(tz, inv);
  /* det != 0 as tri4_test's unordered compare: a NaN det gives a NaN t,
   * which the ordered compares on t reject either way */
  unsigned hit = inside & ~vpm_bits(vp_eq(det, zero)) & vpm_bits(vp_gt(t, r->tnear)) & vpm_bits(vp_lt(t, r->tfar));
  /* thin triangles' hits take the plane's t, as tri4_check_thin: lane
   * 4j + i is triangle i */
  const unsigned thin = hit & fr_tri4_thin_lanes(tr) * (P == 16 ? 0x1111u : 0x11u);
  if (__builtin_expect(thin != 0, 0)) hit = quad_plane_t(tr, q, r, hit, thin, &t);
  if (h) { h->t = t; h->e1 = e[1]; h->e2 = e[2]; h->inv = inv; }
  return hit;
}
#endif
