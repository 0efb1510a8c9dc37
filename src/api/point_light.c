/* fr_occluded_point_light: shadow rays from a point light to many points,
 * traced as multi-frusta (render/shadow_frusta.h) in runs of RUN points,
 * each run deciding for itself whether its frusta pay (as a Whitted tile
 * does). */
#include <math.h>
#include "base/error.h"
#include "render/shadow_frusta.h"
#include "render/tracer.h"
#include "scene.h"

#define RUN 1024

fr_error fr_occluded_point_light(const fr_scene *s, const float light[3], const float *points, size_t n, float eps,
                                 uint8_t *occluded) {
  if (!s || !light || (n && (!points || !occluded)))
    return fr_fail(FR_ERR_ARG, "fr_occluded_point_light: NULL scene, light, points or answers");
  if (!s->committed) return fr_fail(FR_ERR_STATE, "fr_occluded_point_light: the scene is not committed");
  if (!(eps >= 0.0f) || !isfinite(light[0]) || !isfinite(light[1]) || !isfinite(light[2]))
    return fr_fail(FR_ERR_ARG, "fr_occluded_point_light: the light or eps is not finite and non-negative");
  const fr_mft_tracer m = fr_mft_tracer_of(s, fr_mft_opts_default());
  const fr_tracer t = s->sphere_bvh.nprims ? fr_tracer_frusta(s) : fr_tracer_mft(&m);
  fr_ray rays[RUN];
  for (size_t a = 0; a < n; a += RUN) {
    size_t k = n - a < RUN ? n - a : RUN;
    if (t.occluded_frusta) { /* the segments made as rays only where they go as rays */
      const fr_shadow_rays src = {NULL, light, points + 3 * a, eps};
      fr_shadow_frusta_occluded(&t, &src, occluded + a, k, 1);
      continue;
    }
    fr_mft_active()->rays_to_points(light, points + 3 * a, k, eps, rays);
    fr_occluded_stream(s, rays, occluded + a, k);
  }
  return FR_OK;
}
