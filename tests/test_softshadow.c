/*
 * Soft-shadow images converge: every sample count and light-set choice of
 * `render --shade softshadow` against a many-sample reference of the same
 * view, by the mean error of the light visibility over the pixels that hit
 * and by the largest mean error of any 8x8 block, so that a structured
 * pattern (a grid of pixel-sized errors) fails even where the mean is small.
 * More samples must never make an image worse.
 */
#include <string.h>
#include "render/softshadow.h"
#include "render/views.h"
#include "test_util.h"

enum { SZ = 128, BLOCK = 8 };

typedef struct quality { double mean, block; } quality;

static quality compare(const float *vis, const float *ref, const float *img) {
  quality q = {0, 0};
  size_t n = 0;
  for (int by = 0; by < SZ; by += BLOCK)
    for (int bx = 0; bx < SZ; bx += BLOCK) {
      double sum = 0;
      int cnt = 0;
      for (int y = by; y < by + BLOCK; y++)
        for (int x = bx; x < bx + BLOCK; x++) {
          const size_t i = (size_t)y * SZ + (size_t)x;
          if (img[3 * i] == 0.05f && img[3 * i + 1] == 0.05f && img[3 * i + 2] == 0.05f) continue; /* background */
          sum += fabs((double)vis[i] - (double)ref[i]);
          cnt++;
        }
      q.mean += sum;
      n += (size_t)cnt;
      if (cnt == BLOCK * BLOCK && sum / cnt > q.block) q.block = sum / cnt;
    }
  q.mean /= n ? (double)n : 1.0;
  return q;
}

static void converge(const char *rel) {
  char path[1024];
  shared_scene_path(path, sizeof path, rel);
  fr_workload w;
  fr_scene *s = shared_workload(path, SZ, &w);
  w.threads = 2;
  fr_mft_tracer mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  fr_tracer t = fr_tracer_mft(&mctx);
  static float img[SZ * SZ * 3], ref[SZ * SZ], vis[SZ * SZ];
  fr_workload_result r;
  /* the reference: 1024 spread samples, seeded apart from the images */
  w.seed = 1000;
  fr_softshadow_opts ro = {1024, 0, FR_LIGHT_SETS_SPREAD};
  assert_int_equal(fr_render_softshadow(&w, &t, &ro, img, ref, &r), FR_OK);
  w.seed = 1;
  static const struct { int samples, filter; fr_light_sets sets; double mean, block; } cases[] = {
      {16, 1, FR_LIGHT_SETS_CELLS, 0.06, 0.35},   /* the default: cells and the filter */
      {16, 0, FR_LIGHT_SETS_SPREAD, 0.02, 0.10},
      {16, 0, FR_LIGHT_SETS_CELLS, 0.12, 0.50},   /* unfiltered cells: a pixel sees a sixteenth of the light */
      {64, 1, FR_LIGHT_SETS_CELLS, 0.01, 0.06},   /* more than 16: spread passes, whatever was asked */
      {64, 0, FR_LIGHT_SETS_SPREAD, 0.01, 0.06},
      {256, 1, FR_LIGHT_SETS_CELLS, 0.005, 0.03},
      {256, 0, FR_LIGHT_SETS_SPREAD, 0.005, 0.03},
  };
  double err[7];
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    fr_softshadow_opts o = {cases[c].samples, cases[c].filter, cases[c].sets};
    assert_int_equal(fr_render_softshadow(&w, &t, &o, img, vis, &r), FR_OK);
    quality q = compare(vis, ref, img);
    print_message("%s: %d samples, %s, filter %s: mean error %.4f, worst 8x8 block %.4f\n", s->name, o.samples,
                  o.sets == FR_LIGHT_SETS_CELLS ? "cells" : "spread", o.filter ? "on" : "off", q.mean, q.block);
    if (q.mean > cases[c].mean || q.block > cases[c].block)
      fail_msg("%s: %d samples: mean error %.4f (bound %.3f), worst block %.4f (bound %.3f)", s->name, o.samples, q.mean,
               cases[c].mean, q.block, cases[c].block);
    err[c] = q.mean;
  }
  /* more samples are never worse than fewer of the same kind, nor than the
   * default 16 */
  for (size_t c = 5; c < 7; c++) assert_true(err[c] <= err[c - 2] && err[c] <= err[0]);
  fr_scene_release(s);
}

static void kitchen(void **state) { (void)state; converge("kitchen/kitchen.ply.zst"); }
static void conference(void **state) { (void)state; converge("conference/conference.ply.zst"); }

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(kitchen),
      cmocka_unit_test(conference),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
