/*
 * Progressive rendering of one view in any shade mode: passes are summed
 * while the camera rests, and the mean so far is resolved into an image
 * with the guides a denoiser takes (albedo, normal, depth). The command's
 * render and the viewer both draw through it, so that a view rendered to
 * rest in the window and `frusta render` with as many samples give the
 * same bits.
 *
 * What one pass is:
 *   eyelight, normals, shadows, whitted  the whole image (it is then done)
 *   softshadow  16 shadow rays per pixel. With a preview (the default),
 *               the first pass takes the chosen light sets and the
 *               discontinuity filter, Benthin & Wald's real-time frame,
 *               and is shown until FR_SOFT_SPREAD_SHOWN more passes of
 *               spread sets are summed (or all there will be, if
 *               max_passes allows fewer); their unfiltered mean, which
 *               converges to the light's true visibility, is shown after.
 *   ao          16 hemisphere rays per pixel, a new scramble per pass
 *   path        spp_per_pass samples per pixel, up to the setup's spp
 */
#ifndef FR_RENDER_PROGRESSIVE_H
#define FR_RENDER_PROGRESSIVE_H
#include "render/path.h"
#include "render/softshadow.h"
#include "render/workload.h"

typedef enum fr_shade_mode {
  FR_SM_EYELIGHT, FR_SM_NORMALS, FR_SM_SHADOWS, FR_SM_SOFTSHADOW, FR_SM_WHITTED, FR_SM_AO, FR_SM_PATH, FR_SM_COUNT
} fr_shade_mode;

/* The modes' names as the command spells them, in fr_shade_mode order. */
extern const char *const fr_shade_mode_names[FR_SM_COUNT];
const char *fr_shade_mode_name(fr_shade_mode m);
/* The workload a mode's passes run, and how it shades the hits. */
void fr_shade_mode_workload(fr_shade_mode m, fr_workload_kind *kind, fr_shade *shade);
/* Whether a mode's passes differ (they are summed) or it is done in one. */
int fr_shade_mode_progressive(fr_shade_mode m);

#define FR_SOFT_SPREAD_SHOWN 4
#define FR_DEPTH_MISS FR_PATH_DEPTH_MISS /* the depth guide where the camera sees the background */

typedef struct fr_progressive {
  fr_workload w;         /* scene, camera, view, threads, seed; whitted's mats; path's setup (copied to path) */
  fr_shade_mode mode;
  fr_softshadow_opts soft; /* softshadow: the preview's filter and sets (samples is not used) */
  int soft_preview;      /* softshadow: 1 (default) for the preview pass first */
  fr_path_setup path;    /* path: a copy of *w->path, whose spp_begin and spp_end the passes set */
  int spp_per_pass;      /* path: samples per pixel in one pass (1..spp; may change between passes) */
  int path_spp;          /* path: samples per pixel summed */
  int max_passes;        /* ao and softshadow: passes after which it is done (0: never) */
  int passes;            /* passes summed since the last restart */
  size_t np;
  float *sum;            /* RGB sums (ao, path), the image (eyelight, normals, shadows, whitted);
                            softshadow: the spread passes' visibility sum, then the preview's */
  float *pass;           /* one pass's RGB (ao) or visibility (softshadow) */
  float *albedo, *normal, *depth; /* guides: sums (path), or the last pass's (softshadow, ao) */
} fr_progressive;

/* p renders w's view in mode m; w is copied (for path, *w->path too).
 * FR_ERR_NOMEM without memory for the buffers. */
fr_error fr_progressive_init(fr_progressive *p, const fr_workload *w, fr_shade_mode m);
void fr_progressive_free(fr_progressive *p);
/* Forgets the passes, e.g. after the caller changed p->w.cam. */
void fr_progressive_restart(fr_progressive *p);
/* Whether another pass would change the image. */
int fr_progressive_done(const fr_progressive *p);
/* Samples per pixel summed so far (light or hemisphere rays for softshadow
 * and ao, path samples, 1 for the others once rendered). */
int fr_progressive_spp(const fr_progressive *p);
/* One more pass through t, abandoned (nothing summed, *r->cancelled set)
 * when *cancel becomes nonzero; cancel may be NULL. */
void fr_progressive_pass(fr_progressive *p, const fr_tracer *t, const int *cancel, fr_workload_result *r);
/* The mean image so far as linear RGB (W*H*3), with means of the guides
 * where albedo, normal (3 floats per pixel) and depth (1) are not NULL:
 * the primary hit's albedo, unit-ish normal facing the camera and
 * distance (FR_DEPTH_MISS where none). Before any pass: black. */
void fr_progressive_resolve(const fr_progressive *p, float *rgb, float *albedo, float *normal, float *depth);
/* softshadow: the visibility the image shows (W*H). */
void fr_progressive_visibility(const fr_progressive *p, float *vis);
/* softshadow: the image (W*H*3) of that visibility, shaded by the light's
 * centre; what fr_progressive_resolve gives, for a caller that wants the
 * visibility too without filtering twice. */
void fr_progressive_shade_soft(const fr_progressive *p, const float *vis, float *image);
#endif
