/* frusta's renderers from a program: the built-in scene, path traced, and
 * saved (PNG, EXR or PFM by the first argument's extension, if given) as
 * display values. */
#include <stdio.h>
#include <stdlib.h>
#include "frusta.h"

int main(int argc, char **argv) {
  fr_scene *s;
  if (fr_scene_builtin(&s) != FR_OK || fr_scene_smooth(s, 30.0f) != FR_OK || fr_scene_commit(s) != FR_OK) {
    fprintf(stderr, "frusta: %s\n", fr_last_error());
    return 1;
  }
  enum { W = 160, H = 120 };
  fr_render_desc d;
  fr_render_desc_default(&d); /* then what differs: the size, the shade, the samples */
  d.camera.width = W, d.camera.height = H;
  d.shade = FR_RENDER_PATH;
  d.spp = 8;
  fr_renderer *r;
  float *rgb = malloc(sizeof(float) * W * H * 3);
  if (!rgb || fr_renderer_new(s, &d, &r) != FR_OK) {
    fprintf(stderr, "frusta: %s\n", rgb ? fr_last_error() : "out of memory");
    return 1;
  }
  int done = 0, passes = 0;
  while (!done && fr_renderer_pass(r, &done) == FR_OK) passes++;
  fr_renderer_image(r, 1, rgb, NULL, NULL, NULL); /* display values in [0, 1) */
  double mean = 0.0;
  for (int i = 0; i < W * H * 3; i++) mean += rgb[i] / (W * H * 3);
  printf("path traced %dx%d, %d spp in %d passes, mean %.3f\n", W, H, fr_renderer_spp(r), passes, mean);
  const int saved = argc < 2 || fr_image_save(argv[1], W, H, rgb) == FR_OK;
  if (!saved) fprintf(stderr, "frusta: %s\n", fr_last_error());
  fr_renderer_release(r);
  fr_scene_release(s);
  free(rgb);
  return saved && mean > 0.05 ? 0 : 1;
}
