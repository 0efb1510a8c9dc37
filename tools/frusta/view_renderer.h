/* What the viewer draws: a scene in one shade mode, trace mode and camera,
 * rendered pass by pass by the public renderer (fr_renderer), denoised and
 * blended where asked, and turned into screen pixels. Called from one
 * thread at a time, but for view_renderer_cancel. */
#ifndef FR_TOOL_VIEW_RENDERER_H
#define FR_TOOL_VIEW_RENDERER_H
#include <stdint.h>
#include "api/renderer_tuning.h"
#include "cli.h"
#include "cli_path.h"
#include "render/progressive.h"
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
  fr_render_desc base;     /* the flags' description; the settings give camera, size, shade and the rest */
  int path_depth, whitted_depth;
  const cli_path *po;
  fr_renderer *fr;
  view_settings cur;
  int path_told, whitted_told; /* their set-up lines printed */
  float *rgb;              /* the resolved (denoised, blended) image */
  uint8_t *bgra;           /* the screen's pixels, 4 bytes each */
  uint8_t srgb[VIEW_SRGB_STEPS + 1]; /* made before any thread reads it */
  int buf_w, buf_h;
  int shown;               /* rgb and bgra hold a frame */
  /* the last pass */
  uint64_t rays;
  double seconds, denoise_seconds;
} view_renderer;

/* A renderer of s with the flags' options (the lights of view, po, wo,
 * the soft-shadow preview's filter and sets) in the settings first; 0, or
 * the exit code after reporting. */
int view_renderer_init(view_renderer *r, fr_scene *s, const fr_view *view, const cli_path *po, const cli_whitted *wo,
                       int filter, fr_light_sets sets, int threads, const view_settings *first);
void view_renderer_free(view_renderer *r);
/* Makes the next pass render s: a new mode, trace mode or size starts
 * afresh, a new camera restarts the sums (and, with temporal set, the
 * next frame blends in the last one carried to the new view). 0, or the exit code after
 * reporting. */
int view_renderer_apply(view_renderer *r, const view_settings *s);
/* Whether another pass would change the image. */
int view_renderer_done(const view_renderer *r);
/* While cancel is 1 the pass under way stops and passes do nothing; from any thread. */
void view_renderer_cancel(view_renderer *r, int cancel);
/* One pass; 1 when the image changed (rgb and bgra hold it), 0 when it was
 * abandoned (cancelled) or nothing was left to do; -1 after reporting an error. */
int view_renderer_pass(view_renderer *r);
/* The share of the last frame's pixels blended with the one before (0..1). */
float view_renderer_reused(const view_renderer *r);
/* Samples per pixel of the image. */
int view_renderer_spp(const view_renderer *r);
/* Writes the image as `frusta render` would (PNG of a path image through
 * the filmic curve); and for path, the linear image as EXR beside a PNG.
 * 0, or 1 after reporting. */
int view_renderer_screenshot(const view_renderer *r, const char *path);
#endif
