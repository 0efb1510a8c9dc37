/* What the viewer draws: a scene in one shade mode, trace mode and camera,
 * rendered pass by pass (render/progressive.h), denoised where asked, and
 * turned into screen pixels. Called from one thread at a time. */
#ifndef FR_TOOL_VIEW_RENDERER_H
#define FR_TOOL_VIEW_RENDERER_H
#include <stdint.h>
#include "cli.h"
#include "cli_path.h"
#include "film/denoise.h"
#include "film/temporal.h"
#include "render/progressive.h"
#include "render/whitted.h"
#include "view_camera.h"

typedef enum view_trace { VIEW_TRACE_MFT, VIEW_TRACE_AUTO, VIEW_TRACE_PACKET16, VIEW_TRACE_SINGLE, VIEW_TRACE_COUNT } view_trace;
extern const char *const view_trace_names[VIEW_TRACE_COUNT];

#define VIEW_SRGB_STEPS 4096 /* the screen's sRGB table: linear values in steps of 1/4096 */

typedef struct view_settings {
  view_camera cam;
  int width, height;
  fr_shade_mode mode;
  view_trace trace;
  int denoise;      /* progressive modes only */
  int temporal;     /* path and ao: temporal reprojection while the camera moves */
} view_settings;

typedef struct view_renderer {
  fr_scene *scene;
  fr_workload base;        /* view, eps, threads, seed */
  const cli_path *po;
  const cli_whitted *wo;
  fr_softshadow_opts so;
  cli_path_run path_run;   /* set up on the first path frame */
  int path_ready;
  fr_whitted_mats wmats;   /* built on the first whitted frame */
  int whitted_ready;
  view_settings cur;
  int have_cur;
  fr_progressive prog;
  int prog_ready;
  fr_denoiser *dn;
  fr_temporal *tp;
  fr_mft_tracer mctx;
  float *rgb, *albedo, *normal, *depth; /* the resolved (and denoised) image and its guides */
  uint8_t *bgra;           /* the screen's pixels, 4 bytes each */
  uint8_t srgb[VIEW_SRGB_STEPS + 1]; /* made before any thread reads it */
  int buf_w, buf_h;
  /* the last pass */
  uint64_t rays;
  double seconds, denoise_seconds;
} view_renderer;

/* base: scene, view, eps, threads and seed set (cli_workload_setup). */
void view_renderer_init(view_renderer *r, fr_scene *s, const fr_workload *base, const cli_path *po, const cli_whitted *wo,
                        fr_softshadow_opts so);
void view_renderer_free(view_renderer *r);
/* Makes the next pass render s: a new mode, trace mode or size starts
 * afresh, a new camera restarts the sums (and, with temporal set, the
 * next frame blends in the last one carried to the new view). 0, or the exit code after
 * reporting. */
int view_renderer_apply(view_renderer *r, const view_settings *s);
/* Whether another pass would change the image. */
int view_renderer_done(const view_renderer *r);
/* One pass; 1 when the image changed (rgb and bgra hold it), 0 when it was
 * abandoned (*cancel set) or nothing was left to do. */
int view_renderer_pass(view_renderer *r, const int *cancel);
/* The share of the last frame's pixels blended with the one before (0..1). */
float view_renderer_reused(const view_renderer *r);
/* Samples per pixel of the image (render/progressive.h). */
int view_renderer_spp(const view_renderer *r);
/* Writes the image as `frusta render` would (PNG of a path image through
 * the filmic curve); and for path, the linear image as EXR beside a PNG.
 * 0, or 1 after reporting. */
int view_renderer_screenshot(const view_renderer *r, const char *path);
#endif
