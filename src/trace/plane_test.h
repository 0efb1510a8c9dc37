/*
 * Rays against a planar occluder (accel/plane_occluders.h), a packet's
 * lanes at once: the kernels' form of fr_plane_occluder_hit, with the same
 * margins. Include after base/simd_packet.h.
 */
#ifndef FR_TRACE_PLANE_TEST_H
#define FR_TRACE_PLANE_TEST_H
#include "accel/plane_occluders.h"
#include "base/simd_packet.h"

/* The lanes whose rays o + t d, t in (tnear, tfar), cross p inside by the
 * margins, where the crossings are known inside the edges not in `edges`
 * (bit k: edge k) by the margins. */
FR_INLINE unsigned fr_plane_hits_edges(const fr_plane_occluder *p, const vpf o[3], const vpf d[3], vpf tnear, vpf tfar,
                                       unsigned edges) {
  const int a = p->axis, u = (a + 1) % 3, v = (a + 2) % 3;
  const vpf c = vp(p->c), toward = vp_sub(c, o[a]);
  const vpf t = vp_div(toward, d[a]);
  /* the origin clearly off the plane, t inside the range by a margin of itself */
  vpm in = vp_gt(vp_abs(toward), vp_mul(vp(FR_PLANE_ORG_MARGIN), vp_add(vp_abs(o[a]), vp_abs(c))));
  const vpf dt = vp_mul(vp(FR_PLANE_T_MARGIN), vp_abs(t));
  in = vpm_and(in, vpm_and(vp_gt(vp_sub(t, dt), tnear), vp_lt(vp_add(t, dt), tfar)));
  const vpf su = vp_mul(t, d[u]), sv = vp_mul(t, d[v]);
  const vpf pu = vp_add(o[u], su), pv = vp_add(o[v], sv);
  /* most crossings miss the polygon's box: no edge tests then (they cost
   * hemisphere packets, which cross most planes, 11% on kitchen ao16) */
  in = vpm_and(in, vpm_and(vpm_and(vp_ge(pu, vp(p->lo[0])), vp_le(pu, vp(p->hi[0]))),
                           vpm_and(vp_ge(pv, vp(p->lo[1])), vp_le(pv, vp(p->hi[1])))));
  if (!vpm_bits(in) || !edges) return vpm_bits(in);
  /* the crossing's rounding, generously */
  const vpf err = vp_mul(vp(FR_PLANE_POINT_MARGIN), vp_add(vp_add(vp_abs(o[u]), vp_abs(o[v])), vp_add(vp_abs(su), vp_abs(sv))));
  for (; edges; edges &= edges - 1) {
    const int k = __builtin_ctz(edges);
    in = vpm_and(in, vp_le(vp_add(vp_add(vp_mul(vp(p->nu[k]), pu), vp_mul(vp(p->nv[k]), pv)), err), vp(p->e[k])));
  }
  return vpm_bits(in);
}

/* The lanes whose rays o + t d, t in (tnear, tfar), cross p inside by the
 * margins. */
FR_INLINE unsigned fr_plane_hits(const fr_plane_occluder *p, const vpf o[3], const vpf d[3], vpf tnear, vpf tfar) {
  return fr_plane_hits_edges(p, o, d, tnear, tfar, (1u << p->nedges) - 1u);
}
#endif
