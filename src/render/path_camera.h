/*
 * The path tracer's camera rays, a block of samples at a time, lane by lane
 * as vector code (path_camera.c, compiled once per ISA): a pixel's point
 * jittered within it, through a pinhole or a thin lens. The arithmetic is
 * the scalar camera's, operation for operation, so every ISA makes the same
 * bits.
 */
#ifndef FR_RENDER_PATH_CAMERA_H
#define FR_RENDER_PATH_CAMERA_H
#include <stddef.h>
#include "frusta.h"

/* A pinhole (aperture 0) or thin-lens camera as the lanes read it: the
 * image plane at distance 1 along fwd spans [-1, 1] by right and up; the
 * lens is a disc of radius aperture in the plane of the unit ru and uu,
 * focused at distance focus. */
typedef struct fr_path_camera {
  float eye[3], fwd[3], right[3], up[3], ru[3], uu[3];
  float width, height, aperture, focus;
} fr_path_camera;

/* rays[j] for j < m: through pixel (x[j], y[j]) at the point (jx[j], jy[j])
 * within it, leaving the lens at its sample (lx[j], ly[j]) when the
 * aperture is above 0 (lx, ly unread otherwise); unit directions, t in
 * [0, inf). One function per ISA. */
#define FR_PATH_CAMERA_FNS(isa)                                                                                  \
  void fr_path_camera_rays_##isa(const fr_path_camera *c, size_t m, const float *x, const float *y,            \
                                 const float *jx, const float *jy, const float *lx, const float *ly, fr_ray *rays);
FR_PATH_CAMERA_FNS(scalar)
FR_PATH_CAMERA_FNS(avx2)
FR_PATH_CAMERA_FNS(avx512)
#endif
