/* Progressive rendering of one view (see progressive.h). */
#include "render/progressive.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"
#include "render/shadow_filter.h"

const char *const fr_shade_mode_names[FR_SM_COUNT] = {"eyelight", "normals", "shadows", "softshadow",
                                                      "whitted",  "ao",      "path"};

const char *fr_shade_mode_name(fr_shade_mode m) { return m < FR_SM_COUNT ? fr_shade_mode_names[m] : "?"; }

void fr_shade_mode_workload(fr_shade_mode m, fr_workload_kind *kind, fr_shade *shade) {
  static const fr_workload_kind kinds[FR_SM_COUNT] = {FR_WL_PRIMARY, FR_WL_PRIMARY, FR_WL_SHADOW, FR_WL_SOFT16,
                                                       FR_WL_WHITTED, FR_WL_AO16,   FR_WL_PATH};
  *kind = kinds[m];
  *shade = m == FR_SM_EYELIGHT ? FR_SHADE_EYELIGHT : m == FR_SM_NORMALS ? FR_SHADE_NORMALS : FR_SHADE_LIGHT;
}

int fr_shade_mode_progressive(fr_shade_mode m) { return m == FR_SM_SOFTSHADOW || m == FR_SM_AO || m == FR_SM_PATH; }

fr_error fr_progressive_init(fr_progressive *p, const fr_workload *w, fr_shade_mode m) {
  memset(p, 0, sizeof *p);
  p->w = *w;
  p->mode = m;
  p->soft = (fr_softshadow_opts){16, 1, FR_LIGHT_SETS_CELLS};
  p->spp_per_pass = 1;
  p->soft_preview = 1;
  if (m == FR_SM_PATH) {
    if (!w->path) return fr_fail(FR_ERR_ARG, "path tracing without a path setup");
    p->path = *w->path;
    p->w.path = &p->path;
  }
  p->np = (size_t)w->cam.width * (size_t)w->cam.height;
  p->sum = malloc(p->np * 3 * sizeof(float));
  p->pass = malloc(p->np * 4 * sizeof(float));
  p->albedo = malloc(p->np * 7 * sizeof(float));
  if (!p->sum || !p->pass || !p->albedo) {
    fr_progressive_free(p);
    return fr_fail(FR_ERR_NOMEM, "out of memory for a %dx%d image", w->cam.width, w->cam.height);
  }
  p->normal = p->albedo + 3 * p->np;
  p->depth = p->albedo + 6 * p->np;
  fr_progressive_restart(p);
  return FR_OK;
}

void fr_progressive_free(fr_progressive *p) {
  free(p->sum);
  free(p->pass);
  free(p->albedo);
  p->sum = p->pass = p->albedo = p->normal = p->depth = NULL;
}

void fr_progressive_restart(fr_progressive *p) {
  p->passes = 0;
  p->path_spp = 0;
  memset(p->sum, 0, p->np * 3 * sizeof(float));
  memset(p->albedo, 0, p->np * 7 * sizeof(float));
}

/* Soft shadows: the spread passes summed, and whether the preview is what shows. */
static int soft_spread(const fr_progressive *p) { return p->passes - (p->soft_preview && p->passes > 0); }
/* The preview shows until FR_SOFT_SPREAD_SHOWN spread passes are summed,
 * or all there will be where max_passes allows fewer. */
static int soft_shows_preview(const fr_progressive *p) {
  if (!p->soft_preview) return 0;
  const int spread_max = p->max_passes > 0 ? p->max_passes - 1 : FR_SOFT_SPREAD_SHOWN;
  const int shown_at = spread_max < FR_SOFT_SPREAD_SHOWN ? spread_max : FR_SOFT_SPREAD_SHOWN;
  return shown_at == 0 || soft_spread(p) < shown_at;
}

int fr_progressive_spp(const fr_progressive *p) {
  switch (p->mode) {
  case FR_SM_SOFTSHADOW: return p->passes == 0 ? 0 : soft_shows_preview(p) ? 16 : 16 * soft_spread(p);
  case FR_SM_AO: return 16 * p->passes;
  case FR_SM_PATH: return p->path_spp;
  default: return p->passes;
  }
}

int fr_progressive_done(const fr_progressive *p) {
  if (p->mode == FR_SM_PATH) return fr_progressive_spp(p) >= p->path.spp;
  if (fr_shade_mode_progressive(p->mode)) return p->max_passes > 0 && p->passes >= p->max_passes;
  return p->passes > 0;
}

void fr_progressive_pass(fr_progressive *p, const fr_tracer *t, const int *cancel, fr_workload_result *r) {
  memset(r, 0, sizeof *r);
  if (fr_progressive_done(p)) return;
  fr_workload w = p->w;
  fr_shade_mode_workload(p->mode, &w.kind, &w.shade);
  w.cancel = cancel;
  w.image = NULL;
  w.gbuf_vis = w.gbuf_depth = w.gbuf_normal = w.gbuf_albedo = NULL;
  const uint64_t golden = 0x9E3779B97F4A7C15ull; /* a new scramble per pass */
  float *vis = p->pass + 3 * p->np;
  const int preview = p->mode == FR_SM_SOFTSHADOW && p->soft_preview && p->passes == 0;
  switch (p->mode) {
  case FR_SM_SOFTSHADOW:
    w.seed += (uint64_t)(preview ? 0 : soft_spread(p)) * golden;
    w.light_sets_kind = preview ? p->soft.sets : FR_LIGHT_SETS_SPREAD;
    w.gbuf_vis = vis, w.gbuf_depth = p->depth, w.gbuf_normal = p->normal, w.gbuf_albedo = p->albedo;
    break;
  case FR_SM_AO:
    w.seed += (uint64_t)p->passes * golden;
    w.image = p->pass;
    w.gbuf_vis = vis, w.gbuf_depth = p->depth, w.gbuf_normal = p->normal, w.gbuf_albedo = p->albedo;
    break;
  case FR_SM_PATH:
    w.path = &p->path; /* p's own copy, wherever p now lives */
    p->path.spp_begin = fr_progressive_spp(p);
    p->path.spp_end = p->path.spp_begin + p->spp_per_pass < p->path.spp ? p->path.spp_begin + p->spp_per_pass : p->path.spp;
    w.image = p->sum;
    w.gbuf_albedo = p->albedo, w.gbuf_normal = p->normal, w.gbuf_depth = p->depth;
    break;
  default:
    w.image = p->sum;
    break;
  }
  *r = fr_workload_run(&w, t);
  if (r->cancelled) { /* a path pass added some of its tiles: start again */
    fr_progressive_restart(p);
    return;
  }
  if (preview)
    memcpy(p->sum + p->np, vis, p->np * sizeof(float));
  else if (p->mode == FR_SM_SOFTSHADOW)
    for (size_t i = 0; i < p->np; i++) p->sum[i] += vis[i];
  else if (p->mode == FR_SM_AO)
    for (size_t i = 0; i < 3 * p->np; i++) p->sum[i] += p->pass[i];
  else if (p->mode == FR_SM_PATH)
    p->path_spp = p->path.spp_end;
  p->passes++;
}

void fr_progressive_visibility(const fr_progressive *p, float *vis) {
  const size_t np = p->np;
  if (p->mode != FR_SM_SOFTSHADOW || p->passes == 0) {
    memset(vis, 0, np * sizeof(float));
  } else if (soft_shows_preview(p)) {
    if (p->soft.filter) fr_filter_visibility(p->sum + np, p->depth, p->normal, p->w.cam.width, p->w.cam.height, vis);
    else memcpy(vis, p->sum + np, np * sizeof(float));
  } else {
    const float k = (float)soft_spread(p);
    for (size_t i = 0; i < np; i++) vis[i] = p->sum[i] / k;
  }
}

void fr_progressive_shade_soft(const fr_progressive *p, const float *vis, float *image) {
  const fr_workload *w = &p->w;
  const int W = w->cam.width, H = w->cam.height;
  const vec3 centre = v3_add(w->view.area_c, v3_scale(v3_add(w->view.area_e1, w->view.area_e2), 0.5f));
#pragma omp parallel for schedule(static) num_threads(w->threads > 0 ? w->threads : 1)
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      const size_t i = (size_t)y * (size_t)W + (size_t)x;
      float *px = image + 3 * i;
      if (!(p->depth[i] < INFINITY)) { px[0] = px[1] = px[2] = 0.05f; continue; }
      const fr_ray r = fr_camera_ray(&w->cam, x, y);
      const vec3 d = v3_load(r.dir), n = v3_load(p->normal + 3 * i), q = v3_add(v3_load(r.org), v3_scale(d, p->depth[i]));
      const vec3 L = v3_norm(v3_sub(centre, q));
      const float k = 0.15f * fabsf(v3_dot(n, d)) + 0.85f * vis[i] * fmaxf(0.0f, v3_dot(n, L));
      for (int c = 0; c < 3; c++) px[c] = p->albedo[3 * i + c] * k;
    }
}

/* Soft shadows' image when the caller wants no visibility of its own. */
static void resolve_soft(const fr_progressive *p, float *image) {
  float *vis = malloc(p->np * sizeof(float));
  if (!vis) { memset(image, 0, 3 * p->np * sizeof(float)); return; }
  fr_progressive_visibility(p, vis);
  fr_progressive_shade_soft(p, vis, image);
  free(vis);
}

void fr_progressive_resolve(const fr_progressive *p, float *rgb, float *albedo, float *normal, float *depth) {
  const size_t np = p->np;
  if (p->passes == 0) {
    memset(rgb, 0, 3 * np * sizeof(float));
    if (albedo) memset(albedo, 0, 3 * np * sizeof(float));
    if (normal) memset(normal, 0, 3 * np * sizeof(float));
    if (depth)
      for (size_t i = 0; i < np; i++) depth[i] = FR_DEPTH_MISS;
    return;
  }
  /* the path tracer sums its guides over the samples; the others write a pass's */
  const float g = p->mode == FR_SM_PATH ? 1.0f / (float)fr_progressive_spp(p) : 1.0f;
  if (p->mode == FR_SM_SOFTSHADOW) {
    resolve_soft(p, rgb);
  } else {
    const float inv = p->mode == FR_SM_PATH ? g : p->mode == FR_SM_AO ? 1.0f / (float)p->passes : 1.0f;
    for (size_t i = 0; i < 3 * np; i++) rgb[i] = p->sum[i] * inv;
  }
  if (albedo)
    for (size_t i = 0; i < 3 * np; i++) albedo[i] = p->albedo[i] * g;
  if (normal)
    for (size_t i = 0; i < 3 * np; i++) normal[i] = p->normal[i] * g;
  if (depth)
    for (size_t i = 0; i < np; i++) depth[i] = p->mode == FR_SM_PATH ? p->depth[i] * g : p->depth[i] < INFINITY ? p->depth[i] : FR_DEPTH_MISS;
}
