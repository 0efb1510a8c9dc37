/* The scene behind the opaque fr_scene handle (internal: tools and tests of
 * this repository may look inside, users of libfrusta cannot). */
#ifndef FR_API_SCENE_H
#define FR_API_SCENE_H
#include "accel/bvh2.h"
#include "accel/bvhn.h"
#include "accel/plane_occluders.h"
#include "base/tuning.h"
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
  fr_tuning trace; /* how packets and streams are traced */
  int committed;
  size_t skipped;       /* degenerate triangles left out of the BVH */
  aabb bounds;
  double build_seconds;
  char name[64];        /* scene name for views and reports */
  struct fr_scene_file *file; /* the scene file it was loaded from, meshes aside (NULL if none) */
};

/* How the scene's packets and streams are traced (base/tuning.h): for
 * measurements and tests. FR_ERR_ARG for a field out of range; a 4-wide
 * packet BVH is built here if the scene has none. Call while no thread
 * traces the scene. */
fr_error fr_scene_set_tuning(fr_scene *s, const fr_tuning *t);
void fr_scene_get_tuning(const fr_scene *s, fr_tuning *t);
/* Which BVH the single-ray calls traverse: 8-wide (default) or 4-wide (the
 * MIC paper's; FRUSTA_BVH_WIDTH=4 for new scenes). A 4-wide BVH is built
 * on first need: choose it before the commit, or while no thread traces. */
fr_error fr_scene_set_bvh_width(fr_scene *s, int width);
/* Plain scalar traversal of the binary BVH with the scalar watertight test:
 * the reference the kernels are tested against. */
void fr_intersect1_reference(const fr_scene *s, const fr_ray *ray, fr_hit *hit);
int fr_occluded1_reference(const fr_scene *s, const fr_ray *ray);
/* Sets the BVH4's and BVH8's prefetching from the trace options. */
void fr_scene_apply_prefetch(fr_scene *s);
fr_error fr_scene_need_bvh4(fr_scene *s); /* builds the BVH4 on first need (scene.c) */
/* Another binary BVH of a committed scene with leaves of up to max_leaf
 * triangles (the shallow trees multi-frusta tracing may prefer); the caller
 * frees it with fr_bvh2_free. */
fr_error fr_scene_build_bvh2(fr_scene *s, int max_leaf, fr_bvh2 *out);
/* Leaves of the camera frusta's tree: the paper traces frusta through a
 * shallower tree than packets, and camera frusta run fastest on leaves of
 * 8. Shadow frusta stay on leaves of 4: with 8, more tiles' first batches
 * fetch enough triangles to fall back to rays. Large packets too lose with
 * 8. */
#define FR_MFT_LEAF 8
/* fr_occluded_stream as ray streams (FR_TRACE_RAYSTREAM) whatever the
 * scene's trace mode: for callers that know their rays diverge at the
 * scale of the triangles (multi-frusta tiles that fell back to rays). */
void fr_occluded_raystream(const fr_scene *s, const fr_ray *rays, uint8_t *occ, size_t n);
/* A scene file's meshes (io/scene_file.h) as one scene, named after the
 * file; files it names stay under root (NULL: the file's folder). The
 * scene keeps the rest of the file (camera, lights, materials, render
 * settings) in s->file. */
struct fr_scene_file;
fr_error fr_scene_load_json(const char *path, const char *root, fr_scene **out);
/* The path tracer's material called name in the scene file s was loaded
 * from, or NULL. */
const struct fr_bsdf *fr_scene_file_bsdf(const fr_scene *s, const char *name);
/* The unit shading normal of triangle prim at barycentrics (u, v): its
 * corner normals interpolated; 0 where it has none (flat). */
int fr_scene_shading_normal(const fr_scene *s, uint32_t prim, float u, float v, float n[3]);
/* The texture coordinates of triangle prim at barycentrics (u, v); 0
 * where it has none. */
int fr_scene_texcoord(const fr_scene *s, uint32_t prim, float u, float v, float st[2]);
/* Starts loading what the two calls above read of triangle prim (its
 * corners' normal and texture indices), for a shader a few hits ahead. */
static inline void fr_scene_prefetch_shading(const fr_scene *s, uint32_t prim) {
  if (prim >= s->mesh.ntris) return;
  if (s->mesh.nrm.idx) __builtin_prefetch(s->mesh.nrm.idx + 3 * (size_t)prim);
  if (s->mesh.uv.idx) __builtin_prefetch(s->mesh.uv.idx + 3 * (size_t)prim);
}
/* Triangle prim's unnormalized normal (v1 - v0) x (v2 - v0) made in double
 * and rounded once, the bits the kernels report (fr_tri_normal_lane). */
static inline void fr_scene_triangle_normal(const fr_scene *s, uint32_t prim, float ng[3]) {
  const uint32_t *ix = s->mesh.idx + 3 * (size_t)prim;
  const float *a = s->mesh.pos + 3 * (size_t)ix[0], *b = s->mesh.pos + 3 * (size_t)ix[1], *c = s->mesh.pos + 3 * (size_t)ix[2];
  fr_tri_normal_lane(a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2], &ng[0], &ng[1], &ng[2]);
}
/* The first sphere's prim number (the triangle count). */
static inline uint32_t fr_scene_sphere_base(const fr_scene *s) { return (uint32_t)s->mesh.ntris; }
#endif
