/*
 * The benchmark workloads of ../shared/spec/workloads.md, written once against
 * an abstract tracer so that frusta and Embree trace the same rays, made by the
 * same code, in the same run. The renderer uses the same engine with shading.
 */
#ifndef FR_RENDER_WORKLOAD_H
#define FR_RENDER_WORKLOAD_H
#include <stdint.h>
#include "frusta.h"
#include "render/camera.h"
#include "render/views.h"
#include "render/mft_rays.h"
#include "trace/mft.h"
#include "trace/lpacket.h"

typedef enum fr_workload_kind {
  FR_WL_PRIMARY, FR_WL_SHADOW, FR_WL_SOFT16, FR_WL_AO16, FR_WL_DIFFUSE8, FR_WL_SPECULAR8, FR_WL_WHITTED, FR_WL_COUNT
} fr_workload_kind;

const char *fr_workload_name(fr_workload_kind k);
int fr_workload_parse(const char *name, fr_workload_kind *k);

/* A tracer: rays come in tiles of up to 16x16 pixels, ordered in 4x4 blocks,
 * so consecutive groups of 16 are coherent when the workload is.
 * Implementations may overwrite the ray arrays.
 *
 * A multi-frusta tracer also takes whole frusta: camera rays of full 16x16
 * tiles, and the soft shadow rays of 16 pixels at a time (trace/mft.h). Where
 * these are NULL the engine makes the same rays (fr_mft_ray) and hands them to
 * intersect / occluded, so every tracer traces the same rays.
 *
 * The last argument of intersect / occluded is a hint: 1 for rays the
 * workload knows to be coherent, FR_RAYS_DIVERGENT for rays known to part
 * ways at the scale of the triangles (soft-shadow tiles whose frusta fetched
 * many triangles), 0 otherwise.
 *
 * The Whitted workload hands each packet to intersect / occluded in its own
 * call: the rays of one block of packet_side x packet_side pixels (or their
 * reflection, refraction or shadow rays); packet_side 0 means blocks of
 * 32x32, the whole tile. */
#define FR_RAYS_DIVERGENT (-1)
typedef struct fr_tracer {
  void *ctx;
  void (*intersect)(void *ctx, const fr_ray *rays, fr_hit *hits, size_t n, int coherent);
  void (*occluded)(void *ctx, const fr_ray *rays, uint8_t *occ, size_t n, int coherent);
  unsigned (*intersect_frusta)(void *ctx, const fr_mft_batch *b, const fr_mft_sets *t, fr_mft_hits *hits);
  /* both return the triangles the batch fetched (see soft_shadows in
   * workload.c); cache as fr_mft_fns.occluded's */
  unsigned (*occluded_frusta)(void *ctx, const fr_mft_batch *b, const fr_mft_sets *t, uint16_t occ[FR_MFT_FRUSTA],
                              fr_mft_budget *budget, fr_mft_occluders *cache);
  int packet_side;
  /* the tree occluded_frusta walks, for shafts around runs of batches
   * (fr_mft_shaft); NULL: none */
  const fr_bvh2 *(*shaft_tree)(void *ctx);
} fr_tracer;

typedef enum fr_shade { FR_SHADE_NONE, FR_SHADE_EYELIGHT, FR_SHADE_NORMALS, FR_SHADE_LIGHT } fr_shade;

typedef struct fr_workload {
  fr_workload_kind kind;
  const fr_scene *scene;   /* for normals and materials (the same for every tracer) */
  fr_camera cam;
  fr_view view;
  float eps;               /* 1e-4 x scene diagonal */
  int threads;
  uint64_t seed;
  fr_shade shade;          /* with an image: what to write */
  float *image;            /* width*height*3, or NULL */
  int progress;            /* print progress to stderr */
  fr_light_sets light_sets_kind; /* soft16: how the 256 samples of a 4x4 block are dealt to its pixels */
  /* optional per-pixel outputs (soft16): light visibility, primary hit
   * distance (+inf on a miss) and unit normal facing the camera */
  float *gbuf_vis, *gbuf_depth, *gbuf_normal, *gbuf_albedo;
  /* whitted: which surfaces mirror and refract, recursion depth (0: 4) */
  const struct fr_whitted_mats *mats;
  int max_depth;
  /* soft shadows with a frusta tracer: 0 (default) traces a tile's shadows as
   * rays where its first batch's frusta fetched too many triangles each
   * (SOFT_FRUSTA_MAX_TRIS in workload.c); 1 keeps every batch as frusta (the
   * paper's pure multi-frusta, to measure) */
  int mft_no_fallback;
  /* 1: no tile shafts (SOFT_SHAFT_DECIDES_* in workload.c): every batch
   * walks the tree from the root and no shaft decides a fall-back, to
   * measure */
  int mft_no_shaft;
  /* set by fr_workload_run for its tiles */
  const fr_mft_sets *light_sets;  /* this frame's interleaved samples on the quad light */
  const fr_mft_sets *camera_set;  /* the 4x4 pixels of a block */
} fr_workload;

/* Where a Whitted frame's time goes, in seconds summed over the threads:
 * the camera rays (made and traced: frusta make their own), the shadow
 * rays, the reflection and refraction rays, and the rest of the tiles'
 * time, the renderer's own (hits' normals and materials, shading, new
 * rays), which is the same code whatever the tracer. */
typedef enum fr_wl_stage { FR_STAGE_CAMERA, FR_STAGE_SHADOW, FR_STAGE_SECONDARY, FR_STAGE_SHADE, FR_STAGES } fr_wl_stage;

typedef struct fr_workload_result {
  uint64_t rays;
  double seconds;
  double stage[FR_STAGES]; /* the Whitted workload only (else 0) */
} fr_workload_result;

fr_workload_result fr_workload_run(const fr_workload *w, const fr_tracer *t);

/* Camera rays of the full 16x16 tile at (tx, ty) by multi-frusta tracing
 * (t->intersect_frusta): ray and hit 16 f + k are pixel (tx + 4 (f % 4) +
 * k % 4, ty + 4 (f / 4) + k / 4). The rays are fr_mft_ray's with unit
 * directions, as fr_camera_ray makes them, and the hits are in their units. */
void fr_camera_frusta(const fr_workload *w, const fr_tracer *t, int tx, int ty, fr_ray *rays, fr_hit *hits);

/* The frusta tracer: streams as the scene's trace options say. */
fr_tracer fr_tracer_frusta(const fr_scene *s);

/* The multi-frusta tracer: camera rays and soft shadows by multi-frusta
 * tracing through bvh (the scene's binary BVH, or a shallower one), every
 * other ray as fr_tracer_frusta. The context must outlive the tracer. */
typedef struct fr_mft_tracer {
  const fr_scene *scene;
  const fr_bvh2 *bvh;        /* camera frusta's tree */
  fr_mft_opts opts;
  const fr_bvh2 *shadow_bvh; /* shadow frusta's (NULL: bvh) */
} fr_mft_tracer;
/* The scene's own trees: camera frusta through the shallow one (leaves of
 * FR_MFT_LEAF), shadow frusta through the regular one (leaves of 4), where
 * each measured fastest: see FR_MFT_LEAF. */
fr_mft_tracer fr_mft_tracer_of(const fr_scene *s, fr_mft_opts opts);
fr_tracer fr_tracer_mft(const fr_mft_tracer *ctx);

/* The large-packet tracer: every call's rays in packets of side x side
 * (consecutive rays), traced through the scene's trees (geom) as opts say. */
typedef struct fr_lp_tracer {
  const fr_scene *scene;
  fr_lp_scene geom;
  fr_lp_opts opts;
  int side;
} fr_lp_tracer;
fr_tracer fr_tracer_lp(const fr_lp_tracer *ctx);

/* The Whitted workload's tiles (render/whitted.c): 32x32 pixels. */
#define FR_WHITTED_TILE 32
typedef struct fr_whitted_scratch fr_whitted_scratch;
fr_whitted_scratch *fr_whitted_scratch_new(void);
void fr_whitted_scratch_free(fr_whitted_scratch *s);
/* Adds the time s's tiles spent in each stage to stage[]. */
void fr_whitted_scratch_stages(const fr_whitted_scratch *s, double stage[FR_STAGES]);
uint64_t fr_whitted_tile(const fr_workload *w, const fr_tracer *t, fr_whitted_scratch *s, int tx, int ty);
#endif
