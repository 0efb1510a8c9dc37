/*
 * The watertight Plücker test, scalar form (the 4-wide form lives in the
 * traversal kernel, trace/bvh4_single.c, and computes exactly the same thing).
 *
 * Vertices are first moved into the ray's frame (v = p - o). The weight of each
 * vertex is the signed volume spanned by the ray direction and the opposite
 * edge, computed as dot(d, cross(b - a, b + a)) (= 2 [d, b, a]). For an edge a
 * neighbouring triangle shares, it computes cross(a - b, a + b) from the very
 * same floats: b - a and a - b are exact negations, a + b is commutative, and
 * cross and dot commute with negation bit for bit. So the two triangles see
 * exactly opposite edge values and a ray can never pass between them: the test
 * is watertight without a slower fallback, at the price of three cross products
 * of sums instead of Möller's two.
 */
#ifndef FR_GEOM_TRI_PLUECKER_H
#define FR_GEOM_TRI_PLUECKER_H
#include "base/vec3.h"

static inline int fr_tri_pluecker(vec3 o, vec3 d, float tnear, float tfar, vec3 p0, vec3 p1, vec3 p2,
                                  float *t, float *u, float *v) {
  vec3 v0 = v3_sub(p0, o), v1 = v3_sub(p1, o), v2 = v3_sub(p2, o);
  float w0 = v3_dot(d, v3_cross(v3_sub(v1, v2), v3_add(v1, v2)));
  float w1 = v3_dot(d, v3_cross(v3_sub(v2, v0), v3_add(v2, v0)));
  float w2 = v3_dot(d, v3_cross(v3_sub(v0, v1), v3_add(v0, v1)));
  float lo = fminf(w0, fminf(w1, w2)), hi = fmaxf(w0, fmaxf(w1, w2));
  if (!(lo >= 0.0f || hi <= 0.0f)) return 0;
  float den = (w0 + w1) + w2;
  if (den == 0.0f || !(den == den)) return 0;
  vec3 ng = v3_cross(v3_sub(v1, v0), v3_sub(v2, v0));
  float inv = 1.0f / den;
  float tt = 2.0f * v3_dot(v0, ng) * inv;
  if (!(tt > tnear && tt < tfar)) return 0;
  *t = tt; *u = w1 * inv; *v = w2 * inv;
  return 1;
}
#endif
