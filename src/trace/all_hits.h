/* Every crossing of a ray with the triangles of a binary BVH, each triangle
 * once: the kernel of fr_intersect_all.
 *
 * Exactly once, also where a ray passes through a shared edge or vertex:
 * the vertices are projected into the ray's sheared frame as the
 * watertight test does (each vertex once per ray, so every triangle sees
 * the same projected vertex), the three edge values are evaluated in
 * double, where their signs are exact, and an edge value of exactly zero
 * takes the sign it would have if the ray moved by an infinitesimal
 * (eps, eps^2) in that frame. That perturbed point lies on no edge, so it
 * lies in exactly the triangles it lies in: once through a consistently
 * oriented closed surface, never twice at a seam, never zero times. */
#ifndef FR_TRACE_ALL_HITS_H
#define FR_TRACE_ALL_HITS_H
#include <stddef.h>
#include "accel/bvh2.h"
#include "geom/mesh.h"

/* One crossing: t is the plane's distance in double, rounded once. */
typedef struct fr_crossing {
  float t, u, v;
  uint32_t prim;
} fr_crossing;

/* A growable list of crossings, reused from ray to ray. */
typedef struct fr_crossings {
  fr_crossing *items;
  size_t n, cap;
} fr_crossings;

/* Collects the ray's crossings in (tnear, tfar) into c (emptied first),
 * sorted by t then prim, each prim once. FR_ERR_NOMEM if the list cannot
 * grow. An invalid ray (NaN, tnear > tfar, zero direction) has none. */
fr_error fr_bvh2_all_hits(const fr_bvh2 *b, const fr_mesh *m, const fr_ray *ray, fr_crossings *c);
/* The test on one triangle (for brute-force checks): 1 and t, u, v where
 * the ray crosses it in (tnear, tfar). */
int fr_tri_crossing(const fr_ray *ray, const float p0[3], const float p1[3], const float p2[3], float *t, float *u,
                    float *v);
void fr_crossings_free(fr_crossings *c);
#endif
