#include "view_renderer.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "film/tonemap.h"
#include "io/file_read.h"
#include "io/image_write.h"

const char *const view_trace_names[VIEW_TRACE_COUNT] = {"mft", "auto", "packet16", "single"};

/* The renderer's description of settings s. */
static fr_render_desc desc_of(const view_renderer *r, const view_settings *s) {
  fr_render_desc d = r->base;
  v3_store(d.camera.eye, s->cam.eye), v3_store(d.camera.at, s->cam.at), v3_store(d.camera.up, s->cam.up);
  d.camera.fov_deg = s->cam.fov, d.camera.width = s->width, d.camera.height = s->height;
  d.shade = (fr_render_shade)s->mode;
  d.max_depth = s->mode == FR_SM_WHITTED ? r->whitted_depth : r->path_depth;
  if (s->mode == FR_SM_AO || s->mode == FR_SM_SOFTSHADOW) /* rays per pixel in passes of 16 */
    d.spp = d.spp < 16 ? 16 : d.spp / 16 * 16;
  d.denoise = s->denoise, d.temporal = s->temporal;
  d.camera_frusta = s->trace == VIEW_TRACE_MFT;
  return d;
}

static int set_trace(const view_renderer *r, view_trace t) {
  static const fr_trace_mode modes[VIEW_TRACE_COUNT] = {FR_TRACE_AUTO, FR_TRACE_AUTO, FR_TRACE_PACKET16, FR_TRACE_SINGLE};
  return fr_scene_set_trace_mode(r->scene, modes[t]) ? cli_error(1, "%s", fr_last_error()) : 0;
}

/* The set-up lines `frusta render` prints, the first time a shade shows. */
static void tell(view_renderer *r) {
  const fr_path_setup *P = fr_renderer_path_setup(r->fr);
  if (P && !r->path_told) cli_path_print(r->po, P), r->path_told = 1;
  const fr_whitted_mats *m = fr_renderer_whitted_mats(r->fr);
  if (m && !r->whitted_told) cli_whitted_print(r->scene, m, r->whitted_depth), r->whitted_told = 1;
}

static int buffers(view_renderer *r, int W, int H) {
  if (W == r->buf_w && H == r->buf_h) return 0;
  free(r->rgb), free(r->bgra);
  const size_t np = (size_t)W * (size_t)H;
  r->shown = 0;
  r->rgb = malloc(np * 3 * sizeof(float));
  r->bgra = malloc(np * 4);
  if (!r->rgb || !r->bgra) {
    free(r->rgb), free(r->bgra);
    r->rgb = NULL, r->bgra = NULL, r->buf_w = r->buf_h = 0;
    return cli_error(1, "out of memory for a %dx%d frame", W, H);
  }
  r->buf_w = W, r->buf_h = H;
  return 0;
}

int view_renderer_init(view_renderer *r, fr_scene *s, const fr_view *view, const cli_path *po, const cli_whitted *wo,
                       int filter, fr_light_sets sets, int threads, const view_settings *first) {
  memset(r, 0, sizeof *r);
  r->scene = s;
  r->po = po;
  for (int i = 0; i <= VIEW_SRGB_STEPS; i++) r->srgb[i] = fr_srgb8((float)i / VIEW_SRGB_STEPS);
  fr_render_desc *d = &r->base;
  fr_render_desc_default(d);
  cli_path_desc(po, d);
  d->spp = po->spp, d->threads = threads;
  d->pass_spp = 1; /* a frame a sample */
  cli_desc_view(view, d); /* the lights; each setting brings its camera */
  if (!d->mirror) d->mirror = wo->mirror;
  if (!d->glass) d->glass = wo->glass;
  r->path_depth = po->max_depth, r->whitted_depth = wo->depth;
  int rc = buffers(r, first->width, first->height);
  if (!rc) rc = set_trace(r, first->trace);
  if (rc) return rc;
  const fr_render_desc fd = desc_of(r, first);
  const fr_error e = fr_renderer_new(s, &fd, &r->fr);
  if (e) return cli_error(e == FR_ERR_ARG ? CLI_USAGE_ERROR : 1, "%s", fr_last_error());
  fr_renderer_tuning t;
  fr_renderer_tuning_default(&t);
  t.soft_filter = filter, t.soft_sets = sets;
  fr_renderer_tune(r->fr, &t);
  r->cur = *first;
  tell(r);
  return 0;
}

void view_renderer_free(view_renderer *r) {
  fr_renderer_release(r->fr);
  free(r->rgb), free(r->bgra);
  memset(r, 0, sizeof *r);
}

int view_renderer_apply(view_renderer *r, const view_settings *s) {
  if (!memcmp(s, &r->cur, sizeof *s)) return 0;
  int rc = buffers(r, s->width, s->height);
  if (!rc && s->trace != r->cur.trace) rc = set_trace(r, s->trace);
  if (rc) return rc;
  const fr_render_desc d = desc_of(r, s);
  if (fr_renderer_update(r->fr, &d)) return cli_error(1, "%s", fr_last_error());
  r->cur = *s;
  tell(r);
  return 0;
}

int view_renderer_done(const view_renderer *r) { return fr_renderer_done(r->fr); }
void view_renderer_cancel(view_renderer *r, int cancel) { fr_renderer_set_cancel(r->fr, cancel); }
int view_renderer_spp(const view_renderer *r) { return fr_renderer_spp(r->fr); }

float view_renderer_reused(const view_renderer *r) {
  fr_render_stats st;
  fr_renderer_stats(r->fr, &st);
  return st.reused;
}

/* A display value of v in [0, 1] as 8-bit sRGB, through r's table (powf
 * per pixel would cost a frame's budget); screenshots encode exactly. */
static uint8_t srgb_fast(const view_renderer *r, float v) {
  if (!(v > 0.0f)) return 0;
  return v >= 1.0f ? 255 : r->srgb[(int)(v * VIEW_SRGB_STEPS + 0.5f)];
}

/* The image as render writes it to PNG: path through the filmic curve. */
static float display_value(const view_renderer *r, float v, float gain) {
  return r->cur.mode == FR_SM_PATH ? fr_filmic(v * gain) : v;
}

int view_renderer_pass(view_renderer *r) {
  r->rays = 0, r->seconds = r->denoise_seconds = 0.0;
  if (view_renderer_done(r)) return 0;
  if (fr_renderer_pass(r->fr, NULL)) return cli_error(1, "%s", fr_last_error()), -1;
  fr_render_stats st;
  fr_renderer_stats(r->fr, &st);
  if (st.cancelled) return 0;
  r->rays = st.rays, r->seconds = st.seconds;
  if (fr_renderer_image(r->fr, 0, r->rgb, NULL, NULL, NULL)) return cli_error(1, "%s", fr_last_error()), -1;
  fr_renderer_stats(r->fr, &st);
  r->denoise_seconds = st.denoise_seconds;
  const size_t np = (size_t)r->cur.width * (size_t)r->cur.height;
  const float gain = exp2f(r->po->exposure);
#pragma omp parallel for num_threads(r->base.threads) schedule(static)
  for (size_t i = 0; i < np; i++) {
    r->bgra[4 * i + 0] = srgb_fast(r, display_value(r, r->rgb[3 * i + 2], gain));
    r->bgra[4 * i + 1] = srgb_fast(r, display_value(r, r->rgb[3 * i + 1], gain));
    r->bgra[4 * i + 2] = srgb_fast(r, display_value(r, r->rgb[3 * i + 0], gain));
    r->bgra[4 * i + 3] = 255;
  }
  r->shown = 1;
  return 1;
}

int view_renderer_screenshot(const view_renderer *r, const char *path) {
  if (!r->shown) return cli_error(1, "%s: no frame rendered yet", path);
  const int W = r->cur.width, H = r->cur.height;
  const size_t np = (size_t)W * (size_t)H;
  const int path_mode = r->cur.mode == FR_SM_PATH, png = fr_has_suffix(path, ".png");
  float *img = malloc(np * 3 * sizeof(float));
  if (!img) return cli_error(1, "out of memory for a screenshot");
  memcpy(img, r->rgb, np * 3 * sizeof(float));
  if (path_mode && png) fr_tonemap_filmic(img, 3 * np, r->po->exposure);
  int rc = 0;
  if (fr_image_write(path, W, H, img)) rc = cli_error(1, "%s", fr_last_error());
  if (!rc && path_mode && png) { /* the accumulated radiance too, linear */
    char exr[4096];
    snprintf(exr, sizeof exr, "%.*s.exr", (int)(strlen(path) - 4), path);
    if (fr_image_write(exr, W, H, r->rgb)) rc = cli_error(1, "%s", fr_last_error());
  }
  free(img);
  return rc;
}
