/* Pinhole camera of workloads.md: vertical field of view, image plane at
 * distance 1, rays through pixel centres, normalized directions. */
#ifndef FR_RENDER_CAMERA_H
#define FR_RENDER_CAMERA_H
#include "base/vec3.h"
#include "frusta.h"

typedef struct fr_camera {
  vec3 eye, right, up, fwd; /* right and up scaled to the image plane's half extents */
  int width, height;
} fr_camera;

/* FR_ERR_ARG for a zero-size image, a degenerate basis or a bad fov. */
fr_error fr_camera_setup(fr_camera *c, vec3 eye, vec3 at, vec3 up, float fov_deg, int width, int height);

static inline fr_ray fr_camera_ray(const fr_camera *c, int x, int y) {
  float sx = 2.0f * ((float)x + 0.5f) / (float)c->width - 1.0f;
  float sy = 1.0f - 2.0f * ((float)y + 0.5f) / (float)c->height;
  vec3 d = v3_norm(v3_add(c->fwd, v3_add(v3_scale(c->right, sx), v3_scale(c->up, sy))));
  fr_ray r = {{c->eye.x, c->eye.y, c->eye.z}, 0.0f, {d.x, d.y, d.z}, __builtin_inff()};
  return r;
}
#endif
