/* The scene behind the opaque fr_scene handle (internal: tools and tests of
 * this repository may look inside, users of libfrusta cannot). */
#ifndef FR_API_SCENE_H
#define FR_API_SCENE_H
#include "accel/bvh2.h"
#include "accel/bvhn.h"
#include "geom/mesh.h"
#include "geom/sphere.h"

struct fr_scene {
  fr_mesh mesh;
  fr_spheres spheres;   /* hit prims mesh.ntris + i */
  fr_bvh2 sphere_bvh;   /* built at commit; empty without spheres */
  fr_bvh2 bvh2;
  fr_bvhn bvh4, bvh8;
  int single_width;     /* 4 or 8: the BVH fr_intersect1 traverses */
  fr_trace_options trace; /* how packets and streams are traced */
  int committed;
  size_t skipped;       /* degenerate triangles left out of the BVH */
  aabb bounds;
  double build_seconds;
  char name[64];        /* scene name for views and reports */
};

/* Sets the BVH4's and BVH8's prefetching from the trace options. */
void fr_scene_apply_prefetch(fr_scene *s);
/* Another binary BVH of a committed scene with leaves of up to max_leaf
 * triangles (the shallow trees multi-frusta tracing may prefer); the caller
 * frees it with fr_bvh2_free. */
fr_error fr_scene_build_bvh2(fr_scene *s, int max_leaf, fr_bvh2 *out);
/* The first sphere's prim number (the triangle count). */
static inline uint32_t fr_scene_sphere_base(const fr_scene *s) { return (uint32_t)s->mesh.ntris; }
#endif
