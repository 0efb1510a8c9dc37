/*
 * The edge cross products of one triangle seen from 16 origins (one per
 * lane), shared by the multi-frusta and the large-packet kernels. Include
 * after base/simd_packet.h (FR_PACKET 16).
 *
 *   E_0 = (v1-o) x (v2-o), E_1 = (v2-o) x (v0-o), E_2 = (v0-o) x (v1-o)
 *   det = (v0-o) . n,  n = (v1 - v0) x (v2 - v0) (fr_bvh2_tri_normal)
 *
 * A ray o + t d hits when every d . E_i has the sign of det, at
 * t = det / (d . n); the barycentrics of v1, v2 are d . E_1, d . E_2 over
 * their sum. Each E_i is computed as (P - o) x (Q - P) from the edge's
 * lexicographically smaller vertex P: the error is then relative to the
 * triangle's size, not to its distance squared (tiny far triangles would
 * otherwise get their barycentrics wrong by 10%), and the neighbouring
 * triangle computes exactly the negated value, so no ray slips between two
 * triangles: watertight at no extra cost.
 */
#ifndef FR_TRACE_TRI_EDGES16_H
#define FR_TRACE_TRI_EDGES16_H
#include "accel/bvh2.h"

FR_INLINE vpf fr_dot3v(vpf ax, vpf ay, vpf az, vpf bx, vpf by, vpf bz) {
  return vp_add(vp_add(vp_mul(ax, bx), vp_mul(ay, by)), vp_mul(az, bz));
}

/* c = a x b with v3_cross's operations, so lane by lane the same bits (the
 * edge products below) */
FR_INLINE void fr_cross3v(const vpf a[3], const vpf b[3], vpf c[3]) {
  c[0] = vp_sub(vp_mul(a[1], b[2]), vp_mul(a[2], b[1]));
  c[1] = vp_sub(vp_mul(a[2], b[0]), vp_mul(a[0], b[2]));
  c[2] = vp_sub(vp_mul(a[0], b[1]), vp_mul(a[1], b[0]));
}

FR_INLINE void fr_tri_edges16(const fr_bvh2_tri *r, const float n[3], const vpf o[3], vpf E[3][3], vpf *det) {
  vpf A[3], B[3], C[3];
  for (int a = 0; a < 3; a++) {
    A[a] = vp_sub(vp(r->v0[a]), o[a]);
    B[a] = vp_sub(vp(r->v1[a]), o[a]);
    C[a] = vp_sub(vp(r->v2[a]), o[a]);
  }
  *det = fr_dot3v(A[0], A[1], A[2], vp(n[0]), vp(n[1]), vp(n[2]));
  const float *ends[3][2] = {{r->v1, r->v2}, {r->v2, r->v0}, {r->v0, r->v1}};
  const vpf *from[3][2] = {{B, C}, {C, A}, {A, B}};
  for (int i = 0; i < 3; i++) {
    int flip = (r->edge_flip >> i) & 1;
    const float *p = ends[i][flip], *q = ends[i][!flip];
    const vpf *po = from[i][flip];
    const vpf d[3] = {vp(q[0] - p[0]), vp(q[1] - p[1]), vp(q[2] - p[2])}, sg = vp(flip ? -0.0f : 0.0f);
    vpf c[3];
    fr_cross3v(po, d, c);
    for (int a = 0; a < 3; a++) E[i][a] = vp_xor(c[a], sg);
  }
}

/* The lanes of m whose ray d hits (edges and det from fr_tri_edges16) */
FR_INLINE unsigned fr_tri_edges16_inside(vpf dx, vpf dy, vpf dz, vpf E[3][3], vpf det, unsigned m, vpf w[3]) {
  for (int i = 0; i < 3; i++) w[i] = fr_dot3v(dx, dy, dz, E[i][0], E[i][1], E[i][2]);
  vpf sg = vp_and(det, vp(-0.0f)), zero = vp(0.0f);
  return m & vpm_bits(vpm_and(vpm_and(vp_ge(vp_xor(w[0], sg), zero), vp_ge(vp_xor(w[1], sg), zero)),
                              vp_ge(vp_xor(w[2], sg), zero)));
}
#endif
