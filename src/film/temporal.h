/*
 * Temporal reprojection of a progressive image while the camera moves (as
 * SVGF does): the last frame shown is carried to the new view through its
 * first hits (each pixel's hit point seen from the new camera, or its
 * direction where the camera saw the background) and blended with the new
 * frame, where the hit is the same surface (distance within
 * FR_TEMPORAL_DEPTH_TOL, normals within FR_TEMPORAL_NORMAL_COS, the earlier
 * point on the tangent plane within FR_TEMPORAL_PLANE_TOL); elsewhere
 * (newly seen surfaces, the image's edges) the new frame alone is shown.
 *
 * Weights count passes: a frame of k passes since the camera last moved
 * meets a history worth up to FR_TEMPORAL_HISTORY passes, so while the
 * camera moves each frame's weight is 1/5. While the camera rests the
 * history fades out over FR_TEMPORAL_FADE passes, after which the image
 * is the progressive one exactly.
 */
#ifndef FR_FILM_TEMPORAL_H
#define FR_FILM_TEMPORAL_H
#include "frusta.h"
#include "render/camera.h"

#define FR_TEMPORAL_HISTORY 4
#define FR_TEMPORAL_FADE 32
#define FR_TEMPORAL_DEPTH_TOL 0.05f /* relative */
#define FR_TEMPORAL_NORMAL_COS 0.9f
#define FR_TEMPORAL_PLANE_TOL 0.01f /* off the tangent plane, relative to the distance */

typedef struct fr_temporal fr_temporal;

/* For width x height images; FR_ERR_ARG for a bad size, FR_ERR_NOMEM
 * without memory. One caller at a time. */
fr_error fr_temporal_new(int width, int height, fr_temporal **t);
void fr_temporal_free(fr_temporal *t);
/* Forgets every frame (the image shows something else now). */
void fr_temporal_reset(fr_temporal *t);

/* rgb (W*H*3, linear; replaced by the blend) is cam's image after passes
 * passes (>= 1) since the camera last moved, with its first hits' depth
 * (W*H, FR_DEPTH_MISS where none) and normal (W*H*3). Remembers the
 * result as the history of the next frame. Runs on threads threads. */
void fr_temporal_apply(fr_temporal *t, const fr_camera *cam, int passes, const float *depth, const float *normal,
                       float *rgb, int threads);

/* The share of the last frame's pixels that took a history (0..1). */
float fr_temporal_reused(const fr_temporal *t);
/* The last frame's history weight over its own, averaged over the pixels:
 * the blend holds about (1 + this) times the frame's samples. */
float fr_temporal_worth(const fr_temporal *t);
#endif
