/*
 * A tile's shaft: the leaves of a binary tree that some segment from a box
 * of origins P to a box of end points Q may reach (see fr_mft_shaft in
 * mft.h). The points of the segments p + t (q - p), t in [0, 1], for p in P
 * and q in Q form at each t exactly the box (1 - t) P + t Q, whose bounds
 * are linear in t, so whether a node's box meets the shaft is whether one
 * interval of t survives six half-line constraints: an exact test for the
 * two boxes, like a ray's slab test with reciprocals made once per tile,
 * in float on boxes padded far beyond its rounding.
 */
#include <math.h>
#include "accel/plane_occluders.h"
#include "trace/counters.h"
#include "trace/mft/mft.h"

/* The shaft as six planes of t: per axis, its low side plo + t dl and its
 * high side phi + t dh, with 1 / dl and 1 / dh made once (a side that does
 * not move gets a tiny slope of its sign, as a ray's zero direction does:
 * then the test reads whether the side already passed the box). */
typedef struct shaft_planes { float plo[3], phi[3], il[3], ih[3]; } shaft_planes;

/* comparisons, not fminf: a call into libm without -ffast-math (the first
 * build spent 9% of kitchen's soft16 time there) */
static inline float min2(float a, float b) { return a < b ? a : b; }
static inline float max2(float a, float b) { return a > b ? a : b; }

/* Whether box [lo, hi] meets the segments, t in [0, 1]. */
static inline int shaft_meets(const shaft_planes *S, const float lo[3], const float hi[3]) {
  float t0 = 0.0f, t1 = 1.0f;
  for (int a = 0; a < 3; a++) {
    /* the low side must not pass the box's high side, the high side reach its low side */
    const float ul = (hi[a] - S->plo[a]) * S->il[a], uh = (lo[a] - S->phi[a]) * S->ih[a];
    if (S->il[a] > 0.0f) t1 = min2(t1, ul); else t0 = max2(t0, ul);
    if (S->ih[a] > 0.0f) t0 = max2(t0, uh); else t1 = min2(t1, uh);
  }
  return t0 <= t1;
}

/* The shaft of the padded boxes on tree b. Pad both boxes far beyond the
 * rounding of the rays' directions (made in float from the light's corner
 * and edges) and of this test: by 1e-4 of the scene's size and position. */
static void shaft_setup(const fr_bvh2 *b, const float plo[3], const float phi[3], const float qlo[3], const float qhi[3],
                        shaft_planes *S) {
  const float *blo = &b->bounds.lo.x, *bhi = &b->bounds.hi.x;
  float size = 0.0f;
  for (int a = 0; a < 3; a++) size = max2(size, max2(max2(fabsf(blo[a]), fabsf(bhi[a])), bhi[a] - blo[a]));
  const float pad = 1e-4f * size, tiny = 1e-30f;
  for (int a = 0; a < 3; a++) {
    S->plo[a] = plo[a] - pad;
    S->phi[a] = phi[a] + pad;
    float dl = (qlo[a] - pad) - S->plo[a], dh = (qhi[a] + pad) - S->phi[a];
    if (fabsf(dl) < tiny) dl = copysignf(tiny, dl);
    if (fabsf(dh) < tiny) dh = copysignf(tiny, dh);
    S->il[a] = 1.0f / dl;
    S->ih[a] = 1.0f / dh;
  }
}

/* The planar occluders whose polygon's box the shaft meets: a ray one
 * claims crosses the polygon, so the others can claim none. */
static uint32_t shaft_planes_met(const fr_bvh2 *b, const shaft_planes *S) {
  uint32_t m = 0;
  for (size_t i = 0; b->planes && i < b->planes->n && i < 32; i++) {
    const fr_plane_occluder *p = &b->planes->list[i];
    const int a = p->axis, u = (a + 1) % 3, v = (a + 2) % 3;
    float lo[3], hi[3];
    lo[a] = hi[a] = p->c;
    lo[u] = p->lo[0]; hi[u] = p->hi[0];
    lo[v] = p->lo[1]; hi[v] = p->hi[1];
    if (shaft_meets(S, lo, hi)) m |= 1u << i;
  }
  return m;
}

uint32_t fr_mft_shaft_planes_off(const fr_bvh2 *b, const float plo[3], const float phi[3], const float qlo[3],
                                 const float qhi[3]) {
  if (!b->planes || !b->planes->n) return 0;
  shaft_planes S;
  shaft_setup(b, plo, phi, qlo, qhi, &S);
  return ~shaft_planes_met(b, &S);
}

int fr_mft_shaft_build(const fr_bvh2 *b, const float plo[3], const float phi[3], const float qlo[3],
                       const float qhi[3], fr_mft_shaft *s) {
  s->n = 0;
  if (!b->nodes || (b->root & FR_BVH2_LEAF)) return 0;
  shaft_planes S;
  shaft_setup(b, plo, phi, qlo, qhi, &S);
  uint32_t stack[FR_MFT_SHAFT_STACK];
  int sp = 0, visits = 0;
  stack[sp++] = b->root;
  while (sp) {
    const uint32_t node = stack[--sp];
    const fr_bvh2_node *n = &b->nodes[node];
    if (++visits > FR_MFT_SHAFT_VISITS) return 0;
    FR_COUNT(mft_shaft_box_tests, 2);
    for (int k = 1; k >= 0; k--) { /* child 0 popped first */
      const float lo[3] = {n->lo_x[k], n->lo_y[k], n->lo_z[k]}, hi[3] = {n->hi_x[k], n->hi_y[k], n->hi_z[k]};
      if (!shaft_meets(&S, lo, hi)) continue;
      const uint32_t c = n->child[k];
      if (!(c & FR_BVH2_LEAF)) {
        if (sp == FR_MFT_SHAFT_STACK) return 0;
        stack[sp++] = c;
        continue;
      }
      if (FR_BVH2_LEAF_COUNT(c) == 0) continue;
      if (s->n == FR_MFT_SHAFT_MAX) return 0;
      s->leaf[s->n++] = node << 1 | (uint32_t)k;
    }
  }
  return 1;
}
