/* The scene behind the opaque fr_scene handle (internal: tools and tests of
 * this repository may look inside, users of libfrusta cannot). */
#ifndef FR_API_SCENE_H
#define FR_API_SCENE_H
#include "accel/bvh2.h"
#include "accel/bvhn.h"
#include "accel/plane_occluders.h"
#include "geom/mesh.h"
#include "geom/sphere.h"

struct fr_scene {
  fr_mesh mesh;
  fr_spheres spheres;   /* hit prims mesh.ntris + i */
  fr_bvh2 sphere_bvh;   /* built at commit; empty without spheres */
  fr_bvh2 bvh2;
  fr_bvh2 bvh2_mft;     /* the same with leaves of up to FR_MFT_LEAF, for camera frusta (shares bvh2's triangles) */
  fr_bvhn bvh4, bvh8;
  fr_plane_occluders planes; /* for occlusion queries (accel/plane_occluders.h); bvh2, bvh4 and bvh8 point here */
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
fr_error fr_scene_need_bvh4(fr_scene *s); /* builds the BVH4 on first need (scene.c) */
/* Another binary BVH of a committed scene with leaves of up to max_leaf
 * triangles (the shallow trees multi-frusta tracing may prefer); the caller
 * frees it with fr_bvh2_free. */
fr_error fr_scene_build_bvh2(fr_scene *s, int max_leaf, fr_bvh2 *out);
/* Leaves of the camera frusta's tree. The paper traces frusta through a
 * shallower tree than packets. Against leaves of 4, interleaved, one thread,
 * 1024x1024 (CONCURRENT=1 bench/ab.sh): dragon primary 1.15x (4/5 pairs),
 * 1.06x (3/4), 1.01x (6/8) in three runs; kitchen 1.04x (2/5), sibenik
 * 1.01x (3/5), conference 0.985x (3/5); Whitted kitchen 1.015x (3/4).
 * Shadow frusta stay on leaves of 4: with 8, more tiles' first batches
 * fetch enough triangles to fall back to rays (sibenik 0.4% -> 1.9% of
 * batches) and sibenik soft16 measured 0.91x (3/6). Overbeck's large
 * packets lost 10% with 8 (Whitted kitchen 16x16, museum 32x32). */
#define FR_MFT_LEAF 8
/* fr_occluded_stream as ray streams (FR_TRACE_RAYSTREAM) whatever the
 * scene's trace mode: for callers that know their rays diverge at the
 * scale of the triangles (multi-frusta tiles that fell back to rays). */
void fr_occluded_raystream(const fr_scene *s, const fr_ray *rays, uint8_t *occ, size_t n);
/* The first sphere's prim number (the triangle count). */
static inline uint32_t fr_scene_sphere_base(const fr_scene *s) { return (uint32_t)s->mesh.ntris; }
#endif
