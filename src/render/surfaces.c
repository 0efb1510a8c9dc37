#include "render/surfaces.h"
#include <stdlib.h>
#include "base/alloc.h"
#include "base/error.h"

int32_t fr_surface_material(const fr_scene *s, uint32_t prim, int32_t none) {
  const uint32_t i = fr_scene_prim_material(s, prim);
  return i == FR_INVALID_ID || i >= (uint32_t)none ? none : (int32_t)i;
}

fr_error fr_surfaces_build(const fr_scene *s, int32_t none, fr_surface **out, size_t *n) {
  const size_t nt = fr_scene_triangle_count(s);
  fr_surface *r = malloc(fr_mul_size(nt ? nt : 1, sizeof *r));
  if (!r) return fr_fail(FR_ERR_NOMEM, "out of memory for %zu triangles", nt);
  const float none_p[3] = {0, 0, 0}; /* the point matters for spheres only */
  for (size_t t = 0; t < nt; t++) {
    fr_scene_geometric_normal(s, (uint32_t)t, none_p, r[t].ng);
    r[t].mat = fr_surface_material(s, (uint32_t)t, none);
  }
  *out = r;
  *n = nt;
  return FR_OK;
}
