/*
 * Soft shadows from the scene's quad light, as Benthin & Wald render them:
 * visibility from 16 shadow rays per pixel (multi-frusta traced when the
 * tracer can), 4x4 interleaved sample sets and the discontinuity filter,
 * kept apart from shading, which takes one sample at the light's centre.
 */
#ifndef FR_RENDER_SOFTSHADOW_H
#define FR_RENDER_SOFTSHADOW_H
#include "render/workload.h"

typedef struct fr_softshadow_opts {
  int samples;          /* per pixel: 16, or a multiple of 16 (passes of 16 spread samples averaged, no
                           filter: converges to the reference) */
  int filter;           /* the discontinuity filter (16 samples only) */
  fr_light_sets sets;   /* how a 4x4 block's 256 samples are dealt out (16 samples only) */
} fr_softshadow_opts;

/* The options a render with o really uses: more than 16 samples take
 * unfiltered passes of spread samples. */
fr_softshadow_opts fr_softshadow_used(const fr_softshadow_opts *o);

/* image: w->cam.width * height * 3 RGB; vis: the same pixels' visibility
 * (may be NULL). w->kind, image and gbuf fields are ignored. Returns the rays
 * and seconds of all passes (the filter and shading included). */
fr_error fr_render_softshadow(const fr_workload *w, const fr_tracer *t, const fr_softshadow_opts *o, float *image,
                              float *vis, fr_workload_result *res);
#endif
