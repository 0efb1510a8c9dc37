/*
 * The benchmark workloads of docs/workloads.md, written once against an
 * abstract tracer (render/tracer.h) so that frusta and Embree trace the same
 * rays, made by the same code, in the same run. The renderer uses the same
 * engine with shading.
 */
#ifndef FR_RENDER_WORKLOAD_H
#define FR_RENDER_WORKLOAD_H
#include <stdint.h>
#include "frusta.h"
#include "render/camera.h"
#include "render/views.h"
#include "render/mft_rays.h"
#include "render/tracer.h"

typedef enum fr_workload_kind {
  FR_WL_PRIMARY, FR_WL_SHADOW, FR_WL_SOFT16, FR_WL_AO16, FR_WL_DIFFUSE8, FR_WL_SPECULAR8, FR_WL_WHITTED, FR_WL_PATH, FR_WL_COUNT
} fr_workload_kind;

const char *fr_workload_name(fr_workload_kind k);
int fr_workload_parse(const char *name, fr_workload_kind *k);

typedef enum fr_shade { FR_SHADE_NONE, FR_SHADE_EYELIGHT, FR_SHADE_NORMALS, FR_SHADE_LIGHT } fr_shade;

struct fr_workload;

/* A frame's tiles: tile k of the order (k in 0..count-1) is the tile at
 * x = (order[k] % tiles_x) * size, y = (order[k] / tiles_x) * size,
 * clipped to the image. */
typedef struct fr_tile_grid {
  int size, tiles_x, tiles_y, count;
  const uint32_t *order;
} fr_tile_grid;

/* Where a frame's tiles come from when they are not all this process's:
 * another process's share of the frame (src/cluster). fr_workload_run
 * calls begin once, then next whenever its threads want tiles, done when
 * every tile of a range next gave is rendered (its pixels are in the
 * workload's buffers), and end once the threads are finished. next, done
 * and end are called by one thread at a time, not always the same one.
 * next returns 0 when the frame has no more tiles for this process; end
 * returns the rays of the whole frame, given this process's, and 0 for
 * success (1: the frame failed; fr_last_error says why). */
typedef struct fr_tile_feed {
  void *ctx;
  int (*begin)(void *ctx, const struct fr_workload *w, const fr_tile_grid *g);
  int (*next)(void *ctx, int *first, int *count);
  void (*done)(void *ctx, int first, int count);
  int (*end)(void *ctx, uint64_t rays, uint64_t *all_rays);
} fr_tile_feed;

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
  /* shadows with a frusta tracer: 0 (default) traces a tile's shadows as
   * rays where frusta fetched too many triangles each (soft shadows: its
   * first shadow batch's, SOFT_FRUSTA_MAX_TRIS in soft_tile.c; point-light
   * shadows: its camera batch's, POINT_FRUSTA_MAX_TRIS in tile.c) and a
   * point-light batch over its node budget as rays; 1 keeps every batch as
   * frusta (the paper's pure multi-frusta, to measure) */
  int mft_no_fallback;
  /* 1: no tile shafts (SOFT_SHAFT_DECIDES_* in workload.c): every batch
   * walks the tree from the root and no shaft decides a fall-back, to
   * measure */
  int mft_no_shaft;
  /* when set, tiles not yet begun are skipped once *cancel is nonzero (read
   * atomically; another thread sets it): the frame is abandoned */
  const int *cancel;
  /* when set, the tiles this process renders (else all of them) */
  const fr_tile_feed *feed;
  /* when set, tile_seconds[k] gets the seconds the k-th tile of the order
   * took to render (0 for those another process rendered); room for
   * ceil(width / 16) x ceil(height / 16) tiles */
  double *tile_seconds;
  /* path: materials, lights, samples (render/path.h) */
  const struct fr_path_setup *path;
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
  int cancelled;           /* *w->cancel was seen set: some tiles were not rendered */
  int failed;              /* the feed failed: the frame is incomplete (fr_last_error says why) */
} fr_workload_result;

fr_workload_result fr_workload_run(const fr_workload *w, const fr_tracer *t);
/* The side of the square tiles fr_workload_run cuts w's frame into: 16,
 * 32 for Whitted and for path passes of few samples (render/path.h). */
int fr_workload_tile_side(const fr_workload *w);

/* Camera rays of the full 16x16 tile at (tx, ty) by multi-frusta tracing
 * (t->intersect_frusta): ray and hit 16 f + k are pixel (tx + 4 (f % 4) +
 * k % 4, ty + 4 (f / 4) + k / 4). The rays are fr_mft_ray's with unit
 * directions, as fr_camera_ray makes them, and the hits are in their units.
 * Returns the triangles the frusta fetched. */
unsigned fr_camera_frusta(const fr_workload *w, const fr_tracer *t, int tx, int ty, fr_ray *rays, fr_hit *hits);

#endif
