/* Point-light shadow rays by multi-frusta: rays from the light, 16
 * consecutive ones a frustum, 256 a batch (fr_mft_fns.from_rays); for the
 * Whitted renderer and fr_occluded_point_light. */
#ifndef FR_RENDER_SHADOW_FRUSTA_H
#define FR_RENDER_SHADOW_FRUSTA_H
#include <stddef.h>
#include <stdint.h>
#include "render/tracer.h"

/* occ[i] = whether anything lies on rays[i] in its range; t must be a
 * multi-frusta tracer. budgeted: a batch whose frusta visit too many nodes
 * sends the rest to t's streams (0: every batch goes as frusta, for
 * measurements). */
void fr_shadow_frusta_occluded(const fr_tracer *t, const fr_ray *rays, uint8_t *occ, size_t n, int budgeted);
#endif
