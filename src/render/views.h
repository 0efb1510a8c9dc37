/* Cameras and lights of the scenes in ../shared/scenes (its README's table),
 * of the built-in scene, and a fallback from a scene's bounds. */
#ifndef FR_RENDER_VIEWS_H
#define FR_RENDER_VIEWS_H
#include "base/vec3.h"

typedef struct fr_view {
  vec3 eye, at, up;
  float fov;
  vec3 light;                 /* point light */
  vec3 area_c, area_e1, area_e2; /* quad light c + s e1 + t e2 */
} fr_view;

/* 1 if name has a known view. */
int fr_view_lookup(const char *name, fr_view *v);
/* The scenes README's mirror and glass materials of a shared scene, as
 * comma-separated names (left alone for a scene without suggestions). */
void fr_view_surfaces(const char *name, const char **mirror, const char **glass);
/* Whether name is one of the comma-separated names of list (NULL: none). */
int fr_names_contain(const char *list, const char *name);
/* A 3/4 view of the box with lights above it. */
fr_view fr_view_from_bounds(aabb b);
/* A scene's own view: the known one of its name, else one of its bounds. */
fr_view fr_view_of(const char *name, aabb bounds);
#endif
