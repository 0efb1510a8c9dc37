#include "sphere_bvh.h"
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"

aabb fr_sphere_box(const fr_sphere *s) {
  float pad = s->r * (1.0f + 0x1p-20f);
  aabb b;
  b.lo = v3(s->c[0] - pad, s->c[1] - pad, s->c[2] - pad);
  b.hi = v3(s->c[0] + pad, s->c[1] + pad, s->c[2] + pad);
  float e[3] = {fabsf(s->c[0]) * 0x1p-20f, fabsf(s->c[1]) * 0x1p-20f, fabsf(s->c[2]) * 0x1p-20f};
  b.lo = v3(b.lo.x - e[0], b.lo.y - e[1], b.lo.z - e[2]);
  b.hi = v3(b.hi.x + e[0], b.hi.y + e[1], b.hi.z + e[2]);
  return b;
}

fr_error fr_sphere_bvh_build(const fr_spheres *set, fr_bvh2 *out) {
  memset(out, 0, sizeof *out);
  out->bounds = aabb_empty();
  if (set->n == 0) return FR_OK;
  if (set->n > FR_BVH2_FIRST_MASK) return fr_fail(FR_ERR_ARG, "%zu spheres: at most %u", set->n, FR_BVH2_FIRST_MASK);
  aabb *boxes = malloc(fr_mul_size(set->n, sizeof(aabb)));
  uint32_t *ids = malloc(fr_mul_size(set->n, sizeof(uint32_t)));
  if (!boxes || !ids) { free(boxes); free(ids); return fr_fail(FR_ERR_NOMEM, "out of memory for %zu spheres", set->n); }
  for (size_t i = 0; i < set->n; i++) {
    boxes[i] = fr_sphere_box(&set->s[i]);
    ids[i] = (uint32_t)i;
  }
  fr_build_tree tree;
  fr_error e = fr_build_sah(boxes, ids, set->n, &tree);
  free(boxes);
  free(ids);
  if (e) return e;
  e = fr_bvh2_from_build(&tree, NULL, FR_SPHERE_LEAF, out);
  fr_build_tree_free(&tree);
  if (e) return e;
  out->spheres = fr_alloc_aligned(fr_mul_size(out->nprims, sizeof(fr_sphere)), 64);
  if (!out->spheres) { fr_bvh2_free(out); return fr_fail(FR_ERR_NOMEM, "out of memory for %zu spheres", set->n); }
  for (size_t i = 0; i < out->nprims; i++) out->spheres[i] = set->s[out->prims[i]];
  return FR_OK;
}
