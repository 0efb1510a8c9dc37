/* Packets: 16 camera rays of a 4x4 pixel block traced together against the
 * built-in scene, then shadow rays from their hits as a second packet, and
 * the same rays as a stream. */
#include <math.h>
#include <stdio.h>
#include "frusta.h"

int main(void) {
  fr_scene *s;
  if (fr_scene_builtin(&s) != FR_OK || fr_scene_commit(s) != FR_OK) {
    fprintf(stderr, "frusta: %s\n", fr_last_error());
    return 1;
  }
  /* a 4x4 block of rays looking down at the floor: one lane per ray */
  fr_ray16 cam;
  for (int i = 0; i < 16; i++) {
    cam.org_x[i] = 0.0f; cam.org_y[i] = 20.0f; cam.org_z[i] = 40.0f;
    cam.dir_x[i] = -0.05f + 0.01f * (float)(i & 3);
    cam.dir_y[i] = -0.5f - 0.01f * (float)(i >> 2);
    cam.dir_z[i] = -1.0f;
    cam.tnear[i] = 0.0f;
    cam.tfar[i] = INFINITY;
  }
  fr_hit16 hit;
  fr_intersect16(s, 0xFFFF, &cam, &hit); /* all 16 lanes valid */

  /* shadow rays from the hits toward a point light; only lanes that hit */
  const float light[3] = {10.0f, 60.0f, 10.0f};
  fr_ray16 shadow;
  unsigned valid = 0;
  for (int i = 0; i < 16; i++) {
    if (hit.prim[i] == FR_INVALID_ID) continue;
    valid |= 1u << i;
    float p[3] = {cam.org_x[i] + hit.t[i] * cam.dir_x[i], cam.org_y[i] + hit.t[i] * cam.dir_y[i],
                  cam.org_z[i] + hit.t[i] * cam.dir_z[i]};
    shadow.org_x[i] = p[0]; shadow.org_y[i] = p[1]; shadow.org_z[i] = p[2];
    shadow.dir_x[i] = light[0] - p[0]; shadow.dir_y[i] = light[1] - p[1]; shadow.dir_z[i] = light[2] - p[2];
    shadow.tnear[i] = 1e-3f;
    shadow.tfar[i] = 1.0f; /* the light is at t = 1 */
  }
  unsigned occluded = fr_occluded16(s, valid, &shadow);

  /* the same camera rays as a stream: frusta packs them into packets itself */
  fr_ray rays[16];
  fr_hit hits[16];
  for (int i = 0; i < 16; i++)
    rays[i] = (fr_ray){{cam.org_x[i], cam.org_y[i], cam.org_z[i]}, 0.0f, {cam.dir_x[i], cam.dir_y[i], cam.dir_z[i]}, INFINITY};
  fr_intersect_stream(s, rays, hits, 16);

  int same = 1;
  for (int i = 0; i < 16; i++) {
    printf("ray %2d: prim %6u t %8.4f %s\n", i, hit.prim[i], hit.t[i],
           hit.prim[i] == FR_INVALID_ID ? "" : ((occluded >> i) & 1) ? "in shadow" : "lit");
    same &= hits[i].t == hit.t[i];
  }
  printf("isa=%s packet and stream agree: %s\n", fr_isa_name(fr_get_isa()), same ? "yes" : "no");
  fr_scene_release(s);
  return same && valid ? 0 : 1;
}
