/*
 * The path tracer: unidirectional paths with next-event estimation and
 * multiple importance sampling (the power heuristic) between light
 * sampling and BSDF sampling, for the environment, a quad area light and a
 * point light; Russian roulette once a path's weight falls below
 * FR_PATH_RR_WEIGHT (the MIC paper's 15%); thin-lens depth of field.
 *
 * Rays travel in waves through the tracer (render/tracer.h), so any trace
 * mode, and Embree, trace the same rays: a tile's paths for up to two
 * samples per pixel at once, then at every bounce one call for their next
 * segments and one for their shadow rays.
 */
#ifndef FR_RENDER_PATH_H
#define FR_RENDER_PATH_H
#include <stddef.h>
#include <stdint.h>
#include "frusta.h"
#include "light/environment.h"
#include "material/bsdf.h"
#include "render/sampler.h"

#define FR_PATH_CHUNK 8          /* samples per pixel in one pass of frusta render and fr_renderer */
/* Paths traced together, at most: a tile's for as many samples per pixel
 * as fill the wave. Passes of one or two samples (a viewer frame) take
 * tiles 32 pixels square, so that their waves still hold 1,024 or 2,048
 * paths (16x16 tiles sent 256: 7% slower at 1 spp; 64x64 tiles, waves of
 * 4,096, are 2% faster but keep the viewer from answering input for up to
 * 15 ms rather than 5); longer passes take TILE, as the other workloads,
 * short enough for a cluster's last tile of a long frame (docs/scaling.md),
 * and at 16 spp a tile is one wave (2% faster than two of 2,048). */
#define FR_PATH_WAVE 4096
#define FR_PATH_RR_WEIGHT 0.15f
#define FR_PATH_MAX_DEPTH 64
#define FR_PATH_DEPTH_MISS 1e30f /* the depth AOV of a sample that sees the environment */

typedef struct fr_path_lights {
  const fr_env *env;            /* never NULL; a black one is not sampled */
  int area;                     /* the quad c + s e1 + t e2 (s, t in [0, 1]), emitting area_radiance from the side
                                   e1 x e2 faces (the scenes' lamps face down); its back is dark */
  vec3 area_c, area_e1, area_e2, area_radiance;
  int point;                    /* a point light at point_pos of intensity point_intensity (W/sr) */
  vec3 point_pos, point_intensity;
} fr_path_lights;

typedef struct fr_path_setup {
  const fr_bsdf *mats;          /* one per scene material, and one more (the last) for surfaces without */
  size_t count;                 /* including that last one */
  const struct fr_surface *surf; /* per triangle: normal and material (render/surfaces.h) */
  size_t nsurf;
  const struct fr_texture *textures; /* the materials' color_tex index these */
  fr_path_lights lights;
  int max_depth;                /* segments per path, 1..FR_PATH_MAX_DEPTH (13 by default) */
  fr_sampler_kind sampler;
  uint32_t seed;                /* the sampler's */
  int spp;                      /* samples per pixel of the whole image (the sampler's pattern size) */
  int spp_begin, spp_end;       /* this frame's share of them */
  float aperture, focus;        /* lens radius (0: pinhole) and focus distance */
} fr_path_setup;

/* The materials of a scene for path tracing: MTL rules (material/material_mtl.h),
 * with the named materials made mirrors (chrome) and glass (NULL: the
 * scene's suggestions, views.h), and their diffuse textures (map_Kd)
 * loaded, each file once. *mats and *textures are malloc'd (free the
 * textures with fr_path_textures_free); a texture that does not load is
 * an error naming it. */
fr_error fr_path_mats_build(const fr_scene *s, const char *mirror, const char *glass, fr_bsdf **mats, size_t *count,
                            struct fr_texture **textures, size_t *ntextures);
void fr_path_textures_free(struct fr_texture *t, size_t n);

struct fr_workload;
struct fr_tracer;
typedef struct fr_path_scratch fr_path_scratch;
fr_path_scratch *fr_path_scratch_new(void);
void fr_path_scratch_free(fr_path_scratch *s);
/* Adds what s's tiles spent tracing (camera, shadow, bounce rays) and shading to stage[]. */
void fr_path_scratch_stages(const fr_path_scratch *s, double *stage);
/* One tile (fr_path_tile_side pixels square): adds the samples' radiance
 * to w->image (sums, not means) and, where set, first-hit albedo, normal
 * and distance to w->gbuf_albedo, gbuf_normal and gbuf_depth; returns the
 * rays traced.
 * Each pixel's samples are added one by one in sample order, so a run of
 * samples split into calls any way sums to the same bits. */
uint64_t fr_path_tile(const struct fr_workload *w, const struct fr_tracer *t, fr_path_scratch *s, int tx, int ty);
/* The side of the tiles a pass of P takes (see FR_PATH_WAVE). */
int fr_path_tile_side(const fr_path_setup *P);
#endif
