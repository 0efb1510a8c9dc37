/* fr_renderer: the progressive renderer (render/progressive.h) behind the
 * public handle, with what each shade needs made once and kept while the
 * fields it was made from stay the same: the path tracer's scene
 * (render/path_scene.h), the Whitted materials, the denoiser and the
 * temporal blend. Camera rays and shadows go as multi-frusta where the
 * description asks and the scene has no spheres, paths as the scene's
 * streams, as the command renders them. */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"
#include "base/timer.h"
#include "film/denoise.h"
#include "film/temporal.h"
#include "film/tonemap.h"
#include "io/scene_file.h"
#include "render/path_scene.h"
#include "render/progressive.h"
#include "renderer_tuning.h"
#include "scene.h"

_Static_assert((int)FR_RENDER_PATH == (int)FR_SM_PATH && (int)FR_RENDER_EYELIGHT == (int)FR_SM_EYELIGHT &&
                   (int)FR_RENDER_SOFTSHADOW == (int)FR_SM_SOFTSHADOW && (int)FR_RENDER_AO == (int)FR_SM_AO &&
                   (int)FR_RENDER_WHITTED == (int)FR_SM_WHITTED,
               "fr_render_shade follows fr_shade_mode");
_Static_assert(FR_LIGHT_ENV == FR_PATH_LIGHT_ENV && FR_LIGHT_AREA == FR_PATH_LIGHT_AREA &&
                   FR_LIGHT_POINT == FR_PATH_LIGHT_POINT,
               "FR_LIGHT_* are the path tracer's light bits");

#define DEFAULT_PASS_SPP FR_PATH_CHUNK

/* A description with its own copies of the strings. */
typedef struct owned_desc {
  fr_render_desc d;
  char *str[3]; /* environment, mirror, glass */
} owned_desc;

static void owned_free(owned_desc *o) {
  for (int i = 0; i < 3; i++) free(o->str[i]);
  memset(o, 0, sizeof *o);
}

static fr_error owned_set(owned_desc *o, const fr_render_desc *d) {
  owned_desc n = {*d, {NULL, NULL, NULL}};
  const char *src[3] = {d->environment, d->mirror, d->glass};
  for (int i = 0; i < 3; i++)
    if (src[i] && !(n.str[i] = strdup(src[i]))) {
      owned_free(&n);
      return fr_fail(FR_ERR_NOMEM, "out of memory");
    }
  n.d.environment = n.str[0], n.d.mirror = n.str[1], n.d.glass = n.str[2];
  owned_free(o);
  *o = n;
  return FR_OK;
}

struct fr_renderer {
  const fr_scene *s;
  owned_desc d;
  fr_renderer_tuning tune;
  fr_progressive p;
  int p_ready;
  fr_path_scene *path;       /* made for path_from's fields (camera aside) */
  owned_desc path_from;
  fr_whitted_mats *mats;     /* made for mats_from's mirror and glass */
  owned_desc mats_from;
  fr_mft_tracer mctx;
  fr_denoiser *dn;
  fr_temporal *tp;
  int buf_w, buf_h;          /* the size dn and tp are for */
  float *frame;              /* temporal: the blended image, its albedo, normal and depth (10 floats a pixel) */
  int frame_ready;
  float *guides;             /* the denoiser's when the caller wants none */
  int cancel;                /* read atomically by the pass's threads */
  fr_render_stats stats;
};

void fr_render_desc_default(fr_render_desc *d) {
  if (!d) return;
  memset(d, 0, sizeof *d);
  d->shade = FR_RENDER_EYELIGHT;
  d->spp = 16;
  d->lights = FR_LIGHT_ENV | FR_LIGHT_AREA;
  d->env_color[0] = d->env_color[1] = d->env_color[2] = 1.0f;
  d->env_intensity = 1.0f;
  d->sampler = FR_SAMPLER_HAMMERSLEY;
  d->seed = 1;
  d->camera_frusta = 1;
  d->pass_spp = DEFAULT_PASS_SPP;
}

fr_error fr_render_desc_of_scene(const fr_scene *s, fr_render_desc *d) {
  if (!s || !d) return fr_fail(FR_ERR_ARG, "fr_render_desc_of_scene: NULL scene or description");
  if (!s->committed) return fr_fail(FR_ERR_STATE, "fr_render_desc_of_scene: the scene is not committed");
  fr_render_desc_default(d);
  const fr_scene_file *f = s->file;
  if (!f) return FR_OK;
  if (f->has_eye || f->has_at || f->has_up || f->has_fov) { /* the rest from the scene's own view */
    fr_view v = fr_view_of(s->name, s->bounds);
    if (f->has_eye) v.eye = f->eye;
    if (f->has_at) v.at = f->at;
    if (f->has_up) v.up = f->up;
    if (f->has_fov) v.fov = f->fov;
    v3_store(d->camera.eye, v.eye), v3_store(d->camera.at, v.at), v3_store(d->camera.up, v.up);
    d->camera.fov_deg = v.fov;
  }
  if (f->has_aperture) d->aperture = f->aperture;
  if (f->has_focus) d->focus = f->focus;
  if (f->has_env_file) d->environment = f->env_file;
  if (f->has_env_color) v3_store(d->env_color, f->env_color);
  if (f->has_env_intensity) d->env_intensity = f->env_intensity;
  if (f->has_env_rotate) d->env_rotate = f->env_rotate;
  if (f->has_area) {
    d->has_area = 1;
    v3_store(d->area_corner, f->area[0]), v3_store(d->area_e1, f->area[1]), v3_store(d->area_e2, f->area[2]);
  }
  if (f->has_area_radiance) v3_store(d->area_radiance, f->area_radiance);
  if (f->has_point) d->has_light = 1, v3_store(d->light, f->point);
  if (f->has_point_intensity) v3_store(d->light_intensity, f->point_intensity);
  if (f->has_lights) d->lights = FR_LIGHT_ENV | (f->has_area ? FR_LIGHT_AREA : 0u) | (f->has_point ? FR_LIGHT_POINT : 0u);
  if (f->has_size) d->camera.width = f->width, d->camera.height = f->height;
  if (f->has_spp) d->spp = f->spp;
  if (f->has_max_depth) d->max_depth = f->max_depth;
  if (f->has_seed) d->seed = (uint32_t)f->seed;
  if (f->has_sampler && !fr_sampler_parse(f->sampler, &d->sampler))
    return fr_fail(FR_ERR_FORMAT, "%s: render.sampler: '%s' is neither hammersley nor sobol", s->name, f->sampler);
  if (f->has_shade) {
    int m = -1;
    for (int k = 0; k < FR_SM_COUNT; k++)
      if (!strcmp(f->shade, fr_shade_mode_names[k])) m = k;
    if (m < 0) return fr_fail(FR_ERR_FORMAT, "%s: render.shade: '%s' is no shade frusta knows", s->name, f->shade);
    d->shade = (fr_render_shade)m;
  }
  return FR_OK;
}

void fr_renderer_tuning_default(fr_renderer_tuning *t) {
  memset(t, 0, sizeof *t);
  t->soft_preview = 1;
  t->soft_filter = 1;
  t->soft_sets = FR_LIGHT_SETS_CELLS;
}

static int finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }
static int nonneg3(const float *v) { return finite3(v) && v[0] >= 0.0f && v[1] >= 0.0f && v[2] >= 0.0f; }
static int str_eq(const char *a, const char *b) { return a == b || (a && b && !strcmp(a, b)); }

static int max_depth_of(const fr_render_desc *d) {
  return d->max_depth ? d->max_depth : d->shade == FR_RENDER_WHITTED ? 4 : 13;
}

/* Whether d is a description a renderer can follow (the scene aside). */
static fr_error check_desc(const fr_render_desc *d) {
  const char *f = "fr_renderer";
  if ((int)d->shade < 0 || (int)d->shade > (int)FR_RENDER_PATH) return fr_fail(FR_ERR_ARG, "%s: unknown shade %d", f, (int)d->shade);
  const char *shade = fr_shade_mode_name((fr_shade_mode)d->shade);
  if (d->spp < 1 || d->spp > 65536) return fr_fail(FR_ERR_ARG, "%s: spp %d is not in 1..65536", f, d->spp);
  if ((d->shade == FR_RENDER_AO || d->shade == FR_RENDER_SOFTSHADOW) && d->spp % 16)
    return fr_fail(FR_ERR_ARG, "%s: %s takes spp in multiples of 16, not %d", f, shade, d->spp);
  if (d->threads < 0) return fr_fail(FR_ERR_ARG, "%s: %d threads", f, d->threads);
  if (d->pass_spp < 1) return fr_fail(FR_ERR_ARG, "%s: pass_spp %d is not positive", f, d->pass_spp);
  const int depth = max_depth_of(d), most = d->shade == FR_RENDER_WHITTED ? FR_WHITTED_MAX_DEPTH : FR_PATH_MAX_DEPTH;
  if (d->max_depth < 0 || depth > most)
    return fr_fail(FR_ERR_ARG, "%s: max_depth %d is not in 1..%d for %s", f, d->max_depth, most, shade);
  if (d->lights & ~(FR_LIGHT_ENV | FR_LIGHT_AREA | FR_LIGHT_POINT))
    return fr_fail(FR_ERR_ARG, "%s: lights 0x%x has bits that are no FR_LIGHT_*", f, d->lights);
  if ((int)d->sampler < 0 || (int)d->sampler >= FR_SAMPLER_COUNT) return fr_fail(FR_ERR_ARG, "%s: unknown sampler %d", f, (int)d->sampler);
  if ((d->has_light && !finite3(d->light)) ||
      (d->has_area && (!finite3(d->area_corner) || !finite3(d->area_e1) || !finite3(d->area_e2))))
    return fr_fail(FR_ERR_ARG, "%s: a light is not finite", f);
  if (!nonneg3(d->light_intensity) || !nonneg3(d->area_radiance) || !nonneg3(d->env_color))
    return fr_fail(FR_ERR_ARG, "%s: a light's intensity, radiance or env_color is negative or not finite", f);
  if (!(d->env_intensity >= 0.0f && d->env_intensity <= 1e6f) || !(fabsf(d->env_rotate) <= 360.0f))
    return fr_fail(FR_ERR_ARG, "%s: env_intensity %g is not in 0..1e6 or env_rotate %g not in -360..360", f,
                   (double)d->env_intensity, (double)d->env_rotate);
  if (!(d->aperture >= 0.0f && d->aperture <= 1e9f) || !(d->focus >= 0.0f && d->focus <= 1e9f))
    return fr_fail(FR_ERR_ARG, "%s: aperture %g or focus %g is negative or too large", f, (double)d->aperture,
                   (double)d->focus);
  if (!(fabsf(d->exposure) <= 30.0f)) return fr_fail(FR_ERR_ARG, "%s: exposure %g is not in -30..30", f, (double)d->exposure);
  return FR_OK;
}

/* Every comma-separated name of list is a material of s (or, for
 * Whitted's mirrors, "all"). */
static fr_error check_names(const fr_scene *s, const char *list, const char *field, int all_ok) {
  for (const char *p = list; p && *p;) {
    const char *end = strchr(p, ',');
    const size_t n = end ? (size_t)(end - p) : strlen(p);
    int found = all_ok && n == 3 && !strncmp(p, "all", 3);
    for (size_t i = 0; !found && i < fr_scene_material_count(s); i++) {
      const char *name = fr_scene_material(s, i)->name;
      found = strlen(name) == n && !strncmp(name, p, n);
    }
    if (!found)
      return fr_fail(FR_ERR_ARG, "fr_renderer: %s names '%.*s', which is none of the scene's materials", field, (int)n, p);
    if (!end) break;
    p = end + 1;
  }
  return FR_OK;
}

static fr_error view_of(const fr_scene *s, const fr_render_desc *d, fr_view *v, fr_camera *cam) {
  *v = fr_view_of(s->name, s->bounds);
  const fr_pinhole *c = &d->camera;
  if (c->fov_deg != 0.0f) {
    v->eye = v3_load(c->eye), v->at = v3_load(c->at), v->up = v3_load(c->up), v->fov = c->fov_deg;
    if (!v3_finite(v->eye) || !v3_finite(v->at) || !v3_finite(v->up))
      return fr_fail(FR_ERR_ARG, "fr_renderer: the camera is not finite");
  }
  if (d->has_light) v->light = v3_load(d->light);
  if (d->has_area) v->area_c = v3_load(d->area_corner), v->area_e1 = v3_load(d->area_e1), v->area_e2 = v3_load(d->area_e2);
  return fr_camera_setup(cam, v->eye, v->at, v->up, v->fov, c->width, c->height);
}

/* Whether the path tracer made for a serves b (the camera aside). */
static int path_same(const fr_render_desc *a, const fr_render_desc *b) {
  return a->spp == b->spp && a->has_light == b->has_light && !memcmp(a->light, b->light, sizeof a->light) &&
         !memcmp(a->light_intensity, b->light_intensity, sizeof a->light_intensity) && a->has_area == b->has_area &&
         !memcmp(a->area_corner, b->area_corner, sizeof a->area_corner) && !memcmp(a->area_e1, b->area_e1, sizeof a->area_e1) &&
         !memcmp(a->area_e2, b->area_e2, sizeof a->area_e2) &&
         !memcmp(a->area_radiance, b->area_radiance, sizeof a->area_radiance) && a->lights == b->lights &&
         str_eq(a->environment, b->environment) && !memcmp(a->env_color, b->env_color, sizeof a->env_color) &&
         a->env_intensity == b->env_intensity && a->env_rotate == b->env_rotate && str_eq(a->mirror, b->mirror) &&
         str_eq(a->glass, b->glass) && max_depth_of(a) == max_depth_of(b) && a->sampler == b->sampler &&
         a->seed == b->seed && a->aperture == b->aperture && a->focus == b->focus;
}

/* Whether b renders the image a does, up to its camera and what is done
 * with the sums (exposure, denoise, temporal, threads, pass_spp). */
static int same_image(const fr_render_desc *a, const fr_render_desc *b) {
  return a->shade == b->shade && a->camera.width == b->camera.width && a->camera.height == b->camera.height &&
         a->camera_frusta == b->camera_frusta && path_same(a, b);
}

static int threads_of(const fr_render_desc *d) { return d->threads ? d->threads : omp_get_num_procs(); }
static int is_progressive(const fr_render_desc *d) { return fr_shade_mode_progressive((fr_shade_mode)d->shade); }
/* Whether d's temporal blend has anything to blend: the noisy shades. */
static int temporal_wanted(const fr_render_desc *d) {
  return d->temporal && (d->shade == FR_RENDER_PATH || d->shade == FR_RENDER_AO);
}
static int temporal_applies(const fr_renderer *r) { return r->tp && temporal_wanted(&r->d.d); }

/* The denoiser and the temporal blend d asks for, at its size; r's own are
 * kept where they serve. */
static fr_error ensure_buffers(fr_renderer *r, const fr_render_desc *d) {
  const int W = d->camera.width, H = d->camera.height;
  if (W != r->buf_w || H != r->buf_h) {
    fr_denoiser_free(r->dn), fr_temporal_free(r->tp);
    free(r->frame), free(r->guides);
    r->dn = NULL, r->tp = NULL, r->frame = r->guides = NULL, r->frame_ready = 0;
    r->buf_w = W, r->buf_h = H;
  }
  if (d->denoise && is_progressive(d) && !r->dn) {
    const fr_error e = fr_denoiser_new(W, H, &r->dn);
    if (e) return e;
  }
  if (temporal_wanted(d) && !r->tp) {
    r->frame = malloc((size_t)W * (size_t)H * 10 * sizeof(float));
    if (!r->frame || fr_temporal_new(W, H, &r->tp)) {
      free(r->frame);
      r->frame = NULL;
      return fr_fail(FR_ERR_NOMEM, "out of memory for the temporal blend of a %dx%d image", W, H);
    }
  }
  return FR_OK;
}

/* The progressive renderer's settings of d and the tuning. */
static void apply_settings(fr_renderer *r) {
  const fr_render_desc *d = &r->d.d;
  fr_progressive *p = &r->p;
  p->w.threads = threads_of(d);
  p->w.feed = r->tune.feed;
  p->w.progress = r->tune.progress;
  if (d->shade == FR_RENDER_PATH)
    p->spp_per_pass = r->tune.whole_path_passes || d->pass_spp > d->spp ? d->spp : d->pass_spp;
  /* ao: passes of 16 hemisphere rays; softshadow: the filtered preview of
   * 16 light samples first, then, if spp asks for more, passes of 16
   * spread samples whose mean replaces it */
  if (d->shade == FR_RENDER_AO) p->max_passes = d->spp / 16;
  if (d->shade == FR_RENDER_SOFTSHADOW) {
    p->soft = (fr_softshadow_opts){16, r->tune.soft_filter, r->tune.soft_sets};
    p->soft_preview = r->tune.soft_preview;
    p->max_passes = p->soft_preview ? 1 + (d->spp > 16 ? d->spp / 16 : 0) : d->spp / 16;
  }
}

static fr_error make_path(const fr_scene *s, const fr_render_desc *d, const fr_view *v, fr_path_scene **out) {
  fr_path_scene *ps = calloc(1, sizeof *ps);
  if (!ps) return fr_fail(FR_ERR_NOMEM, "out of memory");
  fr_path_options po;
  fr_path_options_default(&po);
  po.spp = d->spp, po.max_depth = max_depth_of(d), po.lights = (int)d->lights;
  po.sampler = d->sampler, po.seed = d->seed;
  po.env_file = d->environment, po.env_color = v3_load(d->env_color);
  po.env_intensity = d->env_intensity, po.env_rotate = d->env_rotate;
  po.mirror = d->mirror, po.glass = d->glass;
  po.aperture = d->aperture, po.focus = d->focus > 0.0f ? d->focus : -1.0f;
  po.area_radiance = v3_load(d->area_radiance), po.point_intensity = v3_load(d->light_intensity);
  fr_error e = fr_path_scene_init(ps, s, v, &po);
  if (e) { free(ps); return e; }
  *out = ps;
  return FR_OK;
}

static void free_path(fr_path_scene *ps) {
  if (ps) fr_path_scene_free(ps);
  free(ps);
}

static void free_mats(fr_whitted_mats *m) {
  if (m) fr_whitted_mats_free(m);
  free(m);
}

/* Everything made anew for d (the path tracer and materials reused where
 * they serve); r is left as it was on an error. */
static fr_error rebuild(fr_renderer *r, const fr_render_desc *d) {
  const fr_scene *s = r->s;
  fr_workload w;
  memset(&w, 0, sizeof w);
  fr_error e = view_of(s, d, &w.view, &w.cam);
  if (!e) e = check_names(s, d->mirror, "mirror", d->shade == FR_RENDER_WHITTED);
  if (!e) e = check_names(s, d->glass, "glass", 0);
  if (e) return e;
  const fr_shade_mode mode = (fr_shade_mode)d->shade;
  fr_shade_mode_workload(mode, &w.kind, &w.shade);
  w.scene = s;
  w.eps = 1e-4f * v3_len(v3_sub(s->bounds.hi, s->bounds.lo));
  w.threads = threads_of(d);
  w.seed = 1;
  w.max_depth = max_depth_of(d);
  owned_desc nd = {0}, path_from = {0}, mats_from = {0};
  fr_path_scene *path = NULL;
  fr_whitted_mats *mats = NULL;
  const int new_path = mode == FR_SM_PATH && !(r->path && path_same(&r->path_from.d, d));
  const int new_mats = mode == FR_SM_WHITTED &&
                       !(r->mats && str_eq(r->mats_from.d.mirror, d->mirror) && str_eq(r->mats_from.d.glass, d->glass));
  if ((e = owned_set(&nd, d))) return e;
  if (new_path && !(e = make_path(s, d, &w.view, &path))) e = owned_set(&path_from, d);
  if (!e && new_mats) {
    mats = calloc(1, sizeof *mats);
    e = !mats ? fr_fail(FR_ERR_NOMEM, "out of memory") : fr_whitted_mats_build(s, d->mirror, d->glass, mats);
    if (e) free(mats), mats = NULL;
    if (!e) e = owned_set(&mats_from, d);
  }
  if (mode == FR_SM_PATH && !e) w.path = path ? &path->setup : &r->path->setup;
  if (mode == FR_SM_WHITTED && !e) w.mats = mats ? mats : r->mats;
  fr_progressive p;
  memset(&p, 0, sizeof p);
  if (!e) e = fr_progressive_init(&p, &w, mode);
  if (!e) e = ensure_buffers(r, d);
  if (e) {
    if (p.sum) fr_progressive_free(&p);
    free_path(path), free_mats(mats);
    owned_free(&nd), owned_free(&path_from), owned_free(&mats_from);
    return e;
  }
  if (new_path) {
    free_path(r->path), owned_free(&r->path_from);
    r->path = path, r->path_from = path_from;
  }
  if (new_mats) {
    free_mats(r->mats), owned_free(&r->mats_from);
    r->mats = mats, r->mats_from = mats_from;
  }
  if (r->p_ready) fr_progressive_free(&r->p);
  r->p = p, r->p_ready = 1;
  owned_free(&r->d);
  r->d = nd;
  r->frame_ready = 0;
  if (r->tp) fr_temporal_reset(r->tp); /* another image: nothing to carry over */
  apply_settings(r);
  return FR_OK;
}

void fr_renderer_release(fr_renderer *r) {
  if (!r) return;
  if (r->p_ready) fr_progressive_free(&r->p);
  free_path(r->path), free_mats(r->mats);
  owned_free(&r->d), owned_free(&r->path_from), owned_free(&r->mats_from);
  fr_denoiser_free(r->dn);
  fr_temporal_free(r->tp);
  free(r->frame);
  free(r->guides);
  free(r);
}

fr_error fr_renderer_new(const fr_scene *s, const fr_render_desc *d, fr_renderer **out) {
  if (!s || !d || !out) return fr_fail(FR_ERR_ARG, "fr_renderer_new: NULL scene, description or out");
  *out = NULL;
  if (!s->committed) return fr_fail(FR_ERR_STATE, "fr_renderer_new: the scene is not committed");
  fr_error e = check_desc(d);
  if (e) return e;
  fr_renderer *r = calloc(1, sizeof *r);
  if (!r) return fr_fail(FR_ERR_NOMEM, "out of memory");
  r->s = s;
  fr_renderer_tuning_default(&r->tune);
  r->mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  if ((e = rebuild(r, d))) {
    fr_renderer_release(r);
    return e;
  }
  *out = r;
  return FR_OK;
}

fr_error fr_renderer_set_camera(fr_renderer *r, const fr_pinhole *c) {
  if (!r || !c) return fr_fail(FR_ERR_ARG, "fr_renderer_set_camera: NULL");
  const fr_pinhole *now = &r->d.d.camera;
  if (c->width != now->width || c->height != now->height)
    return fr_fail(FR_ERR_ARG, "fr_renderer_set_camera: %dx%d is not the renderer's %dx%d", c->width, c->height,
                   now->width, now->height);
  fr_render_desc d = r->d.d;
  d.camera = *c;
  fr_view v;
  fr_camera cam;
  fr_error e = view_of(r->s, &d, &v, &cam);
  if (e) return e;
  r->d.d.camera = *c;
  r->p.w.cam = cam;
  r->p.w.view = v;
  if (d.shade == FR_RENDER_PATH) r->p.path.focus = fr_path_focus(d.focus, &v);
  fr_progressive_restart(&r->p);
  r->frame_ready = 0;
  return FR_OK;
}

fr_error fr_renderer_update(fr_renderer *r, const fr_render_desc *d) {
  if (!r || !d) return fr_fail(FR_ERR_ARG, "fr_renderer_update: NULL renderer or description");
  fr_error e = check_desc(d);
  if (e) return e;
  if (!same_image(&r->d.d, d)) return rebuild(r, d);
  if ((e = ensure_buffers(r, d))) return e;
  if (memcmp(&d->camera, &r->d.d.camera, sizeof d->camera) && (e = fr_renderer_set_camera(r, &d->camera))) return e;
  if (r->tp && d->temporal != r->d.d.temporal) fr_temporal_reset(r->tp);
  if ((e = owned_set(&r->d, d))) return e;
  apply_settings(r);
  return FR_OK;
}

void fr_renderer_desc(const fr_renderer *r, fr_render_desc *d) {
  if (r && d) *d = r->d.d;
}

void fr_renderer_tune(fr_renderer *r, const fr_renderer_tuning *t) {
  r->tune = *t;
  apply_settings(r);
  fr_progressive_restart(&r->p);
  r->frame_ready = 0;
}

int fr_renderer_uses_frusta(const fr_renderer *r) {
  return !r->tune.has_tracer && r->d.d.camera_frusta && !fr_scene_sphere_count(r->s);
}

const fr_path_setup *fr_renderer_path_setup(const fr_renderer *r) {
  return r->d.d.shade == FR_RENDER_PATH ? &r->p.path : NULL;
}

const fr_whitted_mats *fr_renderer_whitted_mats(const fr_renderer *r) {
  return r->d.d.shade == FR_RENDER_WHITTED ? r->mats : NULL;
}

void fr_renderer_visibility(const fr_renderer *r, float *vis) { fr_progressive_visibility(&r->p, vis); }

void fr_renderer_set_cancel(fr_renderer *r, int cancel) {
  if (r) __atomic_store_n(&r->cancel, cancel != 0, __ATOMIC_RELAXED);
}

fr_error fr_renderer_pass(fr_renderer *r, int *done) {
  if (!r) return fr_fail(FR_ERR_ARG, "fr_renderer_pass: NULL renderer");
  r->stats.rays = 0, r->stats.seconds = 0.0, r->stats.cancelled = 0;
  if (!fr_progressive_done(&r->p)) {
    const fr_tracer t = r->tune.has_tracer ? r->tune.tracer
                        : fr_renderer_uses_frusta(r) ? fr_tracer_mft(&r->mctx)
                                                     : fr_tracer_frusta(r->s);
    fr_workload_result res;
    fr_progressive_pass(&r->p, &t, &r->cancel, &res);
    r->stats.rays = res.rays, r->stats.seconds = res.seconds, r->stats.cancelled = res.cancelled;
    if (res.failed) return fr_fail(FR_ERR_NOMEM, "fr_renderer_pass: %s", fr_last_error());
    if (res.cancelled) r->frame_ready = 0;
    if (!res.cancelled && temporal_applies(r)) { /* blended once per pass: the blend is the next one's history */
      const size_t np = r->p.np;
      float *rgb = r->frame, *albedo = rgb + 3 * np, *normal = rgb + 6 * np, *depth = rgb + 9 * np;
      fr_progressive_resolve(&r->p, rgb, albedo, normal, depth);
      fr_temporal_apply(r->tp, &r->p.w.cam, r->p.passes, depth, normal, rgb, r->p.w.threads);
      r->frame_ready = 1;
    }
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

int fr_renderer_passes(const fr_renderer *r) {
  const fr_progressive *p = &r->p;
  if (p->mode == FR_SM_PATH) return (p->path.spp + p->spp_per_pass - 1) / p->spp_per_pass;
  return p->max_passes > 0 ? p->max_passes : 1;
}

int fr_renderer_done(const fr_renderer *r) { return !r || fr_progressive_done(&r->p); }

int fr_renderer_spp(const fr_renderer *r) { return r ? fr_progressive_spp(&r->p) : 0; }

void fr_renderer_stats(const fr_renderer *r, fr_render_stats *out) {
  if (!r || !out) return;
  *out = r->stats;
  out->reused = temporal_applies(r) ? fr_temporal_reused(r->tp) : 0.0f;
}

fr_error fr_renderer_image(fr_renderer *r, int display, float *rgb, float *albedo, float *normal, float *depth) {
  if (!r || !rgb) return fr_fail(FR_ERR_ARG, "fr_renderer_image: NULL renderer or image");
  const fr_render_desc *d = &r->d.d;
  const size_t np = r->p.np;
  const int denoise = d->denoise && r->dn && is_progressive(d);
  if (denoise && (!albedo || !normal || !depth) && !r->guides) {
    r->guides = malloc(np * 7 * sizeof(float));
    if (!r->guides) return fr_fail(FR_ERR_NOMEM, "out of memory for the denoiser's guides");
  }
  float *a = albedo ? albedo : denoise ? r->guides : NULL;
  float *n = normal ? normal : denoise ? r->guides + 3 * np : NULL;
  float *z = depth ? depth : denoise ? r->guides + 6 * np : NULL;
  int spp = fr_progressive_spp(&r->p);
  if (temporal_applies(r) && r->frame_ready) {
    const float *f = r->frame;
    memcpy(rgb, f, 3 * np * sizeof(float));
    if (a) memcpy(a, f + 3 * np, 3 * np * sizeof(float));
    if (n) memcpy(n, f + 6 * np, 3 * np * sizeof(float));
    if (z) memcpy(z, f + 9 * np, np * sizeof(float));
    spp = (int)((float)spp * (1.0f + fr_temporal_worth(r->tp)));
  } else {
    fr_progressive_resolve(&r->p, rgb, a, n, z);
  }
  r->stats.denoise_seconds = 0.0;
  if (denoise && spp > 0) {
    const double t0 = fr_seconds();
    fr_denoise(r->dn, rgb, a, n, z, spp, r->p.w.threads, rgb);
    r->stats.denoise_seconds = fr_seconds() - t0;
  }
  if (display && d->shade == FR_RENDER_PATH) fr_tonemap_filmic(rgb, 3 * np, d->exposure);
  return FR_OK;
}
