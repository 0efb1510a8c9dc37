/*
 * A double-precision judge of closest-hit and any-hit answers, the rule of
 * docs/rayfile.md made exact for hostile geometry.
 *
 * A float kernel works in coordinates relative to the ray's origin, so it
 * cannot place a point of a triangle better than a few ulps of the
 * triangle's distance from that origin: tol = FR_JUDGE_ULPS * 2^-24 *
 * max |v_i - o| (per triangle, per ray). Then, with P(t) = o + t d in
 * double and dt(t) = 1e-4 max(1, |t|):
 *
 *   a triangle is *clearly hit* at t_q when P(t_q) lies inside it by more
 *   than tol (from every edge) and t_q, widened by the uncertainty
 *   tol / |n . d| that a float test has along the ray, lies inside
 *   (tnear + dt, tfar - dt);
 *   a triangle is *possibly hit* when some point of the ray in
 *   (tnear - dt, tfar + dt) lies within tol of it.
 *
 * A reported hit (prim, t) is right when t is in (tnear - dt, tfar + dt),
 * the ray passes within tol of prim somewhere in (t - dt, t + dt) (so t is
 * that triangle's t, for a sliver as for any other), and no triangle is clearly hit before t - dt. A reported
 * miss, or "not occluded", is right when no triangle is clearly hit; an
 * "occluded" when some triangle is possibly hit.
 */
#ifndef FR_TEST_EXACT_JUDGE_H
#define FR_TEST_EXACT_JUDGE_H
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include "frusta.h"

#define FR_JUDGE_ULPS 16.0

typedef struct jd_tri {
  double v[3][3];
  double n[3], nlen; /* (v1 - v0) x (v2 - v0) in double (exact up to one rounding per term) */
  double lo[3], hi[3];
} jd_tri;

typedef struct jd_mesh {
  jd_tri *tri;
  size_t nt;
  double lo[3], hi[3]; /* the bounds of all vertices */
} jd_mesh;

/* What the judge knows of one ray. */
typedef struct jd_ray {
  double first;  /* least bound t_q + dt + uncertainty over clearly hit triangles, +inf if none */
  int clear;     /* some triangle is clearly hit in range */
  int possible;  /* some triangle is possibly hit in range */
} jd_ray;

static inline double jd_min(double a, double b) { return a < b ? a : b; }
static inline double jd_max(double a, double b) { return a > b ? a : b; }
static inline double jd_dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static inline void jd_cross(const double a[3], const double b[3], double c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
static inline void jd_sub(const double a[3], const double b[3], double c[3]) {
  for (int k = 0; k < 3; k++) c[k] = a[k] - b[k];
}
static inline double jd_dt(double t) { return 1e-4 * jd_max(1.0, fabs(t)); }

/* The judge's mesh, triangle i of the file as tri[i]; nlen is 0 for one
 * without area in double, which nothing can hit. */
static inline jd_mesh jd_mesh_make(const float *pos, const uint32_t *idx, size_t nt) {
  jd_mesh m = {calloc(nt ? nt : 1, sizeof(jd_tri)), nt, {INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  for (size_t t = 0; t < nt; t++) {
    jd_tri *q = &m.tri[t];
    for (int i = 0; i < 3; i++)
      for (int k = 0; k < 3; k++) q->v[i][k] = pos[3 * (size_t)idx[3 * t + i] + k];
    double e1[3], e2[3];
    jd_sub(q->v[1], q->v[0], e1);
    jd_sub(q->v[2], q->v[0], e2);
    jd_cross(e1, e2, q->n);
    q->nlen = sqrt(jd_dot(q->n, q->n));
    for (int k = 0; k < 3; k++) {
      q->lo[k] = jd_min(q->v[0][k], jd_min(q->v[1][k], q->v[2][k]));
      q->hi[k] = jd_max(q->v[0][k], jd_max(q->v[1][k], q->v[2][k]));
      m.lo[k] = jd_min(m.lo[k], q->lo[k]);
      m.hi[k] = jd_max(m.hi[k], q->hi[k]);
    }
  }
  return m;
}

static inline double jd_tol(const jd_tri *q, const double o[3]) {
  double s = 0.0;
  for (int k = 0; k < 3; k++) s = jd_max(s, jd_max(fabs(q->lo[k] - o[k]), fabs(q->hi[k] - o[k])));
  return FR_JUDGE_ULPS * 0x1p-24 * s;
}

/* Signed distance of p (in the plane) from edge i (v_i to v_i+1), positive inside. */
static inline double jd_edge_dist(const jd_tri *q, int i, const double p[3]) {
  const double *a = q->v[i], *b = q->v[(i + 1) % 3];
  double e[3], w[3], c[3];
  jd_sub(b, a, e);
  jd_sub(p, a, w);
  jd_cross(e, w, c);
  double el = sqrt(jd_dot(e, e));
  return el > 0.0 ? jd_dot(c, q->n) / (q->nlen * el) : 0.0;
}

/* Distance from point p to segment [a, b]. */
static inline double jd_point_segment(const double p[3], const double a[3], const double b[3]) {
  double e[3], w[3];
  jd_sub(b, a, e);
  jd_sub(p, a, w);
  double ee = jd_dot(e, e), s = ee > 0.0 ? jd_min(1.0, jd_max(0.0, jd_dot(w, e) / ee)) : 0.0;
  double r[3] = {w[0] - s * e[0], w[1] - s * e[1], w[2] - s * e[2]};
  return sqrt(jd_dot(r, r));
}

/* Distance from p to the closed triangle q. */
static inline double jd_point_tri(const jd_tri *q, const double p[3]) {
  double w[3];
  jd_sub(p, q->v[0], w);
  double h = jd_dot(w, q->n) / q->nlen;
  double f[3] = {p[0] - h * q->n[0] / q->nlen, p[1] - h * q->n[1] / q->nlen, p[2] - h * q->n[2] / q->nlen};
  if (jd_edge_dist(q, 0, f) >= 0.0 && jd_edge_dist(q, 1, f) >= 0.0 && jd_edge_dist(q, 2, f) >= 0.0) return fabs(h);
  double d = INFINITY;
  for (int i = 0; i < 3; i++) d = jd_min(d, jd_point_segment(p, q->v[i], q->v[(i + 1) % 3]));
  return d;
}

/* 2D: do segments pq and rs cross? */
static inline int jd_cross2(const double p[2], const double q[2], const double r[2], const double s[2]) {
  double d1 = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
  double d2 = (q[0] - p[0]) * (s[1] - p[1]) - (q[1] - p[1]) * (s[0] - p[0]);
  double d3 = (s[0] - r[0]) * (p[1] - r[1]) - (s[1] - r[1]) * (p[0] - r[0]);
  double d4 = (s[0] - r[0]) * (q[1] - r[1]) - (s[1] - r[1]) * (q[0] - r[0]);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}

/* Does the ray, over t in [t0, t1], come within tol of q? Clipped to the
 * slab |distance to q's plane| <= tol and to q's bounding sphere, the
 * rest is the distance in the plane between a segment and a triangle. */
static inline int jd_possible(const jd_tri *q, const double o[3], const double d[3], double t0, double t1, double tol) {
  double c[3] = {0, 0, 0}, R = 0.0;
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++) c[k] += q->v[i][k] / 3.0;
  for (int i = 0; i < 3; i++) {
    double e[3];
    jd_sub(q->v[i], c, e);
    R = jd_max(R, sqrt(jd_dot(e, e)));
  }
  R += 2.0 * tol;
  double oc[3];
  jd_sub(o, c, oc);
  double a = jd_dot(d, d), b = jd_dot(d, oc), cc = jd_dot(oc, oc) - R * R, disc = b * b - a * cc;
  if (disc < 0.0 || !(a > 0.0)) return 0;
  double sq = sqrt(disc);
  t0 = jd_max(t0, (-b - sq) / a);
  t1 = jd_min(t1, (-b + sq) / a);
  if (!(t0 <= t1)) return 0;
  double w[3];
  jd_sub(o, q->v[0], w);
  double h0 = jd_dot(w, q->n) / q->nlen, hd = jd_dot(d, q->n) / q->nlen;
  if (hd == 0.0) {
    if (fabs(h0) > tol) return 0;
  } else {
    double ta = (-tol - h0) / hd, tb = (tol - h0) / hd;
    t0 = jd_max(t0, jd_min(ta, tb));
    t1 = jd_min(t1, jd_max(ta, tb));
    if (!(t0 <= t1)) return 0;
  }
  /* in-plane coordinates: x along v1 - v0, y = n x x */
  double ex[3], ey[3];
  jd_sub(q->v[1], q->v[0], ex);
  double exl = sqrt(jd_dot(ex, ex));
  for (int k = 0; k < 3; k++) ex[k] /= exl;
  jd_cross(q->n, ex, ey);
  for (int k = 0; k < 3; k++) ey[k] /= q->nlen;
  double T[3][2], S[2][2];
  for (int i = 0; i < 3; i++) {
    double r[3];
    jd_sub(q->v[i], q->v[0], r);
    T[i][0] = jd_dot(r, ex);
    T[i][1] = jd_dot(r, ey);
  }
  const double ts[2] = {t0, t1};
  for (int j = 0; j < 2; j++) {
    double r[3] = {w[0] + ts[j] * d[0], w[1] + ts[j] * d[1], w[2] + ts[j] * d[2]};
    S[j][0] = jd_dot(r, ex);
    S[j][1] = jd_dot(r, ey);
  }
  /* an end inside, a crossing of an edge, or an end or corner within tol */
  for (int j = 0; j < 2; j++) {
    double p3[3] = {q->v[0][0] + S[j][0] * ex[0] + S[j][1] * ey[0], q->v[0][1] + S[j][0] * ex[1] + S[j][1] * ey[1],
                    q->v[0][2] + S[j][0] * ex[2] + S[j][1] * ey[2]};
    if (jd_point_tri(q, p3) <= tol) return 1;
  }
  for (int i = 0; i < 3; i++) {
    if (jd_cross2(S[0], S[1], T[i], T[(i + 1) % 3])) return 1;
    double p[3] = {T[i][0], T[i][1], 0}, a3[3] = {S[0][0], S[0][1], 0}, b3[3] = {S[1][0], S[1][1], 0};
    if (jd_point_segment(p, a3, b3) <= tol) return 1;
  }
  return 0;
}

/* Box of q, widened by tol, against the ray over [t0, t1]. */
static inline int jd_box(const jd_tri *q, const double o[3], const double d[3], double t0, double t1, double tol) {
  for (int k = 0; k < 3; k++) {
    double lo = q->lo[k] - tol, hi = q->hi[k] + tol;
    if (d[k] == 0.0) {
      if (o[k] < lo || o[k] > hi) return 0;
      continue;
    }
    double a = (lo - o[k]) / d[k], b = (hi - o[k]) / d[k];
    t0 = jd_max(t0, jd_min(a, b));
    t1 = jd_min(t1, jd_max(a, b));
    if (!(t0 <= t1)) return 0;
  }
  return 1;
}

static inline void jd_ray_of(const fr_ray *r, double o[3], double d[3]) {
  for (int k = 0; k < 3; k++) { o[k] = r->org[k]; d[k] = r->dir[k]; }
}

/* What is clearly and possibly hit along r. */
static inline jd_ray jd_judge(const jd_mesh *m, const fr_ray *r) {
  jd_ray j = {INFINITY, 0, 0};
  double o[3], d[3];
  jd_ray_of(r, o, d);
  const double tn = r->tnear, tf = r->tfar, lo = tn - jd_dt(tn), hi = tf + jd_dt(tf);
  /* a bound on every triangle's tol, for a first box test */
  double far = 0.0;
  for (int k = 0; k < 3; k++) far = jd_max(far, jd_max(fabs(m->lo[k] - o[k]), fabs(m->hi[k] - o[k])));
  const double tol_max = FR_JUDGE_ULPS * 0x1p-24 * far;
  for (size_t i = 0; i < m->nt; i++) {
    const jd_tri *q = &m->tri[i];
    if (!(q->nlen > 0.0) || !jd_box(q, o, d, lo, hi, 2.0 * tol_max)) continue;
    double tol = jd_tol(q, o);
    if (!j.possible && jd_possible(q, o, d, lo, hi, tol)) j.possible = 1;
    double w[3];
    jd_sub(q->v[0], o, w);
    double den = jd_dot(q->n, d);
    if (den == 0.0) continue;
    double t = jd_dot(q->n, w) / den;
    double p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
    if (!(jd_edge_dist(q, 0, p) > tol && jd_edge_dist(q, 1, p) > tol && jd_edge_dist(q, 2, p) > tol)) continue;
    double unc = tol * q->nlen / fabs(den); /* t moves by this when the plane moves by tol */
    if (!(t - unc > tn + jd_dt(tn) && t + unc < tf - jd_dt(tf))) continue;
    j.clear = 1;
    j.first = jd_min(j.first, t + jd_dt(t) + unc);
  }
  return j;
}

/* NULL if the closest-hit answer h to ray r is right by the rule, else
 * why not. */
static inline const char *jd_check_hit(const jd_mesh *m, const jd_ray *j, const fr_ray *r, const fr_hit *h) {
  if (h->prim == FR_INVALID_ID) return j->clear ? "missed a clear hit" : NULL;
  if (h->prim >= m->nt) return "no such triangle";
  const jd_tri *tri = &m->tri[h->prim];
  if (!(tri->nlen > 0.0)) return "hit a triangle that has no area";
  double o[3], d[3];
  jd_ray_of(r, o, d);
  double t = h->t;
  if (!(t > r->tnear - jd_dt(r->tnear) && t < r->tfar + jd_dt(r->tfar))) return "t out of range";
  if (!jd_possible(tri, o, d, t - jd_dt(t), t + jd_dt(t), jd_tol(tri, o))) return "the ray is not at the triangle at t";
  if (t > j->first) return "a clear hit lies before";
  return NULL;
}

static inline const char *jd_check_occluded(const jd_ray *j, int occluded) {
  if (occluded) return j->possible ? NULL : "occluded by nothing";
  return j->clear ? "not occluded, but a clear hit" : NULL;
}
#endif
