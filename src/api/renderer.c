/* fr_renderer: the progressive renderer (render/progressive.h) behind the
 * public handle, with what each shade needs set up once: the Whitted
 * materials, the path tracer's scene (render/path_scene.h), the denoiser.
 * Camera rays and soft shadows go as multi-frusta where the scene has no
 * spheres, paths as the scene's streams, as the command renders them. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"
#include "film/denoise.h"
#include "film/tonemap.h"
#include "render/path_scene.h"
#include "render/progressive.h"
#include "render/tracer.h"
#include "render/whitted.h"
#include "scene.h"

_Static_assert((int)FR_RENDER_PATH == (int)FR_SM_PATH && (int)FR_RENDER_EYELIGHT == (int)FR_SM_EYELIGHT &&
                   (int)FR_RENDER_SOFTSHADOW == (int)FR_SM_SOFTSHADOW && (int)FR_RENDER_AO == (int)FR_SM_AO,
               "fr_render_shade follows fr_shade_mode");

struct fr_renderer {
  const fr_scene *s;
  fr_render_desc d;
  fr_workload w;
  fr_progressive p;
  int p_ready;
  fr_path_scene path;
  fr_whitted_mats mats;
  fr_mft_tracer mctx;
  fr_tracer t;
  fr_denoiser *dn;
  float *guides;   /* albedo, normal, depth for the denoiser when the caller wants none */
};

static fr_error view_of(const fr_scene *s, const fr_render_desc *d, fr_view *v, fr_camera *cam) {
  *v = fr_view_of(s->name, s->bounds);
  const fr_pinhole *c = &d->camera;
  if (c->fov_deg != 0.0f) {
    v->eye = v3_load(c->eye), v->at = v3_load(c->at), v->up = v3_load(c->up), v->fov = c->fov_deg;
    if (!v3_finite(v->eye) || !v3_finite(v->at) || !v3_finite(v->up))
      return fr_fail(FR_ERR_ARG, "fr_renderer: the camera is not finite");
  }
  if (d->has_light) {
    v->light = v3_load(d->light);
    if (!v3_finite(v->light)) return fr_fail(FR_ERR_ARG, "fr_renderer: the light is not finite");
  }
  return fr_camera_setup(cam, v->eye, v->at, v->up, v->fov, c->width, c->height);
}

void fr_renderer_release(fr_renderer *r) {
  if (!r) return;
  if (r->p_ready) fr_progressive_free(&r->p);
  fr_path_scene_free(&r->path);
  fr_whitted_mats_free(&r->mats);
  fr_denoiser_free(r->dn);
  free(r->guides);
  free(r);
}

fr_error fr_renderer_new(const fr_scene *s, const fr_render_desc *d, fr_renderer **out) {
  if (!s || !d || !out) return fr_fail(FR_ERR_ARG, "fr_renderer_new: NULL scene, description or out");
  *out = NULL;
  if (!s->committed) return fr_fail(FR_ERR_STATE, "fr_renderer_new: the scene is not committed");
  if ((int)d->shade < 0 || (int)d->shade > (int)FR_RENDER_PATH)
    return fr_fail(FR_ERR_ARG, "fr_renderer_new: unknown shade %d", (int)d->shade);
  const int spp = d->spp ? d->spp : 16;
  if (spp < 1 || spp > 65536) return fr_fail(FR_ERR_ARG, "fr_renderer_new: spp %d is not in 1..65536", spp);
  if ((d->shade == FR_RENDER_AO || d->shade == FR_RENDER_SOFTSHADOW) && spp % 16)
    return fr_fail(FR_ERR_ARG, "fr_renderer_new: %s takes spp in multiples of 16, not %d",
                   fr_shade_mode_name((fr_shade_mode)d->shade), spp);
  if (d->threads < 0) return fr_fail(FR_ERR_ARG, "fr_renderer_new: %d threads", d->threads);
  fr_renderer *r = calloc(1, sizeof *r);
  if (!r) return fr_fail(FR_ERR_NOMEM, "out of memory");
  r->s = s;
  r->d = *d;
  r->d.spp = spp;
  r->d.environment = NULL; /* the caller's string is not kept */
  fr_workload *w = &r->w;
  w->scene = s;
  fr_error e = view_of(s, d, &w->view, &w->cam);
  const fr_shade_mode mode = (fr_shade_mode)d->shade;
  fr_shade_mode_workload(mode, &w->kind, &w->shade);
  w->eps = 1e-4f * v3_len(v3_sub(s->bounds.hi, s->bounds.lo));
  w->threads = d->threads ? d->threads : omp_get_num_procs();
  w->seed = 1;
  if (!e && mode == FR_SM_WHITTED) {
    e = fr_whitted_mats_build(s, NULL, NULL, &r->mats);
    w->mats = &r->mats;
  }
  if (!e && mode == FR_SM_PATH) {
    fr_path_options po;
    fr_path_options_default(&po);
    po.spp = spp;
    po.env_file = d->environment;
    e = fr_path_scene_init(&r->path, s, &w->view, &po, NULL, NULL);
    w->path = &r->path.setup;
  }
  if (!e) {
    e = fr_progressive_init(&r->p, w, mode);
    r->p_ready = !e;
  }
  if (!e && d->denoise && fr_shade_mode_progressive(mode)) e = fr_denoiser_new(w->cam.width, w->cam.height, &r->dn);
  if (e) {
    fr_renderer_release(r);
    return e;
  }
  if (mode == FR_SM_PATH) r->p.spp_per_pass = FR_PATH_CHUNK < spp ? FR_PATH_CHUNK : spp;
  /* ao and softshadow stop at spp rays per pixel; softshadow's 16 are the
   * filtered real-time frame, more are spread sets summed unfiltered (as
   * frusta render --light-samples draws them) */
  if (mode == FR_SM_AO) r->p.max_passes = spp / 16;
  if (mode == FR_SM_SOFTSHADOW) {
    const fr_softshadow_opts asked = {spp, 1, FR_LIGHT_SETS_CELLS};
    r->p.soft = fr_softshadow_used(&asked);
    r->p.soft_preview = spp == 16;
    r->p.max_passes = spp / 16;
  }
  r->mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  const int mft = mode != FR_SM_PATH && !fr_scene_sphere_count(s);
  r->t = mft ? fr_tracer_mft(&r->mctx) : fr_tracer_frusta(s);
  *out = r;
  return FR_OK;
}

fr_error fr_renderer_pass(fr_renderer *r, int *done) {
  if (!r) return fr_fail(FR_ERR_ARG, "fr_renderer_pass: NULL renderer");
  if (!fr_progressive_done(&r->p)) {
    fr_workload_result res;
    fr_progressive_pass(&r->p, &r->t, NULL, &res);
    if (res.failed) return fr_fail(FR_ERR_NOMEM, "fr_renderer_pass: %s", fr_last_error());
  }
  if (done) *done = fr_progressive_done(&r->p);
  return FR_OK;
}

fr_error fr_renderer_render(fr_renderer *r) {
  int done = 0;
  fr_error e = FR_OK;
  while (!e && !done) e = fr_renderer_pass(r, &done);
  return e;
}

int fr_renderer_spp(const fr_renderer *r) { return r ? fr_progressive_spp(&r->p) : 0; }

fr_error fr_renderer_set_camera(fr_renderer *r, const fr_pinhole *c) {
  if (!r || !c) return fr_fail(FR_ERR_ARG, "fr_renderer_set_camera: NULL");
  if (c->width != r->w.cam.width || c->height != r->w.cam.height)
    return fr_fail(FR_ERR_ARG, "fr_renderer_set_camera: %dx%d is not the renderer's %dx%d", c->width, c->height,
                   r->w.cam.width, r->w.cam.height);
  fr_render_desc d = r->d;
  d.camera = *c;
  fr_view v;
  fr_camera cam;
  fr_error e = view_of(r->s, &d, &v, &cam);
  if (e) return e;
  r->d.camera = *c;
  r->p.w.cam = cam;
  r->p.w.view = v;
  fr_progressive_restart(&r->p);
  return FR_OK;
}

fr_error fr_renderer_image(fr_renderer *r, int display, float *rgb, float *albedo, float *normal, float *depth) {
  if (!r || !rgb) return fr_fail(FR_ERR_ARG, "fr_renderer_image: NULL renderer or image");
  const size_t np = (size_t)r->w.cam.width * (size_t)r->w.cam.height;
  if (r->dn && (!albedo || !normal || !depth) && !r->guides) {
    r->guides = malloc(np * 7 * sizeof(float));
    if (!r->guides) return fr_fail(FR_ERR_NOMEM, "out of memory for the denoiser's guides");
  }
  float *a = albedo ? albedo : r->guides ? r->guides : NULL;
  float *n = normal ? normal : r->guides ? r->guides + 3 * np : NULL;
  float *z = depth ? depth : r->guides ? r->guides + 6 * np : NULL;
  fr_progressive_resolve(&r->p, rgb, a, n, z);
  if (r->dn && fr_progressive_spp(&r->p) > 0)
    fr_denoise(r->dn, rgb, a, n, z, fr_progressive_spp(&r->p), r->w.threads, rgb);
  if (display && r->d.shade == FR_RENDER_PATH) fr_tonemap_filmic(rgb, 3 * np, r->d.exposure);
  return FR_OK;
}
