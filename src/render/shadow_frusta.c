#include "shadow_frusta.h"

/* Shadow frusta from a point light pay where they pass little geometry on
 * the way (museum: 2 inner nodes per frustum) and lose where they fan out
 * among dense geometry (hairball: over 100), where packets in the 8-wide
 * BVH take fewer, cheaper steps. Nodes per frustum vary too much over a
 * frame for a few probe tiles to tell, so each batch gets a budget of this
 * many visits per frustum, and a batch over it sends the rest of its tile's
 * shadow rays to the streams. */
#define SHADOW_FRUSTA_MAX_NODES 6u

/* Rays [first, first + n) of src: its own, or made into buf (n rays long). */
static const fr_ray *rays_of(const fr_shadow_rays *src, size_t first, size_t n, fr_ray *buf) {
  if (src->rays) return src->rays + first;
  fr_mft_active()->rays_to_points(src->light, src->points + 3 * first, n, src->eps, buf);
  return buf;
}

/* Shadow rays [0, n) of a generation through a multi-frusta tracer: 16
 * consecutive rays from the light make a frustum (the rays of a 4x4 block
 * and, past its mirrors and unlit pixels, of the next: full frusta measured
 * faster than one per block, museum 0.018 s against 0.023), 256 a batch.
 * What makes no frustum (see fr_mft_fns.from_rays) goes as rays; a batch
 * over its node budget goes as rays, and so does the rest of the
 * generation. */
void fr_shadow_frusta_occluded(const fr_tracer *t, const fr_shadow_rays *src, uint8_t *occ, size_t n, int budgeted) {
  enum { PIECE = 1024 };
  const fr_mft_fns *k = fr_mft_active();
  fr_mft_batch b;
  static _Thread_local fr_mft_sets T;
  uint16_t bits[FR_MFT_FRUSTA];
  fr_ray buf[FR_MFT_RAYS];
  const size_t per = FR_MFT_FRUSTA * FR_MFT_RAYS;
  size_t a = 0;
  while (a < n) {
    const size_t m = n - a < per ? n - a : per;
    const unsigned valid = src->rays ? k->from_rays(&b, &T, src->rays + a, m)
                                     : k->from_points(&b, &T, src->light, src->points + 3 * a, m, src->eps);
    fr_mft_budget budget = {!budgeted ? 0 : SHADOW_FRUSTA_MAX_NODES * (unsigned)__builtin_popcount(valid), 0, 0,
                            0, 0};
    /* no occluder cache: point-light frusta are thin and end at their first
     * occluder anyway (museum and kitchen whitted measured the same) */
    if (valid) t->occluded_frusta(t->ctx, &b, &T, bits, &budget, NULL);
    if (budget.stopped) break; /* these rays too */
    for (size_t f = 0; f * FR_MFT_RAYS < m; f++) {
      size_t first = a + f * FR_MFT_RAYS, cnt = m - f * FR_MFT_RAYS < FR_MFT_RAYS ? m - f * FR_MFT_RAYS : FR_MFT_RAYS;
      if (!((valid >> f) & 1)) {
        t->occluded(t->ctx, rays_of(src, first, cnt, buf), occ + first, cnt, 1);
        continue;
      }
      for (size_t j = 0; j < cnt; j++) occ[first + j] = (uint8_t)((bits[f] >> j) & 1);
    }
    a += m;
  }
  /* the rest in one call, or made a piece at a time */
  fr_ray piece[PIECE];
  for (size_t m; a < n; a += m) {
    m = src->rays || n - a < PIECE ? n - a : PIECE;
    t->occluded(t->ctx, rays_of(src, a, m, piece), occ + a, m, 1);
  }
}
