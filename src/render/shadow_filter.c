#include "shadow_filter.h"
#include <math.h>
#include <stddef.h>

#define DEPTH_TOL 0.05f  /* relative depth difference still "the same surface" */
#define NORMAL_TOL 0.9f  /* cosine between normals still "the same surface" */

void fr_filter_visibility(const float *vis, const float *depth, const float *normal, int w, int h, float *out) {
#pragma omp parallel for schedule(static)
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      size_t i = (size_t)y * (size_t)w + (size_t)x;
      float d = depth[i];
      if (!(d < INFINITY)) { out[i] = vis[i]; continue; }
      const float *n = normal + 3 * i;
      float sum = 0.0f, cnt = 0.0f;
      /* offsets -2..1: every 4x4 window holds each (x mod 4, y mod 4) once */
      for (int dy = -2; dy <= 1; dy++)
        for (int dx = -2; dx <= 1; dx++) {
          int X = x + dx, Y = y + dy;
          if (X < 0 || Y < 0 || X >= w || Y >= h) continue;
          size_t j = (size_t)Y * (size_t)w + (size_t)X;
          const float *m = normal + 3 * j;
          if (!(fabsf(depth[j] - d) <= DEPTH_TOL * d) || n[0] * m[0] + n[1] * m[1] + n[2] * m[2] < NORMAL_TOL) continue;
          sum += vis[j];
          cnt += 1.0f;
        }
      out[i] = sum / cnt; /* the pixel itself always counts */
    }
}
