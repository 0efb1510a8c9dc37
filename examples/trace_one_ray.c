/* The smallest frusta program: one triangle, one ray. */
#include <math.h>
#include <stdio.h>
#include "frusta.h"

int main(void) {
  const float xyz[] = {-1, -1, 0, 1, -1, 0, 0, 1, 0};
  const uint32_t idx[] = {0, 1, 2};
  fr_scene *s;
  if (fr_scene_from_arrays(xyz, 3, idx, 1, &s) != FR_OK || fr_scene_commit(s) != FR_OK) {
    fprintf(stderr, "frusta: %s\n", fr_last_error());
    return 1;
  }
  fr_ray ray = {{0, 0, -5}, 0.0f, {0, 0, 1}, INFINITY};
  fr_hit hit;
  fr_intersect1(s, &ray, &hit);
  printf("isa=%s hit prim=%u t=%g u=%g v=%g\n", fr_isa_name(fr_get_isa()), hit.prim, hit.t, hit.u, hit.v);
  fr_scene_release(s);
  return hit.prim == 0 ? 0 : 1;
}
