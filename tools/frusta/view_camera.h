/* The viewer's camera: orbit, pan, zoom and fly moves on eye, at and up,
 * and camera paths (text files of one view per line). */
#ifndef FR_TOOL_VIEW_CAMERA_H
#define FR_TOOL_VIEW_CAMERA_H
#include <stddef.h>
#include <stdio.h>
#include "base/vec3.h"

typedef struct view_camera {
  vec3 eye, at, up; /* up: the world's up, which orbits keep */
  float fov;        /* vertical, degrees */
} view_camera;

int view_camera_equal(const view_camera *a, const view_camera *b);
/* Turns the eye about at: yaw about up, pitch toward it (radians), never over the pole. */
void view_camera_orbit(view_camera *c, float yaw, float pitch);
/* Moves eye and at together across the view, by fractions of the distance between them. */
void view_camera_pan(view_camera *c, float right, float upward);
/* Moves the eye toward at, scaling their distance by factor. */
void view_camera_zoom(view_camera *c, float factor);
/* Moves eye and at together along the view (forward), across it (right)
 * and along up (rise), in scene units. */
void view_camera_fly(view_camera *c, float forward, float right, float rise);
/* The camera as `frusta render` flags, one line. */
void view_camera_print(FILE *out, const view_camera *c);

/* A camera path: *cams malloc'd, *n views. Lines: "ex,ey,ez ax,ay,az
 * ux,uy,uz fov"; blank lines and lines starting with # are skipped.
 * Returns 0, or 1 after reporting a one-line error (file and line). */
int view_camera_path_read(const char *path, view_camera **cams, size_t *n);
/* One line of a camera path. */
void view_camera_path_write(FILE *out, const view_camera *c);
#endif
