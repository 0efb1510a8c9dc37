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

/* Without branches: for the scattered directions of AO and path rays the
 * axis choice is a coin toss per ray, and its mispredictions took a tenth
 * of the occlusion streams' time (conference ao16). The same choice as
 * kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2), kx the next axis
 * after kz, ky the next after kx, both swapped where d[kz] < 0. */
static inline fr_wt_ray fr_wt_setup(vec3 d) {
  fr_wt_ray w;
  const float v[3] = {d.x, d.y, d.z};
  float ax = fabsf(d.x), ay = fabsf(d.y), az = fabsf(d.z);
  int a = ax > ay, b = ax > az, c = ay > az;
  w.kz = a * 2 * (1 - b) + (1 - a) * (2 - c);
  w.kx = (0x021 >> (4 * w.kz)) & 0xF; /* next axis: 0 -> 1, 1 -> 2, 2 -> 0 */
  w.ky = (0x021 >> (4 * w.kx)) & 0xF;
  float dz = v[w.kz];
  int swap = -(int)(dz < 0.0f), t = (w.kx ^ w.ky) & swap; /* keep the winding */
  w.kx ^= t;
  w.ky ^= t;
  w.sx = v[w.kx] / dz;
  w.sy = v[w.ky] / dz;
  w.sz = 1.0f / dz;
  return w;
}

/* The three edge values in double, rounded once: for a ray through an edge
 * or a vertex, where a float edge value came out exactly zero, their signs
 * say which of the triangles that share it is hit. Every watertight test
 * (this one, and the 4- and P-lane ones of the kernels) takes this path. */
static inline void fr_wt_edges_exact(float ax, float ay, float bx, float by, float cx, float cy, float *e0, float *e1,
                                     float *e2) {
  *e0 = (float)((double)cx * by - (double)cy * bx);
  *e1 = (float)((double)ax * cy - (double)ay * cx);
  *e2 = (float)((double)bx * ay - (double)by * ax);
}

/* The plane's t in double, (n . (p0 - o)) / (n . d) with n = (p1 - p0) x
 * (p2 - p0), rounded once; NaN or inf where d lies in the plane. On plain
 * floats and without branches, so that a loop over a packet's rays
 * vectorizes; IEEE double operations give the same bits either way. */
static inline float fr_tri_plane_t(float ox, float oy, float oz, float dx, float dy, float dz, float ax, float ay,
                                   float az, float bx, float by, float bz, float cx, float cy, float cz) {
  double e1x = (double)bx - ax, e1y = (double)by - ay, e1z = (double)bz - az;
  double e2x = (double)cx - ax, e2y = (double)cy - ay, e2z = (double)cz - az;
  double nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
  double den = nx * dx + ny * dy + nz * dz;
  double num = nx * ((double)ax - ox) + ny * ((double)ay - oy) + nz * ((double)az - oz);
  return (float)(num / den);
}

/* A thin triangle, whose watertight t a hit cannot trust: each sheared
 * coordinate is off by a few 2^-24 of the vertices' distance, the edge
 * values by that times the triangle's size, and t by their sum over det,
 * twice the projected area. For a triangle whose longest edge squared
 * exceeds FR_WT_THIN times twice its area (thinner than 1/256 of its length:
 * slivers and needles) that reaches many ulps of the
 * distance (a ray leaving a sliver met it again 0.045 on, where the plane
 * is 1.4e-6 away), so a hit on one takes the plane's t in double instead,
 * and is no hit where that falls outside (tnear, tfar). The BVH marks them
 * once (accel/bvhn.h, FR_TRI4_THIN); the other triangles' t is refined
 * once, for the hit a query returns (fr_tri_refine_t). */
#define FR_WT_THIN 256.0
static inline int fr_tri_thin(float ax, float ay, float az, float bx, float by, float bz, float cx, float cy,
                              float cz) {
  double e1[3] = {(double)bx - ax, (double)by - ay, (double)bz - az};
  double e2[3] = {(double)cx - ax, (double)cy - ay, (double)cz - az};
  double e3[3] = {(double)cx - bx, (double)cy - by, (double)cz - bz};
  double nx = e1[1] * e2[2] - e1[2] * e2[1], ny = e1[2] * e2[0] - e1[0] * e2[2], nz = e1[0] * e2[1] - e1[1] * e2[0];
  double l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2], l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
  double l3 = e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2];
  double lmax = l1 > l2 ? (l1 > l3 ? l1 : l3) : (l2 > l3 ? l2 : l3);
  return lmax > FR_WT_THIN * sqrt(nx * nx + ny * ny + nz * nz);
}

static inline int fr_tri_watertight(const fr_wt_ray *w, vec3 o, vec3 d, float tnear, float tfar, vec3 p0, vec3 p1,
                                    vec3 p2, float *t, float *u, float *v) {
  vec3 a = v3_sub(p0, o), b = v3_sub(p1, o), c = v3_sub(p2, o);
  float az = v3_get(a, w->kz), bz = v3_get(b, w->kz), cz = v3_get(c, w->kz);
  float ax = v3_get(a, w->kx) - w->sx * az, ay = v3_get(a, w->ky) - w->sy * az;
  float bx = v3_get(b, w->kx) - w->sx * bz, by = v3_get(b, w->ky) - w->sy * bz;
  float cx = v3_get(c, w->kx) - w->sx * cz, cy = v3_get(c, w->ky) - w->sy * cz;
  float e0 = cx * by - cy * bx, e1 = ax * cy - ay * cx, e2 = bx * ay - by * ax;
  if (e0 == 0.0f || e1 == 0.0f || e2 == 0.0f) fr_wt_edges_exact(ax, ay, bx, by, cx, cy, &e0, &e1, &e2);
  if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) return 0;
  float det = (e0 + e1) + e2;
  if (det == 0.0f || !(det == det)) return 0;
  float inv = 1.0f / det;
  float tt = ((e0 * (w->sz * az) + e1 * (w->sz * bz)) + e2 * (w->sz * cz)) * inv;
  if (!(tt > tnear && tt < tfar)) return 0;
  if (fr_tri_thin(p0.x, p0.y, p0.z, p1.x, p1.y, p1.z, p2.x, p2.y, p2.z)) {
    tt = fr_tri_plane_t(o.x, o.y, o.z, d.x, d.y, d.z, p0.x, p0.y, p0.z, p1.x, p1.y, p1.z, p2.x, p2.y, p2.z);
    if (!(tt > tnear && tt < tfar)) return 0;
  }
  *t = tt; *u = e1 * inv; *v = e2 * inv;
  return 1;
}

/* The hit distance again, for the one triangle a closest-hit query returns:
 * the test's t (a weighted sum of sheared z) loses bits on large triangles
 * seen at grazing angles (1e-4 relative on conference walls, against Embree
 * and a double-precision reference); the plane distance in double does not.
 * Kept within (tnear, tfar), so the hit stays a hit. On plain floats and
 * without branches, so that a loop over a packet's rays vectorizes; IEEE
 * double operations give the same bits either way. */
static inline float fr_tri_refine_lane(float ox, float oy, float oz, float dx, float dy, float dz, float tnear,
                                       float tfar, float ax, float ay, float az, float bx, float by, float bz, float cx,
                                       float cy, float cz, float t) {
  float r = fr_tri_plane_t(ox, oy, oz, dx, dy, dz, ax, ay, az, bx, by, bz, cx, cy, cz);
  return ((r > tnear) & (r < tfar)) ? r : t;
}
static inline float fr_tri_refine_t(vec3 o, vec3 d, float tnear, float tfar, vec3 p0, vec3 p1, vec3 p2, float t) {
  return fr_tri_refine_lane(o.x, o.y, o.z, d.x, d.y, d.z, tnear, tfar, p0.x, p0.y, p0.z, p1.x, p1.y, p1.z, p2.x, p2.y,
                            p2.z, t);
}
#endif
