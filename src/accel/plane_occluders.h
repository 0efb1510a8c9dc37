/*
 * Planar occluders: convex regions of an axis plane that a scene's triangles
 * are known to cover without gaps, found once at commit. A table top
 * tessellated into 1,440 triangles of 9 cm² (BART kitchen) is one convex
 * polygon to a shadow ray: a ray that crosses it well inside, between its
 * ends, is occluded whatever triangle it would have met, so a shadow
 * frustum under the table can end without fetching any of them.
 *
 * A patch qualifies when (all checked in double, see plane_occluders.c):
 * its triangles lie exactly in one axis plane, share one orientation, meet
 * edge to edge (each inner edge used by exactly two triangles, opposite
 * ways), every edge used once lies on the boundary of the patch's convex
 * hull, and their areas add up to the hull's. Then the boundary is a cycle
 * on the hull, whose winding number is one constant inside; the areas make
 * it 1: every point of the hull's interior lies in exactly one triangle (or
 * on a shared edge, which the watertight tests give to one of its two).
 * The polygon kept is inscribed in the hull (a subset of its vertices) and
 * shrunk by a margin far above every rounding error involved, and a ray
 * counts only when it crosses the plane inside its (tnear, tfar) by a
 * margin too: such a ray's own traversal would report a hit, so answers do
 * not change.
 */
#ifndef FR_ACCEL_PLANE_OCCLUDERS_H
#define FR_ACCEL_PLANE_OCCLUDERS_H
#include <math.h>
#include <stddef.h>
#include "frusta.h"
#include "geom/mesh.h"

#define FR_PLANE_OCCLUDERS_MAX 16  /* the largest by area; more are dropped */
#define FR_PLANE_OCCLUDER_EDGES 16 /* polygon edges kept */
#define FR_PLANE_OCCLUDER_MIN_TRIS 64 /* smaller patches cost a traversal little anyway */

typedef struct fr_plane_occluder {
  int axis;     /* the plane is x[axis] == c */
  float c;
  int nedges;   /* inside: nu[i] * x[u] + nv[i] * x[v] <= e[i] for all i, u = axis + 1, v = axis + 2 (mod 3) */
  float nu[FR_PLANE_OCCLUDER_EDGES], nv[FR_PLANE_OCCLUDER_EDGES], e[FR_PLANE_OCCLUDER_EDGES];
  float lo[2], hi[2]; /* the polygon's box in (u, v) */
  double area;        /* of the polygon kept */
  size_t tris;        /* triangles in the patch */
} fr_plane_occluder;

typedef struct fr_plane_occluders {
  fr_plane_occluder *list; /* largest first */
  size_t n;
} fr_plane_occluders;

/* Finds the mesh's planar occluders (none is not an error). */
fr_error fr_plane_occluders_find(const fr_mesh *m, fr_plane_occluders *out);
void fr_plane_occluders_free(fr_plane_occluders *p);

/* Margins of a ray's crossing (relative): its origin off the plane by
 * FR_PLANE_ORG_MARGIN of the magnitudes, t inside (tnear, tfar) by
 * FR_PLANE_T_MARGIN of t, the point inside the polygon by
 * FR_PLANE_POINT_MARGIN of the magnitudes that made it (besides the
 * polygon's own margin). Each is far above the rounding of this test and of
 * the triangle tests, so the traversal would report the same hit. */
#define FR_PLANE_ORG_MARGIN 1e-5f
#define FR_PLANE_T_MARGIN 1e-4f
#define FR_PLANE_POINT_MARGIN 1e-5f

/* Whether the ray o + t d, t in (tnear, tfar), crosses occluder p inside
 * by the margins: the scalar reference of trace/plane_test.h. */
static inline int fr_plane_occluder_hit(const fr_plane_occluder *p, const float o[3], const float d[3], float tnear,
                                        float tfar) {
  const int a = p->axis, u = (a + 1) % 3, v = (a + 2) % 3;
  const float toward = p->c - o[a];
  if (!(fabsf(toward) > FR_PLANE_ORG_MARGIN * (fabsf(o[a]) + fabsf(p->c)))) return 0;
  const float t = toward / d[a];
  const float dt = FR_PLANE_T_MARGIN * fabsf(t);
  if (!(t - dt > tnear && t + dt < tfar)) return 0;
  const float su = t * d[u], sv = t * d[v], pu = o[u] + su, pv = o[v] + sv;
  if (!(pu >= p->lo[0] && pu <= p->hi[0] && pv >= p->lo[1] && pv <= p->hi[1])) return 0;
  const float err = FR_PLANE_POINT_MARGIN * ((fabsf(o[u]) + fabsf(o[v])) + (fabsf(su) + fabsf(sv)));
  for (int i = 0; i < p->nedges; i++)
    if (!((p->nu[i] * pu + p->nv[i] * pv) + err <= p->e[i])) return 0;
  return 1;
}

/* Whether any occluder of ps claims the ray: shadow segments only (finite
 * tfar; see the packets' kernel for why), each occluder only if the ray
 * crosses its plane within its range. The single-ray kernel's test (ray
 * streams do not test occluders: per ray it cost them 12%). */
static inline int fr_plane_occluders_hit(const fr_plane_occluders *ps, const float o[3], const float d[3],
                                         float tnear, float tfar) {
  if (!(tfar < INFINITY)) return 0;
  for (size_t i = 0; i < ps->n; i++) {
    const fr_plane_occluder *p = &ps->list[i];
    const float side = o[p->axis] - p->c, end = o[p->axis] + tfar * d[p->axis] - p->c;
    if (side * end < 0.0f && fr_plane_occluder_hit(p, o, d, tnear, tfar)) return 1;
  }
  return 0;
}
#endif
