/* Inside or outside a closed mesh by counting crossings (fr_intersect_all):
 * odd from inside. Each triangle counts once even where the ray passes
 * exactly through an edge or a corner the triangles share. */
#include <math.h>
#include <stdio.h>
#include "frusta.h"

int main(void) {
  /* a unit cube, 12 triangles wound outwards */
  const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
  const uint32_t idx[] = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                          2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  fr_scene *s;
  if (fr_scene_from_arrays(xyz, 8, idx, 12, &s) != FR_OK || fr_scene_commit(s) != FR_OK) {
    fprintf(stderr, "frusta: %s\n", fr_last_error());
    return 1;
  }
  /* from each point towards the cube's far corner (1, 1, 1): through the
     corner itself, along the shared diagonals of faces, and inside */
  const float points[][3] = {{0.5f, 0.5f, 0.5f}, {0.25f, 0.25f, 0.25f}, {-1, -1, -1}, {-1, 0.5f, 0.5f}, {2, 2, 2}};
  const int inside[] = {1, 1, 0, 0, 0};
  fr_ray rays[5];
  for (int i = 0; i < 5; i++) {
    fr_ray r = {{points[i][0], points[i][1], points[i][2]}, 0.0f,
                {1.0f - points[i][0], 1.0f - points[i][1], 1.0f - points[i][2]}, INFINITY};
    if (i == 4) r.dir[0] = r.dir[1] = r.dir[2] = 1.0f; /* away from the cube */
    rays[i] = r;
  }
  fr_hit hits[5 * 4];
  uint32_t counts[5];
  if (fr_intersect_all(s, rays, 5, hits, 4, counts) != FR_OK) {
    fprintf(stderr, "frusta: %s\n", fr_last_error());
    return 1;
  }
  int wrong = 0;
  for (int i = 0; i < 5; i++) {
    printf("point (%g %g %g): %u crossing%s, %s\n", points[i][0], points[i][1], points[i][2], counts[i],
           counts[i] == 1 ? "" : "s", counts[i] % 2 ? "inside" : "outside");
    wrong += (int)(counts[i] % 2) != inside[i];
  }
  fr_scene_release(s);
  return wrong ? 1 : 0;
}
