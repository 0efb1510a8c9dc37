/*
 * The path tracer's camera rays, lane by lane (render/path_camera.h),
 * compiled once per ISA: component arrays and selects, which the compiler
 * turns into vector code; the ray records are written at the end.
 */
#include <math.h>
#include "base/simd.h"
#include "base/trig.h"
#include "render/path_camera.h"

enum { LANES = 64 };

static void camera_chunk(const fr_path_camera *restrict c, size_t m, const float *restrict x,
                         const float *restrict y, const float *restrict jx, const float *restrict jy,
                         const float *restrict lx, const float *restrict ly, fr_ray *restrict rays) {
  float ox[LANES], oy[LANES], oz[LANES], dx[LANES], dy[LANES], dz[LANES];
  const fr_path_camera k = *c; /* a copy the loops see is not written */
  for (size_t j = 0; j < m; j++) {
    const float sx = 2.0f * (x[j] + jx[j]) / k.width - 1.0f, sy = 1.0f - 2.0f * (y[j] + jy[j]) / k.height;
    dx[j] = k.fwd[0] + (k.right[0] * sx + k.up[0] * sy);
    dy[j] = k.fwd[1] + (k.right[1] * sx + k.up[1] * sy);
    dz[j] = k.fwd[2] + (k.right[2] * sx + k.up[2] * sy);
    ox[j] = k.eye[0], oy[j] = k.eye[1], oz[j] = k.eye[2];
  }
  if (k.aperture > 0.0f)
    for (size_t j = 0; j < m; j++) {
      float sn, cs;
      fr_sincos_turns(ly[j], &sn, &cs);
      const float r = k.aperture * sqrtf(lx[j]), a = r * cs, b = r * sn;
      /* the point in focus: the image plane lies at distance 1 along fwd */
      const float fx = k.eye[0] + dx[j] * k.focus, fy = k.eye[1] + dy[j] * k.focus, fz = k.eye[2] + dz[j] * k.focus;
      ox[j] = k.eye[0] + (k.ru[0] * a + k.uu[0] * b);
      oy[j] = k.eye[1] + (k.ru[1] * a + k.uu[1] * b);
      oz[j] = k.eye[2] + (k.ru[2] * a + k.uu[2] * b);
      dx[j] = fx - ox[j], dy[j] = fy - oy[j], dz[j] = fz - oz[j];
    }
  for (size_t j = 0; j < m; j++) { /* v3_norm */
    const float l = sqrtf(dx[j] * dx[j] + dy[j] * dy[j] + dz[j] * dz[j]), il = 1.0f / l;
    dx[j] = l > 0.0f ? dx[j] * il : dx[j];
    dy[j] = l > 0.0f ? dy[j] * il : dy[j];
    dz[j] = l > 0.0f ? dz[j] * il : dz[j];
  }
  for (size_t j = 0; j < m; j++)
    rays[j] = (fr_ray){{ox[j], oy[j], oz[j]}, 0.0f, {dx[j], dy[j], dz[j]}, INFINITY};
}

void FR_ISA_FN(fr_path_camera_rays)(const fr_path_camera *c, size_t m, const float *x, const float *y,
                                     const float *jx, const float *jy, const float *lx, const float *ly,
                                     fr_ray *rays) {
  for (size_t a = 0; a < m; a += LANES) {
    const size_t n = m - a < LANES ? m - a : LANES;
    camera_chunk(c, n, x + a, y + a, jx + a, jy + a, lx ? lx + a : NULL, ly ? ly + a : NULL, rays + a);
  }
}
