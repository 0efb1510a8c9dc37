/*
 * The spheres' own binary BVH: the fr_bvh2 node layout (so the large-packet
 * traversal walks it like the triangle tree), with leaves of up to four
 * spheres and the spheres copied in leaf order (fr_bvh2.spheres; prims maps
 * a leaf-order index back to the sphere's index in the scene).
 */
#ifndef FR_ACCEL_SPHERE_BVH_H
#define FR_ACCEL_SPHERE_BVH_H
#include "accel/bvh2.h"
#include "geom/sphere.h"

#define FR_SPHERE_LEAF 4

/* An empty set gives an empty tree (nprims 0) that every traversal skips. */
fr_error fr_sphere_bvh_build(const fr_spheres *set, fr_bvh2 *out);
/* A sphere's box, rounded outward so that float rounding in the box test
 * cannot lose a grazing hit. */
aabb fr_sphere_box(const fr_sphere *s);
#endif
