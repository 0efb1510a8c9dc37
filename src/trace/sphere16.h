/*
 * Sixteen rays against one sphere, lane by lane the operations of
 * fr_sphere_roots and fr_sphere_hit (geom/sphere.h) in their order, so that
 * every lane's answer is the single-ray test's bit for bit. For kernels
 * compiled per ISA with FR_PACKET 16 (base/simd_packet.h).
 */
#ifndef FR_TRACE_SPHERE16_H
#define FR_TRACE_SPHERE16_H
#include "base/simd_packet.h"
#include "geom/sphere.h"

/* The lanes of m whose ray (origin o, direction d) meets sphere s at a
 * distance in (tn, tf); *t gets it there (from inside the sphere the far
 * root). */
FR_INLINE unsigned fr_sphere16_hit(const fr_sphere *s, const vpf o[3], const vpf d[3], vpf tn, vpf tf, unsigned m,
                                   vpf *t) {
  const vpf dx = d[0], dy = d[1], dz = d[2];
  const vpf fx = vp_sub(o[0], vp(s->c[0])), fy = vp_sub(o[1], vp(s->c[1])), fz = vp_sub(o[2], vp(s->c[2]));
  const vpf a = vp_add(vp_add(vp_mul(dx, dx), vp_mul(dy, dy)), vp_mul(dz, dz));
  const vpf b = vp_xor(vp_add(vp_add(vp_mul(fx, dx), vp_mul(fy, dy)), vp_mul(fz, dz)), vp(-0.0f));
  const vpf tc = vp_div(b, a);
  const vpf lx = vp_add(fx, vp_mul(tc, dx)), ly = vp_add(fy, vp_mul(tc, dy)), lz = vp_add(fz, vp_mul(tc, dz));
  const vpf r2 = vp(s->r * s->r);
  const vpf h = vp_sub(r2, vp_add(vp_add(vp_mul(lx, lx), vp_mul(ly, ly)), vp_mul(lz, lz)));
  m &= vpm_bits(vp_ge(h, vp(0.0f)));
  if (!m) return 0;
  const vpf cc = vp_sub(vp_add(vp_add(vp_mul(fx, fx), vp_mul(fy, fy)), vp_mul(fz, fz)), r2);
  const vpf q = vp_add(b, vp_copysign(vp_sqrt(vp_mul(a, h)), b));
  const vpf t1 = vp_div(q, a), t2 = vp_select(vp_eq(q, vp(0.0f)), t1, vp_div(cc, q));
  const vpf near = vp_min(t1, t2), far = vp_max(t2, t1);
  *t = vp_select(vp_gt(near, tn), near, far);
  return m & vpm_bits(vpm_and(vp_gt(*t, tn), vp_lt(*t, tf)));
}
#endif
