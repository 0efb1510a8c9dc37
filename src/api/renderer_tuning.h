/* What the command sets on an fr_renderer beyond the public description:
 * the tracer it measures with (Embree, large packets), the tiles of a
 * cluster's rank, printed progress and the soft-shadow preview's filter
 * and light sets. Kept out of frusta.h: measurement switches, not API. */
#ifndef FR_API_RENDERER_TUNING_H
#define FR_API_RENDERER_TUNING_H
#include "frusta.h"
#include "render/path.h"
#include "render/softshadow.h"
#include "render/tracer.h"
#include "render/whitted.h"
#include "render/workload.h"

typedef struct fr_renderer_tuning {
  int has_tracer;            /* 1: every pass through tracer (whose context outlives the renderer) */
  fr_tracer tracer;
  const fr_tile_feed *feed;     /* the tiles this process renders (NULL: all) */
  int whole_path_passes;     /* path: a pass takes all spp at once (a cluster's tiles are then whole sums) */
  int progress;              /* one-pass shades print their tiles' progress to stderr */
  int soft_preview;          /* softshadow: the filtered 16-sample preview first [1]; 0: spread passes only */
  int soft_filter;           /* softshadow's preview: the discontinuity filter [1] */
  fr_light_sets soft_sets;   /* softshadow's preview: its light sets [FR_LIGHT_SETS_CELLS] */
} fr_renderer_tuning;

void fr_renderer_tuning_default(fr_renderer_tuning *t);
/* Takes effect from the next pass; the passes start again. */
void fr_renderer_tune(fr_renderer *r, const fr_renderer_tuning *t);
/* The path tracer's set-up (its lights as made), or NULL if the shade is not path. */
const fr_path_setup *fr_renderer_path_setup(const fr_renderer *r);
/* The Whitted materials, or NULL if the shade is not whitted. */
const fr_whitted_mats *fr_renderer_whitted_mats(const fr_renderer *r);
/* The passes the image takes from the start (for a progress line). */
int fr_renderer_passes(const fr_renderer *r);
/* softshadow: the visibility the image shows (W*H). */
void fr_renderer_visibility(const fr_renderer *r, float *vis);
/* Whether passes trace through the multi-frusta tracer: camera rays and
 * shadows, or a path tracer's shadow rays from its camera hits to the
 * point light. */
int fr_renderer_uses_frusta(const fr_renderer *r);
#endif
