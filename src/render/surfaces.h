/*
 * What a hit on a triangle needs for shading, in one 16-byte record per
 * triangle: its geometric normal (v1 - v0) x (v2 - v0), not unit, and its
 * material index. Read straight from the mesh, a hit costs two dependent
 * loads and three vertex lines; the renderers (Whitted, path) read these.
 */
#ifndef FR_RENDER_SURFACES_H
#define FR_RENDER_SURFACES_H
#include <stddef.h>
#include <stdint.h>
#include "frusta.h"

typedef struct fr_surface {
  float ng[3];
  int32_t mat;
} fr_surface;

/* One record per scene triangle; a triangle without a material, or with
 * one at or past `none`, gets `none`. *out is malloc'd. */
fr_error fr_surfaces_build(const fr_scene *s, int32_t none, fr_surface **out, size_t *n);
/* The material index of any prim (triangle or sphere), as the records have it. */
int32_t fr_surface_material(const fr_scene *s, uint32_t prim, int32_t none);
#endif
