/* Möller–Trumbore: the plain reference ray-triangle test (one ray, one triangle). */
#ifndef FR_GEOM_TRI_MOLLER_H
#define FR_GEOM_TRI_MOLLER_H
#include "base/vec3.h"

/* Returns 1 and t,u,v when the ray hits with tnear < t < tfar. Zero-area
 * triangles (det == 0) never hit; NaN inputs fail every comparison. */
static inline int fr_tri_moller(vec3 o, vec3 d, float tnear, float tfar, vec3 p0, vec3 p1, vec3 p2,
                                float *t, float *u, float *v) {
  vec3 e1 = v3_sub(p1, p0), e2 = v3_sub(p2, p0);
  vec3 pv = v3_cross(d, e2);
  float det = v3_dot(e1, pv);
  if (det == 0.0f || !(det == det)) return 0;
  float inv = 1.0f / det;
  vec3 tv = v3_sub(o, p0);
  float uu = v3_dot(tv, pv) * inv;
  if (!(uu >= 0.0f && uu <= 1.0f)) return 0;
  vec3 qv = v3_cross(tv, e1);
  float vv = v3_dot(d, qv) * inv;
  if (!(vv >= 0.0f && uu + vv <= 1.0f)) return 0;
  float tt = v3_dot(e2, qv) * inv;
  if (!(tt > tnear && tt < tfar)) return 0;
  *t = tt; *u = uu; *v = vv;
  return 1;
}
#endif
