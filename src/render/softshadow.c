#include "softshadow.h"
#include <stdlib.h>
#include "base/error.h"
#include "base/timer.h"
#include "render/progressive.h"

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
  fr_progressive p;
  fr_error e = fr_progressive_init(&p, w0, FR_SM_SOFTSHADOW);
  if (e) return e;
  const fr_softshadow_opts used = fr_softshadow_used(o);
  const int passes = used.samples / 16;
  p.soft = used;
  p.soft_preview = passes == 1; /* one pass: the filtered real-time frame; more: spread sets only */
  p.w.progress = w0->progress && passes == 1;
  const double t0 = fr_seconds();
  uint64_t rays = 0;
  for (int k = 0; k < passes; k++) {
    fr_workload_result r;
    fr_progressive_pass(&p, t, NULL, &r);
    rays += r.rays;
    if (r.failed) {
      fr_progressive_free(&p);
      return FR_ERR_ARG;
    }
  }
  if (vis_out) {
    fr_progressive_visibility(&p, vis_out);
    fr_progressive_shade_soft(&p, vis_out, image);
  } else {
    fr_progressive_resolve(&p, image, NULL, NULL, NULL);
  }
  res->rays = rays;
  res->seconds = fr_seconds() - t0;
  fr_progressive_free(&p);
  return FR_OK;
}
