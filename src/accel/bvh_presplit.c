#include "bvh_presplit.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"

#define MAX_PIECES 64 /* references per triangle */
#define MAX_DEPTH 48  /* cuts that leave one side empty use up no pieces: this bounds them */

static float tri_area(vec3 a, vec3 b, vec3 c) { return 0.5f * v3_len(v3_cross(v3_sub(b, a), v3_sub(c, a))); }

/* What splitting can win: the box's area beyond that of the tightest box a
 * triangle of this area can have (an axis-aligned right triangle's, twice
 * its area), counted for boxes more than FR_PRESPLIT_RATIO times that. */
static float excess(aabb b, float area) {
  float h = aabb_half_area(b);
  return h > FR_PRESPLIT_RATIO * 2.0f * area ? h - 2.0f * area : 0.0f;
}

static int box_empty(aabb b) { return !(b.lo.x <= b.hi.x && b.lo.y <= b.hi.y && b.lo.z <= b.hi.z); }

static aabb box_clamp(aabb b, aabb to) { return (aabb){v3_max(b.lo, to.lo), v3_min(b.hi, to.hi)}; }

/* The cut through b across its longest axis: on the coarsest plane of a
 * power-of-two grid over the scene that passes inside b (so that the pieces
 * line up with the build's own top-level splits, as Embree's presplits do),
 * else through the middle. Returns 0 when b is too thin to cut. */
static int cut_plane(aabb b, aabb scene, int *axis, float *plane) {
  vec3 ext = v3_sub(b.hi, b.lo);
  int a = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
  float lo = v3_get(b.lo, a), hi = v3_get(b.hi, a);
  double s0 = v3_get(scene.lo, a), se = (double)v3_get(scene.hi, a) - s0;
  *axis = a;
  for (int l = 1; l <= 24 && se > 0.0; l++) {
    double cell = se / (double)(1u << l);
    float p = (float)(s0 + ceil(((double)lo - s0) / cell) * cell);
    if (p > lo && p < hi) { *plane = p; return 1; }
  }
  float mid = 0.5f * lo + 0.5f * hi;
  if (mid > lo && mid < hi) { *plane = mid; return 1; }
  return 0;
}

/* Grows b by the point p + t (q - p) (t in (0, 1)), whose coordinate on
 * axis a is the plane: computed in double, rounded outward on the others. */
static aabb grow_crossing(aabb b, vec3 p, vec3 q, int a, float plane) {
  double pa = v3_get(p, a), qa = v3_get(q, a), t = ((double)plane - pa) / (qa - pa);
  float lo[3], hi[3];
  for (int k = 0; k < 3; k++) {
    if (k == a) { lo[k] = hi[k] = plane; continue; }
    double x = (double)v3_get(p, k) + t * ((double)v3_get(q, k) - (double)v3_get(p, k));
    float f = (float)x;
    lo[k] = nextafterf(f, -INFINITY);
    hi[k] = nextafterf(f, INFINITY);
  }
  return aabb_merge(b, (aabb){v3(lo[0], lo[1], lo[2]), v3(hi[0], hi[1], hi[2])});
}

/* The bounds of the triangle's part on each side of the plane, within b. */
static void cut(const vec3 v[3], aabb b, int a, float plane, aabb *left, aabb *right) {
  aabb L = aabb_empty(), R = aabb_empty();
  for (int i = 0; i < 3; i++) {
    vec3 p = v[i], q = v[(i + 1) % 3];
    float pc = v3_get(p, a), qc = v3_get(q, a);
    if (pc <= plane) L = aabb_grow(L, p);
    if (pc >= plane) R = aabb_grow(R, p);
    if ((pc < plane && qc > plane) || (pc > plane && qc < plane)) {
      L = grow_crossing(L, p, q, a, plane);
      R = grow_crossing(R, p, q, a, plane);
    }
  }
  *left = box_clamp(L, b);
  *right = box_clamp(R, b);
}

typedef struct out_refs { aabb *boxes; uint32_t *ids; size_t n; } out_refs;

/* Cuts the triangle's part in b into about k pieces, appending their boxes. */
static void split(const vec3 v[3], uint32_t id, aabb b, int k, aabb scene, int depth, out_refs *o) {
  int a;
  float plane;
  if (k <= 1 || depth >= MAX_DEPTH || !cut_plane(b, scene, &a, &plane)) {
    o->boxes[o->n] = b;
    o->ids[o->n++] = id;
    return;
  }
  aabb L, R;
  cut(v, b, a, plane, &L, &R);
  if (box_empty(L)) { split(v, id, R, k, scene, depth + 1, o); return; }
  if (box_empty(R)) { split(v, id, L, k, scene, depth + 1, o); return; }
  float al = aabb_half_area(L), ar = aabb_half_area(R);
  int kl = al + ar > 0.0f ? (int)lrintf((float)k * al / (al + ar)) : k / 2;
  kl = kl < 1 ? 1 : kl > k - 1 ? k - 1 : kl;
  split(v, id, L, kl, scene, depth + 1, o);
  split(v, id, R, k - kl, scene, depth + 1, o);
}

fr_error fr_presplit(const fr_mesh *m, aabb scene, float budget, double min_share, aabb **boxes, uint32_t **ids,
                     size_t *n) {
  const size_t count = *n;
  if (budget <= 0.0f || count == 0) return FR_OK;
  const size_t extra = (size_t)((double)budget * (double)count);
  float *ex = malloc(fr_mul_size(count, sizeof(float)));
  int *np = malloc(fr_mul_size(count, sizeof(int))); /* the pieces of each triangle: at most, then exactly */
  if (!ex || !np) {
    free(ex); free(np);
    return fr_fail(FR_ERR_NOMEM, "presplit: out of memory for %zu triangles", count);
  }
  double total = 0.0, box_area = 0.0;
  for (size_t i = 0; i < count; i++) {
    const uint32_t *ix = m->idx + 3 * (size_t)(*ids)[i];
    vec3 a = v3_load(m->pos + 3 * (size_t)ix[0]), b = v3_load(m->pos + 3 * (size_t)ix[1]), c = v3_load(m->pos + 3 * (size_t)ix[2]);
    float ar = tri_area(a, b, c);
    ex[i] = excess((*boxes)[i], ar);
    float ratio = ar > 0.0f ? aabb_half_area((*boxes)[i]) / (2.0f * ar) : (float)MAX_PIECES;
    /* pieces beyond box area / (ratio x the ideal) would cut a part that fits its box */
    np[i] = ratio / FR_PRESPLIT_RATIO >= MAX_PIECES ? MAX_PIECES : (int)ceilf(ratio / FR_PRESPLIT_RATIO);
    if (np[i] < 1) np[i] = 1;
    total += ex[i];
    box_area += aabb_half_area((*boxes)[i]);
  }
  if (total <= 0.0 || total < min_share * box_area) { free(ex); free(np); return FR_OK; }
  /* pieces in proportion to the excess, rounded down (at most count + extra
   * in all) */
  const double per = (double)extra / total;
  size_t pieces = 0;
  for (size_t i = 0; i < count; i++) {
    double want = (double)ex[i] * per;
    int k = 1 + (want >= MAX_PIECES - 1 ? MAX_PIECES - 1 : (int)want);
    np[i] = k < np[i] ? k : np[i];
    pieces += (size_t)np[i];
  }
  out_refs o = {fr_alloc_aligned(fr_mul_size(pieces, sizeof(aabb)), 64),
               fr_alloc_aligned(fr_mul_size(pieces, sizeof(uint32_t)), 64), 0};
  if (!o.boxes || !o.ids) {
    free(ex); free(np); fr_free_aligned(o.boxes); fr_free_aligned(o.ids);
    return fr_fail(FR_ERR_NOMEM, "presplit: out of memory for %zu references", pieces);
  }
  for (size_t i = 0; i < count; i++) {
    const uint32_t id = (*ids)[i];
    if (np[i] == 1) {
      o.boxes[o.n] = (*boxes)[i];
      o.ids[o.n++] = id;
      continue;
    }
    const uint32_t *ix = m->idx + 3 * (size_t)id;
    vec3 v[3] = {v3_load(m->pos + 3 * (size_t)ix[0]), v3_load(m->pos + 3 * (size_t)ix[1]), v3_load(m->pos + 3 * (size_t)ix[2])};
    split(v, id, (*boxes)[i], np[i], scene, 0, &o);
  }
  free(ex);
  free(np);
  fr_free_aligned(*boxes);
  fr_free_aligned(*ids);
  *boxes = o.boxes;
  *ids = o.ids;
  *n = o.n;
  return FR_OK;
}
