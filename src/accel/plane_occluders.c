/*
 * Finding planar occluders (accel/plane_occluders.h): the axis-plane
 * triangles grouped by plane, each plane's triangles split into patches that
 * share vertices, and each patch checked to cover its convex hull exactly.
 */
#include "accel/plane_occluders.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"

#define FR_PLANE_HULL_MAX 1024 /* hull vertices */

/* A triangle of an axis plane: the plane as a sortable key, the triangle. */
typedef struct plane_tri { int axis; float c; uint32_t tri; } plane_tri;

static int plane_tri_cmp(const void *pa, const void *pb) {
  const plane_tri *a = pa, *b = pb;
  if (a->axis != b->axis) return a->axis < b->axis ? -1 : 1;
  if (a->c != b->c) return a->c < b->c ? -1 : 1;
  return a->tri < b->tri ? -1 : a->tri > b->tri;
}

/* A corner of a patch's triangle in plane coordinates, to merge corners at
 * the same place (meshes may repeat a vertex under several indices). */
typedef struct corner { float u, v; uint32_t slot; } corner;

static int corner_cmp(const void *pa, const void *pb) {
  const corner *a = pa, *b = pb;
  if (a->u != b->u) return a->u < b->u ? -1 : 1;
  if (a->v != b->v) return a->v < b->v ? -1 : 1;
  return a->slot < b->slot ? -1 : a->slot > b->slot;
}

/* An undirected edge between two merged corners; dir 1 when a triangle runs lo -> hi. */
typedef struct edge { uint32_t lo, hi; int dir; } edge;

static int edge_cmp(const void *pa, const void *pb) {
  const edge *a = pa, *b = pb;
  if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
  if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
  return a->dir - b->dir;
}

static uint32_t uf_find(uint32_t *par, uint32_t x) {
  while (par[x] != x) { par[x] = par[par[x]]; x = par[x]; }
  return x;
}

typedef struct pt { double u, v; } pt;

static double cross3(pt o, pt a, pt b) { return (a.u - o.u) * (b.v - o.v) - (a.v - o.v) * (b.u - o.u); }

/* Convex hull, counter-clockwise, of n sorted distinct points (Andrew's
 * monotone chain); h has room for n + 1. Returns its vertex count. */
static size_t hull_of(const pt *p, size_t n, pt *h) {
  size_t k = 0;
  for (size_t i = 0; i < n; i++) {
    while (k >= 2 && cross3(h[k - 2], h[k - 1], p[i]) <= 0.0) k--;
    h[k++] = p[i];
  }
  for (size_t i = n - 1, lo = k + 1; i-- > 0;) {
    while (k >= lo && cross3(h[k - 2], h[k - 1], p[i]) <= 0.0) k--;
    h[k++] = p[i];
  }
  return k > 1 ? k - 1 : k;
}

static double polygon_area(const pt *h, size_t n) {
  double a = 0.0;
  for (size_t i = 0; i < n; i++) a += h[i].u * h[(i + 1) % n].v - h[(i + 1) % n].u * h[i].v;
  return 0.5 * a;
}

/* Whether segment pq lies on an edge of hull h (n vertices) within tol. */
static int on_hull(const pt *h, size_t n, pt p, pt q, double tol) {
  for (size_t i = 0; i < n; i++) {
    pt a = h[i], b = h[(i + 1) % n];
    double len = hypot(b.u - a.u, b.v - a.v);
    if (len == 0.0) continue;
    if (fabs(cross3(a, b, p)) / len > tol || fabs(cross3(a, b, q)) / len > tol) continue;
    /* both within the segment's span (with tol) */
    double tp = ((p.u - a.u) * (b.u - a.u) + (p.v - a.v) * (b.v - a.v)) / len;
    double tq = ((q.u - a.u) * (b.u - a.u) + (q.v - a.v) * (b.v - a.v)) / len;
    if (tp >= -tol && tp <= len + tol && tq >= -tol && tq <= len + tol) return 1;
  }
  return 0;
}

/* One patch: triangles tris[0..n) of plane (axis, c). On success fills *o. */
static int patch_occluder(const fr_mesh *m, int axis, float c, const uint32_t *tris, size_t n, fr_plane_occluder *o) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  int ok = 0;
  corner *cs = malloc(3 * n * sizeof *cs);
  uint32_t *id = malloc(3 * n * sizeof *id);
  edge *es = malloc(3 * n * sizeof *es);
  pt *p = malloc(3 * n * sizeof *p), *h = malloc((3 * n + 1) * sizeof *h);
  if (!cs || !id || !es || !p || !h) goto done;
  for (size_t t = 0; t < n; t++)
    for (int k = 0; k < 3; k++) {
      const float *x = m->pos + 3 * (size_t)m->idx[3 * (size_t)tris[t] + k];
      cs[3 * t + k] = (corner){x[u], x[v], (uint32_t)(3 * t + k)};
    }
  qsort(cs, 3 * n, sizeof *cs, corner_cmp);
  size_t np = 0;
  for (size_t i = 0; i < 3 * n; i++) {
    if (i == 0 || cs[i].u != cs[i - 1].u || cs[i].v != cs[i - 1].v) p[np++] = (pt){cs[i].u, cs[i].v};
    id[cs[i].slot] = (uint32_t)(np - 1);
  }
  /* one orientation, no zero area */
  double area = 0.0;
  int sign = 0;
  for (size_t t = 0; t < n; t++) {
    double s = 0.5 * cross3(p[id[3 * t]], p[id[3 * t + 1]], p[id[3 * t + 2]]);
    int sg = s > 0.0 ? 1 : s < 0.0 ? -1 : 0;
    if (!sg || (sign && sg != sign)) goto done;
    sign = sg;
    area += fabs(s);
  }
  /* edges: inner ones twice, opposite ways; the rest once */
  for (size_t t = 0; t < n; t++)
    for (int k = 0; k < 3; k++) {
      uint32_t a = id[3 * t + k], b = id[3 * t + (k + 1) % 3];
      es[3 * t + k] = a < b ? (edge){a, b, 1} : (edge){b, a, 0};
    }
  qsort(es, 3 * n, sizeof *es, edge_cmp);
  size_t nh = hull_of(p, np, h);
  /* the boundary check below is boundary edges times hull edges: finely
   * curved outlines are passed over rather than slow to prove */
  if (nh < 3 || nh > FR_PLANE_HULL_MAX) goto done;
  /* the diameter, within a factor of 1.5: the diagonal of the hull's box */
  double lo_u = INFINITY, hi_u = -INFINITY, lo_v = INFINITY, hi_v = -INFINITY, mag = fabs((double)c);
  for (size_t i = 0; i < nh; i++) {
    lo_u = fmin(lo_u, h[i].u); hi_u = fmax(hi_u, h[i].u);
    lo_v = fmin(lo_v, h[i].v); hi_v = fmax(hi_v, h[i].v);
    mag = fmax(mag, fmax(fabs(h[i].u), fabs(h[i].v)));
  }
  const double diam = hypot(hi_u - lo_u, hi_v - lo_v);
  /* Boundary vertices of an outline modelled to a few digits may sit a
   * little inside the hull (kitchen's table top: 2e-5 of 1.5 m); the
   * polygon kept is shrunk by ten times this */
  const double tol = 5e-5 * diam + 1e-6 * mag;
  for (size_t i = 0; i < 3 * n;) {
    size_t j = i + 1;
    while (j < 3 * n && es[j].lo == es[i].lo && es[j].hi == es[i].hi) j++;
    if (j - i > 2 || (j - i == 2 && es[i].dir == es[i + 1].dir)) goto done;
    if (j - i == 1 && !on_hull(h, nh, p[es[i].lo], p[es[i].hi], tol)) goto done;
    i = j;
  }
  const double hull_area = polygon_area(h, nh);
  if (!(fabs(area - hull_area) <= 1e-3 * hull_area)) goto done;
  /* keep up to FR_PLANE_OCCLUDER_EDGES of the hull's vertices, spread evenly:
   * a polygon inscribed in the hull, then shrunk by the margin */
  const size_t keep = nh < FR_PLANE_OCCLUDER_EDGES ? nh : FR_PLANE_OCCLUDER_EDGES;
  pt q[FR_PLANE_OCCLUDER_EDGES];
  for (size_t i = 0; i < keep; i++) q[i] = h[i * nh / keep];
  const double margin = 10.0 * tol;
  memset(o, 0, sizeof *o);
  o->axis = axis;
  o->c = c;
  o->nedges = (int)keep;
  o->lo[0] = o->lo[1] = INFINITY;
  o->hi[0] = o->hi[1] = -INFINITY;
  for (size_t i = 0; i < keep; i++) {
    pt a = q[i], b = q[(i + 1) % keep];
    double len = hypot(b.u - a.u, b.v - a.v);
    /* counter-clockwise: the outward normal is (dv, -du) */
    double nu = (b.v - a.v) / len, nv = -(b.u - a.u) / len;
    o->nu[i] = (float)nu;
    o->nv[i] = (float)nv;
    /* the float normal's rounding moves the line by under 1e-7 * mag, far inside the margin */
    o->e[i] = (float)((double)o->nu[i] * a.u + (double)o->nv[i] * a.v - margin);
    o->lo[0] = fminf(o->lo[0], (float)a.u); o->hi[0] = fmaxf(o->hi[0], (float)a.u);
    o->lo[1] = fminf(o->lo[1], (float)a.v); o->hi[1] = fmaxf(o->hi[1], (float)a.v);
  }
  o->area = polygon_area(q, keep);
  o->tris = n;
  ok = o->area > 0.0;
done:
  free(cs); free(id); free(es); free(p); free(h);
  return ok;
}

static int occluder_cmp(const void *pa, const void *pb) {
  const fr_plane_occluder *a = pa, *b = pb;
  return (a->area < b->area) - (a->area > b->area);
}

static int u32_pair_cmp(const void *pa, const void *pb) {
  const uint32_t *a = pa, *b = pb;
  if (a[0] != b[0]) return a[0] < b[0] ? -1 : 1;
  return (a[1] > b[1]) - (a[1] < b[1]);
}

/* Splits one plane's triangles pl[0..n) into patches that touch (corners at
 * the same place) and tries each of FR_PLANE_OCCLUDER_MIN_TRIS or more;
 * appends the occluders found to *out. */
static fr_error plane_patches(const fr_mesh *m, const plane_tri *pl, size_t n, fr_plane_occluder **out, size_t *nout,
                              size_t *cap) {
  const int axis = pl[0].axis, u = (axis + 1) % 3, v = (axis + 2) % 3;
  fr_error e = FR_OK;
  corner *cs = malloc(3 * n * sizeof *cs);
  uint32_t *par = malloc(n * sizeof *par), *pairs = malloc(2 * n * sizeof *pairs), *tris = malloc(n * sizeof *tris);
  if (!cs || !par || !pairs || !tris) { e = fr_fail(FR_ERR_NOMEM, "planar occluders: out of memory"); goto done; }
  for (size_t i = 0; i < n; i++) {
    par[i] = (uint32_t)i;
    for (int k = 0; k < 3; k++) {
      const float *x = m->pos + 3 * (size_t)m->idx[3 * (size_t)pl[i].tri + k];
      cs[3 * i + k] = (corner){x[u], x[v], (uint32_t)i};
    }
  }
  qsort(cs, 3 * n, sizeof *cs, corner_cmp);
  for (size_t i = 1; i < 3 * n; i++)
    if (cs[i].u == cs[i - 1].u && cs[i].v == cs[i - 1].v) {
      uint32_t a = uf_find(par, cs[i].slot), b = uf_find(par, cs[i - 1].slot);
      if (a != b) par[a] = b;
    }
  for (size_t i = 0; i < n; i++) { pairs[2 * i] = uf_find(par, (uint32_t)i); pairs[2 * i + 1] = (uint32_t)i; }
  qsort(pairs, n, 2 * sizeof *pairs, u32_pair_cmp);
  for (size_t i = 0; i < n;) {
    size_t j = i;
    while (j < n && pairs[2 * j] == pairs[2 * i]) { tris[j - i] = pl[pairs[2 * j + 1]].tri; j++; }
    if (j - i >= FR_PLANE_OCCLUDER_MIN_TRIS) {
      fr_plane_occluder o;
      if (patch_occluder(m, axis, pl[0].c, tris, j - i, &o)) {
        if (*nout == *cap) {
          size_t nc = *cap ? 2 * *cap : 16;
          fr_plane_occluder *g = realloc(*out, nc * sizeof *g);
          if (!g) { e = fr_fail(FR_ERR_NOMEM, "planar occluders: out of memory"); goto done; }
          *out = g;
          *cap = nc;
        }
        (*out)[(*nout)++] = o;
      }
    }
    i = j;
  }
done:
  free(cs); free(par); free(pairs); free(tris);
  return e;
}

fr_error fr_plane_occluders_find(const fr_mesh *m, fr_plane_occluders *out) {
  memset(out, 0, sizeof *out);
  plane_tri *pl = malloc((m->ntris ? m->ntris : 1) * sizeof *pl);
  if (!pl) return fr_fail(FR_ERR_NOMEM, "planar occluders: out of memory");
  size_t n = 0;
  for (size_t t = 0; t < m->ntris; t++) {
    const float *x[3];
    for (int k = 0; k < 3; k++) x[k] = m->pos + 3 * (size_t)m->idx[3 * t + k];
    for (int a = 0; a < 3; a++)
      if (x[0][a] == x[1][a] && x[1][a] == x[2][a]) {
        /* only triangles the BVH holds: a skipped one would be a gap */
        if (fr_mesh_triangle_traceable(m, t)) pl[n++] = (plane_tri){a, x[0][a] == 0.0f ? 0.0f : x[0][a], (uint32_t)t};
        break;
      }
  }
  qsort(pl, n, sizeof *pl, plane_tri_cmp);
  fr_plane_occluder *list = NULL;
  size_t nl = 0, cap = 0;
  fr_error e = FR_OK;
  for (size_t i = 0; i < n && !e;) {
    size_t j = i + 1;
    while (j < n && pl[j].axis == pl[i].axis && pl[j].c == pl[i].c) j++;
    if (j - i >= FR_PLANE_OCCLUDER_MIN_TRIS) e = plane_patches(m, pl + i, j - i, &list, &nl, &cap);
    i = j;
  }
  free(pl);
  if (e) { free(list); return e; }
  if (nl) qsort(list, nl, sizeof *list, occluder_cmp); /* qsort takes no NULL, even for none */
  out->list = list;
  out->n = nl < FR_PLANE_OCCLUDERS_MAX ? nl : FR_PLANE_OCCLUDERS_MAX;
  return FR_OK;
}

void fr_plane_occluders_free(fr_plane_occluders *p) {
  free(p->list);
  memset(p, 0, sizeof *p);
}
