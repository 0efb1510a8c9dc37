/* fr_intersect_all: every triangle along each ray, in order of t, through
 * the one exact kernel of trace/all_hits.h whatever the trace mode. */
#include <stdlib.h>
#include "base/error.h"
#include "scene.h"
#include "trace/all_hits.h"
#include "trace/kernels.h"

static void to_hit(const fr_scene *s, const fr_crossing *x, fr_hit *h) {
  h->t = x->t;
  h->u = x->u;
  h->v = x->v;
  h->prim = x->prim;
  fr_scene_triangle_normal(s, x->prim, h->ng);
}

fr_error fr_intersect_all(const fr_scene *s, const fr_ray *rays, size_t n, fr_hit *hits, size_t max_hits,
                          uint32_t *counts) {
  if (!s || (n && (!rays || !counts || (max_hits && !hits))))
    return fr_fail(FR_ERR_ARG, "fr_intersect_all: NULL scene, rays, counts or hits");
  if (!s->committed) return fr_fail(FR_ERR_STATE, "fr_intersect_all: the scene is not committed");
  if (s->sphere_bvh.nprims) return fr_fail(FR_ERR_UNSUPPORTED, "fr_intersect_all: scenes with spheres are not supported");
  if (max_hits && n > SIZE_MAX / max_hits) return fr_fail(FR_ERR_ARG, "fr_intersect_all: n * max_hits overflows");
  fr_crossings c = {0};
  for (size_t i = 0; i < n; i++) {
    fr_error e = fr_bvh2_all_hits(&s->bvh2, &s->mesh, &rays[i], &c);
    if (e != FR_OK) { fr_crossings_free(&c); return e; }
    counts[i] = c.n > UINT32_MAX ? UINT32_MAX : (uint32_t)c.n;
    fr_hit *h = hits + i * max_hits;
    for (size_t j = 0; j < max_hits; j++) {
      if (j < c.n) to_hit(s, &c.items[j], &h[j]);
      else fr_hit_miss(&h[j]);
    }
  }
  fr_crossings_free(&c);
  return FR_OK;
}
