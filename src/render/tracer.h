/*
 * The abstract tracer the workloads and renderers trace through, and
 * frusta's tracers (tracers.c); Embree's is in tools/frusta/embree_tracer.c.
 */
#ifndef FR_RENDER_TRACER_H
#define FR_RENDER_TRACER_H
#include <stddef.h>
#include <stdint.h>
#include "frusta.h"
#include "accel/bvh2.h"
#include "trace/lpacket/lpacket.h"
#include "trace/mft/mft.h"

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
  /* both return the triangles the batch fetched (see render/soft_tile.c); cache as fr_mft_fns.occluded's */
  unsigned (*occluded_frusta)(void *ctx, const fr_mft_batch *b, const fr_mft_sets *t, uint16_t occ[FR_MFT_FRUSTA],
                              fr_mft_budget *budget, fr_mft_occluders *cache);
  int packet_side;
  /* the tree occluded_frusta walks, for shafts around runs of batches
   * (fr_mft_shaft); NULL: none */
  const fr_bvh2 *(*shaft_tree)(void *ctx);
} fr_tracer;

/* The frusta tracer: streams as the scene's trace mode says. */
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

#endif
