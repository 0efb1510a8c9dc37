/*
 * What the tile drivers of the workloads share (internal to src/render): a
 * tile's buffers, and the hit shading every tracer's rays go through, so
 * that frusta and Embree shade with the same normals and materials.
 */
#ifndef FR_RENDER_TILE_H
#define FR_RENDER_TILE_H
#include <math.h>
#include "api/scene.h"
#include "base/vec3.h"
#include "render/workload.h"

#define TILE 16 /* 16 blocks of 4x4 pixels: one batch of 16 frusta */
#define TILE_PIX (TILE * TILE)
#define MAX_SEC 16 /* secondary rays per pixel */

typedef struct fr_tile_buffers {
  fr_ray rays[TILE_PIX * MAX_SEC];
  fr_hit hits[TILE_PIX * MAX_SEC];
  uint8_t occ[TILE_PIX * MAX_SEC];
  int px[TILE_PIX], py[TILE_PIX];
  fr_hit prim_hit[TILE_PIX];
  fr_ray prim_ray[TILE_PIX];
  int owner[TILE_PIX * MAX_SEC];
  /* soft shadows: a tile's batches held back for ray streams, the rays
   * their frusta found occluded, and their batch numbers */
  fr_mft_batch held[TILE_PIX / 16];
  uint16_t held_occ[TILE_PIX / 16][FR_MFT_FRUSTA];
  int held_j[TILE_PIX / 16];
} fr_tile_buffers;

/* One 16x16 tile of any workload but Whitted (tile.c): returns the rays
 * traced; writes shaded pixels when w->image is set. */
uint64_t fr_tile_run(const fr_workload *w, const fr_tracer *t, fr_tile_buffers *B, int tx, int ty);

/* Soft shadows of a tile's n pixels from their primary hits (soft_tile.c):
 * lit[i] gets pixel i's unoccluded fraction; returns the shadow rays
 * traced. */
uint64_t fr_tile_soft_shadows(const fr_workload *w, const fr_tracer *t, fr_tile_buffers *B, int n, float *lit);

/* order[i]: the i-th tile of a tiles_x x tiles_y grid to trace, as
 * y * tiles_x + x (tile_order.c); NULL without memory. */
uint32_t *fr_tile_order(int tiles_x, int tiles_y);

/* Unit geometric normal of a hit, facing the ray; taken from the scene so that
 * every tracer shades with the same normals. */
static inline vec3 hit_point(const fr_ray *r, const fr_hit *h) {
  return v3_add(v3_load(r->org), v3_scale(v3_load(r->dir), h->t));
}

static inline vec3 facing_normal(const fr_scene *s, const fr_hit *h, const fr_ray *r) {
  vec3 p = hit_point(r, h), d = v3_load(r->dir);
  float g[3], pp[3] = {p.x, p.y, p.z};
  fr_scene_geometric_normal(s, h->prim, pp, g);
  vec3 n = v3_norm(v3_load(g));
  return v3_dot(n, d) > 0.0f ? v3_scale(n, -1.0f) : n;
}

/* The normal to shade with: the interpolated shading normal where the mesh
 * has one, turned to face the ray like the geometric normal nf (facing
 * the ray) and given up for nf where it does not (a grazing ray past a
 * smooth silhouette). */
static inline vec3 shading_normal(const fr_scene *s, const fr_hit *h, vec3 d, vec3 nf) {
  float sn[3];
  if (!fr_scene_shading_normal(s, h->prim, h->u, h->v, sn)) return nf;
  vec3 n = v3_load(sn);
  if (v3_dot(n, nf) < 0.0f) n = v3_scale(n, -1.0f);
  return v3_dot(n, d) < 0.0f ? n : nf;
}

static inline vec3 cosine_dir(vec3 n, float u1, float u2) {
  vec3 t, b;
  v3_onb(n, &t, &b);
  float r = sqrtf(u1), phi = 2.0f * (float)M_PI * u2;
  float x = r * cosf(phi), y = r * sinf(phi), z = sqrtf(fmaxf(0.0f, 1.0f - u1));
  return v3_add(v3_add(v3_scale(t, x), v3_scale(b, y)), v3_scale(n, z));
}

static inline fr_ray make_ray(vec3 o, vec3 d, float tnear, float tfar) {
  fr_ray r = {{o.x, o.y, o.z}, tnear, {d.x, d.y, d.z}, tfar};
  return r;
}

static inline vec3 albedo(const fr_scene *s, uint32_t prim) {
  uint32_t m = fr_scene_prim_material(s, prim);
  const fr_material *mat = m == FR_INVALID_ID ? NULL : fr_scene_material(s, m);
  return mat ? v3(mat->diffuse[0], mat->diffuse[1], mat->diffuse[2]) : v3(0.8f, 0.8f, 0.8f);
}
#endif
