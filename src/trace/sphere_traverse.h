/* Single rays through the sphere tree (accel/sphere_bvh.h), scalar: scenes
 * hold far fewer spheres than triangles, and the packet calls run their
 * rays through here one by one after the triangle kernels. */
#ifndef FR_TRACE_SPHERE_TRAVERSE_H
#define FR_TRACE_SPHERE_TRAVERSE_H
#include "accel/bvh2.h"
#include "frusta.h"

/* If a sphere lies nearer than hit->t (or ray->tfar on a miss) within the
 * ray's range, overwrites *hit with it: prim = prim_base + the sphere's
 * index, u = v = 0, ng = hit point - centre. */
void fr_spheres_intersect1(const fr_bvh2 *b, uint32_t prim_base, const fr_ray *ray, fr_hit *hit);
int fr_spheres_occluded1(const fr_bvh2 *b, const fr_ray *ray);
/* Brute force over every sphere (the reference for tests). */
void fr_spheres_intersect1_brute(const fr_bvh2 *b, uint32_t prim_base, const fr_ray *ray, fr_hit *hit);
/* Sixteen rays for fr_spheres16 (kernels.h), one row per quantity. */
typedef struct fr_sphere_rays16 {
  float o[3][16], d[3][16], tnear[16], tfar[16];
  uint32_t li[16]; /* the leaf-order index of a lane's sphere hit */
} __attribute__((aligned(64))) fr_sphere_rays16;
/* The fr_hit of a hit at t on the sphere at leaf-order index li. */
void fr_spheres_hit(const fr_bvh2 *b, uint32_t prim_base, const fr_ray *ray, uint32_t li, float t, fr_hit *hit);
#endif
