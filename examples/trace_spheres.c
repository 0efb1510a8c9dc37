/* Analytic spheres: a scene of spheres only, a material, one ray. */
#include <math.h>
#include <stdio.h>
#include "frusta.h"

int main(void) {
  fr_scene *s;
  uint32_t red;
  fr_material m = {.name = "red", .diffuse = {1, 0, 0}};
  if (fr_scene_new(&s) != FR_OK || fr_scene_add_material(s, &m, &red) != FR_OK ||
      fr_scene_add_sphere(s, (float[3]){0, 0, 0}, 1.0f, red) != FR_OK ||
      fr_scene_add_sphere(s, (float[3]){0, 0, 4}, 0.5f, FR_INVALID_ID) != FR_OK || fr_scene_commit(s) != FR_OK) {
    fprintf(stderr, "frusta: %s\n", fr_last_error());
    return 1;
  }
  fr_ray ray = {{0, 0, -5}, 0.0f, {0, 0, 1}, INFINITY};
  fr_hit hit;
  fr_intersect1(s, &ray, &hit);
  /* sphere i is prim triangle_count + i; ng points out of the sphere */
  float p[3] = {0, 0, -5 + hit.t}, n[3];
  fr_scene_geometric_normal(s, hit.prim, p, n);
  uint32_t mat = fr_scene_prim_material(s, hit.prim);
  printf("hit sphere %u t=%g normal=(%g %g %g) material=%s\n", hit.prim, hit.t, n[0], n[1], n[2],
         mat == FR_INVALID_ID ? "none" : fr_scene_material(s, mat)->name);
  int ok = hit.prim == 0 && hit.t == 4.0f && n[2] == -1.0f && mat == red;
  fr_scene_release(s);
  return ok ? 0 : 1;
}
