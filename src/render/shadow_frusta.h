/* Point-light shadow rays by multi-frusta: rays from the light, 16
 * consecutive ones a frustum, 256 a batch (fr_mft_fns.from_rays); for the
 * Whitted renderer and fr_occluded_point_light. */
#ifndef FR_RENDER_SHADOW_FRUSTA_H
#define FR_RENDER_SHADOW_FRUSTA_H
#include <stddef.h>
#include <stdint.h>
#include "render/tracer.h"

/* Shadow rays from a point light: rays[i], or (rays NULL) the segments
 * from light to points[i] (3 floats each) that fr_mft_fns.rays_to_points
 * makes, made as rays only where they are traced as rays. */
typedef struct fr_shadow_rays {
  const fr_ray *rays;
  const float *light, *points;
  float eps;
} fr_shadow_rays;

/* occ[i] = whether anything lies on shadow ray i of src in its range; t
 * must be a multi-frusta tracer. budgeted: a batch whose frusta visit too
 * many nodes sends the rest to t's streams (0: every batch goes as frusta,
 * for measurements). */
void fr_shadow_frusta_occluded(const fr_tracer *t, const fr_shadow_rays *src, uint8_t *occ, size_t n, int budgeted);
#endif
