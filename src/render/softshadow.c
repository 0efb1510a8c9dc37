#include "softshadow.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"
#include "base/timer.h"
#include "render/shadow_filter.h"

fr_softshadow_opts fr_softshadow_used(const fr_softshadow_opts *o) {
  fr_softshadow_opts u = *o;
  /* Several passes converge to the light's true visibility only if each
   * pass samples the whole light: with cells sets a pixel's samples stay
   * in one cell of the light in every pass, and a grid of pixel-sized
   * errors shows through the unfiltered average. */
  if (u.samples > 16) { u.sets = FR_LIGHT_SETS_SPREAD; u.filter = 0; }
  return u;
}

fr_error fr_render_softshadow(const fr_workload *w0, const fr_tracer *t, const fr_softshadow_opts *o, float *image,
                              float *vis_out, fr_workload_result *res) {
  if (o->samples < 16 || o->samples % 16) return fr_fail(FR_ERR_ARG, "light samples must be a multiple of 16, not %d", o->samples);
  const int W = w0->cam.width, H = w0->cam.height;
  size_t np = (size_t)W * (size_t)H;
  float *buf = malloc(np * 10 * sizeof(float));
  if (!buf) return fr_fail(FR_ERR_NOMEM, "out of memory for a %dx%d image", W, H);
  float *vis = buf, *acc = buf + np, *depth = buf + 2 * np, *normal = buf + 3 * np, *albedo = buf + 6 * np;
  fr_workload w = *w0;
  w.kind = FR_WL_SOFT16;
  w.image = NULL;
  const fr_softshadow_opts used = fr_softshadow_used(o);
  const int passes = used.samples / 16;
  w.light_sets_kind = used.sets;
  w.gbuf_vis = vis; w.gbuf_depth = depth; w.gbuf_normal = normal; w.gbuf_albedo = albedo;
  memset(acc, 0, np * sizeof(float));
  double t0 = fr_seconds();
  uint64_t rays = 0;
  for (int p = 0; p < passes; p++) {
    w.seed = w0->seed + (uint64_t)p * 0x9E3779B97F4A7C15ull; /* a new scramble per pass */
    w.progress = w0->progress && passes == 1;
    rays += fr_workload_run(&w, t).rays;
    for (size_t i = 0; i < np; i++) acc[i] += vis[i];
  }
  for (size_t i = 0; i < np; i++) acc[i] /= (float)passes;
  if (used.filter) fr_filter_visibility(acc, depth, normal, W, H, vis);
  else memcpy(vis, acc, np * sizeof(float));
  vec3 centre = v3_add(w.view.area_c, v3_scale(v3_add(w.view.area_e1, w.view.area_e2), 0.5f));
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      size_t i = (size_t)y * (size_t)W + (size_t)x;
      float *px = image + 3 * i;
      if (!(depth[i] < INFINITY)) { px[0] = px[1] = px[2] = 0.05f; continue; }
      fr_ray r = fr_camera_ray(&w.cam, x, y);
      vec3 d = v3_load(r.dir), n = v3_load(normal + 3 * i), p = v3_add(v3_load(r.org), v3_scale(d, depth[i]));
      vec3 L = v3_norm(v3_sub(centre, p));
      float k = 0.15f * fabsf(v3_dot(n, d)) + 0.85f * vis[i] * fmaxf(0.0f, v3_dot(n, L));
      for (int c = 0; c < 3; c++) px[c] = albedo[3 * i + c] * k;
    }
  if (vis_out) memcpy(vis_out, vis, np * sizeof(float));
  res->rays = rays;
  res->seconds = fr_seconds() - t0;
  free(buf);
  return FR_OK;
}
