/*
 * The denoiser alone (film/denoise.h) on a real frame: kitchen with its
 * materials path traced at 1 sample per pixel (1024x768 by default, the
 * viewer's frame) through the public renderer, its image, albedo, normal
 * and depth handed to fr_denoise on 2 threads, REPEAT times on one
 * denoiser as the viewer calls it frame after frame; prints the best and
 * the median. For the benchmark only (bench/denoise_time.sh builds it).
 *   usage: denoise_time SCENE [WIDTH HEIGHT [REPEAT]]
 */
#include <stdio.h>
#include <stdlib.h>
#include "base/timer.h"
#include "film/denoise.h"
#include "frusta.h"

static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

int main(int argc, char **argv) {
  if (argc < 2) { fprintf(stderr, "usage: denoise_time SCENE [WIDTH HEIGHT [REPEAT]]\n"); return 2; }
  const int W = argc > 3 ? atoi(argv[2]) : 1024, H = argc > 3 ? atoi(argv[3]) : 768, repeat = argc > 4 ? atoi(argv[4]) : 20;
  if (W < 1 || H < 1 || repeat < 1 || repeat > 10000) { fprintf(stderr, "denoise_time: bad size or repeat\n"); return 2; }
  fr_scene *s;
  fr_renderer *r;
  fr_render_desc d;
  fr_render_desc_default(&d);
  d.camera.width = W, d.camera.height = H, d.shade = FR_RENDER_PATH, d.spp = 1, d.threads = 2;
  if (fr_scene_load(argv[1], &s) || fr_scene_commit(s) || fr_renderer_new(s, &d, &r) || fr_renderer_render(r)) {
    fprintf(stderr, "denoise_time: %s\n", fr_last_error());
    return 1;
  }
  const size_t np = (size_t)W * H;
  float *rgb = malloc(np * 10 * sizeof(float)), *out = malloc(np * 3 * sizeof(float));
  double *ms = malloc((size_t)repeat * sizeof(double));
  fr_denoiser *dn;
  if (!rgb || !out || !ms || fr_denoiser_new(W, H, &dn)) { fprintf(stderr, "denoise_time: out of memory\n"); return 1; }
  float *albedo = rgb + 3 * np, *normal = rgb + 6 * np, *depth = rgb + 9 * np;
  if (fr_renderer_image(r, 0, rgb, albedo, normal, depth)) { fprintf(stderr, "%s\n", fr_last_error()); return 1; }
  for (int k = 0; k < repeat; k++) {
    const double t0 = fr_seconds();
    fr_denoise(dn, rgb, albedo, normal, depth, 1, 2, out);
    ms[k] = (fr_seconds() - t0) * 1e3;
  }
  qsort(ms, (size_t)repeat, sizeof ms[0], cmp_double);
  printf("denoise size=%dx%d threads=2 spp=1 repeat=%d best_ms=%.2f median_ms=%.2f worst_ms=%.2f\n", W, H, repeat, ms[0],
         ms[repeat / 2], ms[repeat - 1]);
  fr_denoiser_free(dn);
  fr_renderer_release(r);
  fr_scene_release(s);
  free(rgb), free(out), free(ms);
  return 0;
}
