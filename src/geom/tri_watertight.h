/*
 * Watertight ray-triangle test (Woop, Benthin, Wald, "Watertight Ray/Triangle
 * Intersection", JCGT 2013), scalar form. The 4-wide form in the traversal
 * kernel (trace/bvhn_single.c) performs exactly the same operations, so both
 * give bit-identical answers.
 *
 * Vertices are moved into the ray's frame and sheared so the ray becomes the
 * +z axis; the test is then three 2D edge functions of the projected vertices
 * against the origin. Each projected vertex is computed once per ray from the
 * vertex alone, and an edge's function in one triangle is the exact negation of
 * the same edge's in its neighbour (a*b - c*d against c*d - a*b; the build uses
 * no FMA contraction), so neither shared edges nor shared vertices leak: the
 * noise sits in the vertex positions, which all triangles share. Edge values
 * that come out exactly zero are recomputed in double (products of floats are
 * exact there) so that ties break the same way everywhere. An earlier Plücker
 * form (edge values from cross products of vertex sums) was watertight on
 * edges but let ~1% of rays aimed exactly at a vertex slip through.
 */
#ifndef FR_GEOM_TRI_WATERTIGHT_H
#define FR_GEOM_TRI_WATERTIGHT_H
#include <math.h>
#include "base/vec3.h"

/* Per-ray precomputation: the dominant axis kz and the shear. */
typedef struct fr_wt_ray { int kx, ky, kz; float sx, sy, sz; } fr_wt_ray;

static inline fr_wt_ray fr_wt_setup(vec3 d) {
  fr_wt_ray w;
  float ax = fabsf(d.x), ay = fabsf(d.y), az = fabsf(d.z);
  w.kz = (ax > ay) ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
  w.kx = w.kz == 2 ? 0 : w.kz + 1;
  w.ky = w.kx == 2 ? 0 : w.kx + 1;
  float dz = v3_get(d, w.kz);
  if (dz < 0.0f) { int t = w.kx; w.kx = w.ky; w.ky = t; } /* keep the winding */
  w.sx = v3_get(d, w.kx) / dz;
  w.sy = v3_get(d, w.ky) / dz;
  w.sz = 1.0f / dz;
  return w;
}

static inline int fr_tri_watertight(const fr_wt_ray *w, vec3 o, float tnear, float tfar, vec3 p0, vec3 p1, vec3 p2,
                                    float *t, float *u, float *v) {
  vec3 a = v3_sub(p0, o), b = v3_sub(p1, o), c = v3_sub(p2, o);
  float az = v3_get(a, w->kz), bz = v3_get(b, w->kz), cz = v3_get(c, w->kz);
  float ax = v3_get(a, w->kx) - w->sx * az, ay = v3_get(a, w->ky) - w->sy * az;
  float bx = v3_get(b, w->kx) - w->sx * bz, by = v3_get(b, w->ky) - w->sy * bz;
  float cx = v3_get(c, w->kx) - w->sx * cz, cy = v3_get(c, w->ky) - w->sy * cz;
  float e0 = cx * by - cy * bx, e1 = ax * cy - ay * cx, e2 = bx * ay - by * ax;
  if (e0 == 0.0f || e1 == 0.0f || e2 == 0.0f) {
    e0 = (float)((double)cx * by - (double)cy * bx);
    e1 = (float)((double)ax * cy - (double)ay * cx);
    e2 = (float)((double)bx * ay - (double)by * ax);
  }
  if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) return 0;
  float det = (e0 + e1) + e2;
  if (det == 0.0f || !(det == det)) return 0;
  float inv = 1.0f / det;
  float tt = ((e0 * (w->sz * az) + e1 * (w->sz * bz)) + e2 * (w->sz * cz)) * inv;
  if (!(tt > tnear && tt < tfar)) return 0;
  *t = tt; *u = e1 * inv; *v = e2 * inv;
  return 1;
}
/* The hit distance again, for the one triangle a closest-hit query returns:
 * the test's t (a weighted sum of sheared z) loses bits on large triangles
 * seen at grazing angles (1e-4 relative on conference walls, against Embree
 * and a double-precision reference); the plane distance in double does not.
 * Kept within (tnear, tfar), so the hit stays a hit. */
static inline float fr_tri_refine_t(vec3 o, vec3 d, float tnear, float tfar, vec3 p0, vec3 p1, vec3 p2, float t) {
  double e1[3] = {(double)p1.x - p0.x, (double)p1.y - p0.y, (double)p1.z - p0.z};
  double e2[3] = {(double)p2.x - p0.x, (double)p2.y - p0.y, (double)p2.z - p0.z};
  double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  double den = n[0] * d.x + n[1] * d.y + n[2] * d.z;
  if (den == 0.0) return t;
  double num = n[0] * ((double)p0.x - o.x) + n[1] * ((double)p0.y - o.y) + n[2] * ((double)p0.z - o.z);
  float r = (float)(num / den);
  return (r > tnear && r < tfar) ? r : t;
}
#endif
