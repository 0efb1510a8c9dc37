/*
 * The discontinuity filter of multi-frusta soft shadows (Benthin & Wald §4.5):
 * each pixel averages the light visibility of the 4x4 pixels around it that
 * lie on the same surface (similar depth and normal). With 4x4 interleaved
 * sample sets, any 4x4 window holds all 16 sets, so a pixel inside a smooth
 * region gathers all 256 samples of its neighbourhood.
 */
#ifndef FR_RENDER_SHADOW_FILTER_H
#define FR_RENDER_SHADOW_FILTER_H

/* vis, depth: w*h; normal: 3*w*h (unit); depth = +inf where nothing was hit.
 * out: w*h (may not alias vis). */
void fr_filter_visibility(const float *vis, const float *depth, const float *normal, int w, int h, float *out);
#endif
