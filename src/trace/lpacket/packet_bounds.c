#include "packet_bounds.h"
#include <math.h>
#include <string.h>

#define SLACK ((double)FR_PBOUNDS_SLACK)

static const char *cull_names[FR_CULL_COUNT] = {"off", "ia", "planes", "corners"};

const char *fr_cull_name(fr_cull c) { return c < FR_CULL_COUNT ? cull_names[c] : "?"; }

int fr_cull_parse(const char *name, fr_cull *out) {
  for (int i = 0; i < FR_CULL_COUNT; i++)
    if (!strcmp(name, cull_names[i])) { *out = (fr_cull)i; return 1; }
  return 0;
}

static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

static int ray_valid(const fr_ray_soa *r, int i) {
  return !r->mask || ((r->mask[i / 16] >> (i % 16)) & 1);
}

static float down(double x) {
  float f = (float)x;
  return (double)f > x ? nextafterf(f, -INFINITY) : f;
}
static float up(double x) {
  float f = (float)x;
  return (double)f < x ? nextafterf(f, INFINITY) : f;
}

/* Made in double, stored in float rounded outward. */
void fr_pbounds_build(fr_pbounds *b, const fr_ray_soa *r) {
  memset(b, 0, sizeof *b);
  double minfrac[3] = {INFINITY, INFINITY, INFINITY}, olo[3], ohi[3], dlo[3], dhi[3];
  double tmin = INFINITY, tmax = -INFINITY;
  int count = 0;
  for (int a = 0; a < 3; a++) {
    olo[a] = dlo[a] = INFINITY;
    ohi[a] = dhi[a] = -INFINITY;
  }
  for (int i = 0; i < r->n; i++) {
    if (!ray_valid(r, i)) continue;
    double l1 = fabs((double)r->d[0][i]) + fabs((double)r->d[1][i]) + fabs((double)r->d[2][i]);
    for (int a = 0; a < 3; a++) {
      double o = r->o[a][i], d = r->d[a][i];
      olo[a] = dmin(olo[a], o);
      ohi[a] = dmax(ohi[a], o);
      dlo[a] = dmin(dlo[a], d);
      dhi[a] = dmax(dhi[a], d);
      minfrac[a] = dmin(minfrac[a], l1 > 0.0 ? fabs(d) / l1 : 0.0);
    }
    tmin = dmin(tmin, r->tnear[i]);
    tmax = dmax(tmax, r->tfar[i]);
    count++;
  }
  if (!count) { b->empty = 1; return; }
  b->tmin = (float)tmin;
  b->tmax = (float)tmax;
  int best = -1;
  double scale = 0.0;
  for (int a = 0; a < 3; a++) {
    b->olo[a] = (float)olo[a]; b->ohi[a] = (float)ohi[a];
    b->dlo[a] = (float)dlo[a]; b->dhi[a] = (float)dhi[a];
    scale = dmax(scale, dmax(fabs(olo[a]), fabs(ohi[a])));
    if (dlo[a] > 0.0 || dhi[a] < 0.0) {
      b->uniform |= 1u << a;
      /* 1/d is monotonic on an interval of one sign */
      b->rlo[a] = down(1.0 / dhi[a]);
      b->rhi[a] = up(1.0 / dlo[a]);
      if (best < 0 || minfrac[a] > minfrac[best]) best = a;
    }
  }
  b->scale = up(scale);
  b->shared_origin = olo[0] == ohi[0] && olo[1] == ohi[1] && olo[2] == ohi[2];
  if (best < 0) return;
  /* bounding planes along the major axis: the axis whose directions stay
   * farthest from 0 relative to their length, so the slopes stay small */
  const int k = best, u = (k + 1) % 3, v = (k + 2) % 3;
  const double sk = dlo[k] > 0.0 ? 1.0 : -1.0;
  double knear = INFINITY, kfar = -INFINITY;
  for (int i = 0; i < r->n; i++) {
    if (!ray_valid(r, i)) continue;
    double K = sk * r->o[k][i], dk = fabs((double)r->d[k][i]);
    knear = dmin(knear, K + (double)r->tnear[i] * dk);
    kfar = dmax(kfar, isinf(r->tfar[i]) ? INFINITY : K + (double)r->tfar[i] * dk);
  }
  double ulo = INFINITY, vlo = INFINITY, sulo = INFINITY, svlo = INFINITY;
  double uhi = -INFINITY, vhi = -INFINITY, suhi = -INFINITY, svhi = -INFINITY;
  for (int i = 0; i < r->n; i++) {
    if (!ray_valid(r, i)) continue;
    double rk = 1.0 / fabs((double)r->d[k][i]), back = knear - sk * r->o[k][i];
    double su = r->d[u][i] * rk, sv = r->d[v][i] * rk;
    double pu = r->o[u][i] + back * su, pv = r->o[v][i] + back * sv;
    ulo = dmin(ulo, pu); uhi = dmax(uhi, pu);
    vlo = dmin(vlo, pv); vhi = dmax(vhi, pv);
    sulo = dmin(sulo, su); suhi = dmax(suhi, su);
    svlo = dmin(svlo, sv); svhi = dmax(svhi, sv);
  }
  b->has_planes = 1;
  b->k = k; b->u = u; b->v = v;
  b->sk = (float)sk;
  b->knear = down(knear);
  b->kfar = up(kfar);
  b->ulo = down(ulo); b->uhi = up(uhi);
  b->vlo = down(vlo); b->vhi = up(vhi);
  b->sulo = down(sulo); b->suhi = up(suhi);
  b->svlo = down(svlo); b->svhi = up(svhi);
  b->scale = up(dmax(scale, fabs(knear)));
}

/* the triangle and sphere culls fall back to interval arithmetic on their boxes */
static int cull_box_d(const fr_pbounds *b, fr_cull c, const double lo[3], const double hi[3]) {
  float l[3], h[3];
  for (int a = 0; a < 3; a++) {
    l[a] = (float)lo[a];
    h[a] = (float)hi[a];
    if (l[a] > lo[a]) l[a] = nextafterf(l[a], -INFINITY);
    if (h[a] < hi[a]) h[a] = nextafterf(h[a], INFINITY);
  }
  return fr_pbounds_cull_box(b, c, l, h);
}

/* ---- triangles -------------------------------------------------------------- */

typedef struct kuv { double K, u, v; } kuv;

static kuv to_kuv(const fr_pbounds *b, const double p[3]) {
  kuv r = {b->sk * p[b->k], p[b->u], p[b->v]};
  return r;
}

static void from_kuv(const fr_pbounds *b, double K, double u, double v, double p[3]) {
  p[b->k] = b->sk * K;
  p[b->u] = u;
  p[b->v] = v;
}

static float absf_max4(float a, float b, float c, float d) {
  return fr_pb_max(fr_pb_max(fabsf(a), fabsf(b)), fr_pb_max(fabsf(c), fabsf(d)));
}

/* All three corners outside one of the six planes of the packet volume,
 * in float: the test runs once per triangle a packet reaches, where double
 * conversions cost more than it saved. Each side's float rounding is below
 * 2^-20 of the magnitudes it is made of (the coordinates, the slopes times
 * them, the plane offsets), which is added to the slack. */
static int tri_outside_planes(const fr_pbounds *b, const float *const v[3]) {
  float mag = 0.0f;
  for (int i = 0; i < 3; i++)
    for (int a = 0; a < 3; a++) mag = fr_pb_max(mag, fabsf(v[i][a]));
  const float reach = b->scale + mag, slope = 1.0f + absf_max4(b->sulo, b->suhi, b->svlo, b->svhi);
  const float tol = FR_PBOUNDS_SLACK * reach + 0x1p-20f * (slope * reach + absf_max4(b->ulo, b->uhi, b->vlo, b->vhi));
  unsigned out = 0x3f;
  for (int i = 0; i < 3; i++) {
    const float K = b->sk * v[i][b->k], dK = K - b->knear, u = v[i][b->u], w = v[i][b->v];
    out &= (unsigned)(dK < -tol) | (unsigned)(K > b->kfar + tol) << 1 | (unsigned)(u > b->uhi + b->suhi * dK + tol) << 2 |
           (unsigned)(u < b->ulo + b->sulo * dK - tol) << 3 | (unsigned)(w > b->vhi + b->svhi * dK + tol) << 4 |
           (unsigned)(w < b->vlo + b->svlo * dK - tol) << 5;
  }
  return out != 0;
}

static double dot3d(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross3d(const double a[3], const double b[3], double r[3]) {
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
}
static double norm1(const double a[3]) { return fabs(a[0]) + fabs(a[1]) + fabs(a[2]); }

/* The packet volume entirely on one side of the triangle's plane: its
 * corners at knear and kfar, or, unbounded, its corners at knear and the
 * corner rays' directions. */
static int volume_off_plane(const fr_pbounds *b, const double v0[3], const double n[3], double tol) {
  const double us[2] = {b->ulo, b->uhi}, vs[2] = {b->vlo, b->vhi};
  const double su[2] = {b->sulo, b->suhi}, sv[2] = {b->svlo, b->svhi};
  const int bounded = isfinite(b->kfar);
  const double dk = bounded ? b->kfar - b->knear : 0.0;
  int above = 1, below = 1;
  for (int j = 0; j < 4; j++) {
    int iu = j & 1, iv = j >> 1;
    double p[3], q[3];
    from_kuv(b, b->knear, us[iu], vs[iv], p);
    for (int a = 0; a < 3; a++) p[a] -= v0[a];
    double f = dot3d(n, p);
    above &= f > tol;
    below &= f < -tol;
    if (bounded) {
      from_kuv(b, b->kfar, us[iu] + su[iu] * dk, vs[iv] + sv[iv] * dk, q);
      for (int a = 0; a < 3; a++) q[a] -= v0[a];
      f = dot3d(n, q);
      above &= f > tol;
      below &= f < -tol;
    } else {
      from_kuv(b, 1.0, su[iu], sv[iv], q);
      f = dot3d(n, q);
      above &= f >= 0.0;
      below &= f <= 0.0;
    }
  }
  return above | below;
}

/* Every ray's line passes outside one edge. The lines go through a point A
 * of the packet's rectangle at knear and a point B of its rectangle at a
 * later K1; an edge's Pluecker side D . ((P - A) x (Q - A)), D = B - A, is
 * linear in each coordinate of A and of B, so its extremes are at the 16
 * lines through the rectangles' corners (4 when the origins are shared:
 * the rectangle at knear is then the origin itself).
 * A line meets the triangle only if every side has the sign of D . n. */
static int lines_outside_edge(const fr_pbounds *b, const double V[3][3], const double n[3]) {
  const double K1 = b->knear + dmax(b->scale, 1e-6);
  const double us[2] = {b->ulo, b->uhi}, vs[2] = {b->vlo, b->vhi};
  const double su[2] = {b->sulo, b->suhi}, sv[2] = {b->svlo, b->svhi};
  double side_max[3] = {-INFINITY, -INFINITY, -INFINITY};
  int dn_sign = 0;
  /* with a shared origin the rectangle at knear is a point: 4 lines */
  const int lines = b->shared_origin ? 4 : 16;
  for (int j = 0; j < lines; j++) {
    int bu = j & 1, bv = (j >> 1) & 1, au = (j >> 2) & 1, av = (j >> 3) & 1;
    double A[3], B[3], D[3];
    from_kuv(b, b->knear, us[au], vs[av], A);
    double dk = K1 - b->knear;
    from_kuv(b, K1, us[bu] + su[bu] * dk, vs[bv] + sv[bv] * dk, B);
    for (int a = 0; a < 3; a++) D[a] = B[a] - A[a];
    double dn = dot3d(D, n);
    int s = dn > 0.0 ? 1 : dn < 0.0 ? -1 : 0;
    if (s == 0 || (dn_sign && s != dn_sign)) return 0;
    dn_sign = s;
    for (int i = 0; i < 3; i++) {
      const double *P = V[i], *Q = V[(i + 1) % 3];
      double pa[3], qa[3], c[3];
      for (int a = 0; a < 3; a++) { pa[a] = P[a] - A[a]; qa[a] = Q[a] - A[a]; }
      cross3d(pa, qa, c);
      double side = s * dot3d(D, c);
      double guard = SLACK * norm1(D) * norm1(pa) * norm1(qa);
      side_max[i] = dmax(side_max[i], side + guard);
    }
  }
  return side_max[0] < 0.0 || side_max[1] < 0.0 || side_max[2] < 0.0;
}

int fr_pbounds_cull_tri(const fr_pbounds *b, fr_cull c, const float v0[3], const float v1[3], const float v2[3]) {
  if (b->empty) return 1;
  if (c == FR_CULL_OFF) return 0;
  if (c == FR_CULL_IA || !b->has_planes) {
    /* the triangle's box: min and max of floats are exact, so no double */
    float lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
      lo[a] = fr_pb_min(v0[a], fr_pb_min(v1[a], v2[a]));
      hi[a] = fr_pb_max(v0[a], fr_pb_max(v1[a], v2[a]));
    }
    return fr_pbounds_cull_box(b, FR_CULL_IA, lo, hi);
  }
  const float *const src[3] = {v0, v1, v2};
  if (tri_outside_planes(b, src)) return 1;
  if (c != FR_CULL_CORNERS) return 0;
  double V[3][3], mag = 0.0;
  for (int i = 0; i < 3; i++)
    for (int a = 0; a < 3; a++) {
      V[i][a] = src[i][a];
      mag = dmax(mag, fabs(V[i][a]));
    }
  double tol = SLACK * (b->scale + mag);
  double e1[3], e2[3], n[3];
  for (int a = 0; a < 3; a++) { e1[a] = V[1][a] - V[0][a]; e2[a] = V[2][a] - V[0][a]; }
  cross3d(e1, e2, n);
  if (n[0] == 0.0 && n[1] == 0.0 && n[2] == 0.0) return 0; /* degenerate: never hit anyway, not our call */
  if (volume_off_plane(b, V[0], n, tol * norm1(n))) return 1;
  /* the edge test pays only with a shared origin: 4 lines then, not 16
   * (measured: 16 lines cost more than the 16-ray tests they save) */
  return b->shared_origin && lines_outside_edge(b, V, n);
}

/* ---- spheres ----------------------------------------------------------------- */

int fr_pbounds_cull_sphere(const fr_pbounds *b, fr_cull c, const float centre[3], float radius) {
  if (b->empty) return 1;
  if (c == FR_CULL_OFF) return 0;
  double C[3] = {centre[0], centre[1], centre[2]}, r = fabs((double)radius), lo[3], hi[3], mag = 0.0;
  for (int a = 0; a < 3; a++) {
    lo[a] = C[a] - r;
    hi[a] = C[a] + r;
    mag = dmax(mag, fabs(C[a]) + r);
  }
  if (c == FR_CULL_IA || !b->has_planes) return cull_box_d(b, FR_CULL_IA, lo, hi);
  double tol = SLACK * (b->scale + mag);
  kuv p = to_kuv(b, C);
  double dK = p.K - b->knear;
  if (dK < -r - tol || p.K > b->kfar + r + tol) return 1;
  /* distance from the centre to each side plane, in the (K, u) or (K, v) plane */
  double R = r + tol;
  return p.u - b->uhi - b->suhi * dK > R * sqrt(1.0 + b->suhi * b->suhi) ||
         b->ulo + b->sulo * dK - p.u > R * sqrt(1.0 + b->sulo * b->sulo) ||
         p.v - b->vhi - b->svhi * dK > R * sqrt(1.0 + b->svhi * b->svhi) ||
         b->vlo + b->svlo * dK - p.v > R * sqrt(1.0 + b->svlo * b->svlo);
}
