#include "view_renderer.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "base/timer.h"
#include "film/tonemap.h"
#include "io/file_read.h"
#include "io/image_write.h"

const char *const view_trace_names[VIEW_TRACE_COUNT] = {"mft", "auto", "packet16", "single"};

void view_renderer_init(view_renderer *r, fr_scene *s, const fr_workload *base, const cli_path *po, const cli_whitted *wo,
                        fr_softshadow_opts so) {
  memset(r, 0, sizeof *r);
  r->scene = s;
  r->base = *base;
  r->base.progress = 0;
  r->po = po;
  r->wo = wo;
  r->so = so;
  r->mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  for (int i = 0; i <= VIEW_SRGB_STEPS; i++) r->srgb[i] = fr_srgb8((float)i / VIEW_SRGB_STEPS);
}

static void free_buffers(view_renderer *r) {
  free(r->rgb);
  free(r->bgra);
  r->rgb = r->albedo = r->normal = r->depth = NULL;
  r->bgra = NULL;
  fr_denoiser_free(r->dn);
  r->dn = NULL;
  fr_temporal_free(r->tp);
  r->tp = NULL;
}

void view_renderer_free(view_renderer *r) {
  if (r->prog_ready) fr_progressive_free(&r->prog);
  free_buffers(r);
  if (r->path_ready) cli_path_free(&r->path_run);
  if (r->whitted_ready) fr_whitted_mats_free(&r->wmats);
  memset(r, 0, sizeof *r);
}

static int camera_of(const view_settings *s, fr_camera *c) {
  if (fr_camera_setup(c, s->cam.eye, s->cam.at, s->cam.up, s->cam.fov, s->width, s->height))
    return cli_error(CLI_USAGE_ERROR, "%s", fr_last_error());
  return 0;
}

int view_renderer_apply(view_renderer *r, const view_settings *s) {
  const int fresh = !r->have_cur || s->mode != r->cur.mode || s->width != r->cur.width || s->height != r->cur.height ||
                    s->trace != r->cur.trace;
  if (!fresh && view_camera_equal(&s->cam, &r->cur.cam) && s->denoise == r->cur.denoise && s->temporal == r->cur.temporal)
    return 0;
  fr_camera cam;
  int rc = camera_of(s, &cam);
  if (rc) return rc;
  if (!fresh && view_camera_equal(&s->cam, &r->cur.cam)) { /* the denoiser or the blending: the sums stay */
    if (s->temporal != r->cur.temporal || s->denoise != r->cur.denoise) fr_temporal_reset(r->tp);
    r->cur = *s;
    return 0;
  }
  if (!fresh) {
    r->prog.w.cam = cam;
    fr_progressive_restart(&r->prog);
    r->cur = *s;
    return 0;
  }
  if (s->width != r->buf_w || s->height != r->buf_h) {
    free_buffers(r);
    const size_t np = (size_t)s->width * (size_t)s->height;
    r->rgb = malloc(np * 10 * sizeof(float));
    r->bgra = malloc(np * 4);
    if (!r->rgb || !r->bgra || fr_denoiser_new(s->width, s->height, &r->dn) ||
        fr_temporal_new(s->width, s->height, &r->tp)) {
      free_buffers(r);
      r->buf_w = r->buf_h = 0;
      return cli_error(1, "out of memory for a %dx%d frame", s->width, s->height);
    }
    r->albedo = r->rgb + 3 * np, r->normal = r->rgb + 6 * np, r->depth = r->rgb + 9 * np;
    r->buf_w = s->width, r->buf_h = s->height;
  }
  fr_workload w = r->base;
  w.cam = cam;
  if (s->mode == FR_SM_PATH && !r->path_ready) {
    if ((rc = cli_path_setup(r->po, &w, &r->path_run))) return rc;
    r->path_ready = 1;
  }
  if (s->mode == FR_SM_WHITTED && !r->whitted_ready) {
    if ((rc = cli_whitted_setup(r->scene, r->wo, &r->wmats, &w))) return rc;
    r->whitted_ready = 1;
  }
  w.path = r->path_ready ? &r->path_run.setup : NULL;
  w.mats = r->whitted_ready ? &r->wmats : NULL;
  w.max_depth = r->wo->depth;
  if (r->prog_ready) fr_progressive_free(&r->prog);
  r->prog_ready = 0;
  fr_temporal_reset(r->tp); /* another image: nothing to carry over */
  if (fr_progressive_init(&r->prog, &w, s->mode)) return cli_error(1, "%s", fr_last_error());
  r->prog_ready = 1;
  r->prog.soft = r->so;
  /* ao and softshadow stop at --spp rays per pixel; softshadow's preview pass comes first */
  r->prog.max_passes = r->po->spp / 16 + (s->mode == FR_SM_SOFTSHADOW);
  static const fr_trace_mode modes[VIEW_TRACE_COUNT] = {FR_TRACE_AUTO, FR_TRACE_AUTO, FR_TRACE_PACKET16, FR_TRACE_SINGLE};
  if (fr_scene_set_trace_mode(r->scene, modes[s->trace])) return cli_error(1, "%s", fr_last_error());
  r->cur = *s;
  r->have_cur = 1;
  return 0;
}

/* Temporal blending is for the noisy modes, path and ao: softshadow's
 * first pass is filtered already, and its frame rate has no room for the
 * blend's cost (about 20 ms at 1024x768 on 2 threads). */
static int temporal_applies(const view_renderer *r) {
  return r->tp && r->cur.temporal && (r->cur.mode == FR_SM_PATH || r->cur.mode == FR_SM_AO);
}

int view_renderer_done(const view_renderer *r) { return !r->prog_ready || fr_progressive_done(&r->prog); }
float view_renderer_reused(const view_renderer *r) { return temporal_applies(r) ? fr_temporal_reused(r->tp) : 0.0f; }
int view_renderer_spp(const view_renderer *r) { return r->prog_ready ? fr_progressive_spp(&r->prog) : 0; }

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

int view_renderer_pass(view_renderer *r, const int *cancel) {
  r->rays = 0, r->seconds = r->denoise_seconds = 0.0;
  if (view_renderer_done(r)) return 0;
  fr_mft_tracer *mctx = &r->mctx;
  const int mft = r->cur.trace == VIEW_TRACE_MFT && !fr_scene_sphere_count(r->scene);
  const fr_tracer t = mft ? fr_tracer_mft(mctx) : fr_tracer_frusta(r->scene);
  fr_workload_result res;
  fr_progressive_pass(&r->prog, &t, cancel, &res);
  if (res.cancelled) return 0;
  r->rays = res.rays;
  r->seconds = res.seconds;
  /* the guides are for the denoiser and the temporal blend only */
  const int guides = fr_shade_mode_progressive(r->cur.mode) && (r->cur.denoise || temporal_applies(r));
  fr_progressive_resolve(&r->prog, r->rgb, guides ? r->albedo : NULL, guides ? r->normal : NULL, guides ? r->depth : NULL);
  r->denoise_seconds = 0.0;
  int spp = fr_progressive_spp(&r->prog);
  if (temporal_applies(r)) {
    fr_temporal_apply(r->tp, &r->prog.w.cam, r->prog.passes, r->depth, r->normal, r->rgb, r->base.threads);
    spp = (int)(spp * (1.0f + fr_temporal_worth(r->tp)));
  }
  if (r->cur.denoise && fr_shade_mode_progressive(r->cur.mode)) {
    const double t0 = fr_seconds();
    fr_denoise(r->dn, r->rgb, r->albedo, r->normal, r->depth, spp, r->base.threads, r->rgb);
    r->denoise_seconds = fr_seconds() - t0;
  }
  const size_t np = (size_t)r->cur.width * (size_t)r->cur.height;
  const float gain = exp2f(r->po->exposure);
#pragma omp parallel for num_threads(r->base.threads) schedule(static)
  for (size_t i = 0; i < np; i++) {
    r->bgra[4 * i + 0] = srgb_fast(r, display_value(r, r->rgb[3 * i + 2], gain));
    r->bgra[4 * i + 1] = srgb_fast(r, display_value(r, r->rgb[3 * i + 1], gain));
    r->bgra[4 * i + 2] = srgb_fast(r, display_value(r, r->rgb[3 * i + 0], gain));
    r->bgra[4 * i + 3] = 255;
  }
  return 1;
}

int view_renderer_screenshot(const view_renderer *r, const char *path) {
  if (!r->rgb) return cli_error(1, "%s: no frame rendered yet", path);
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
