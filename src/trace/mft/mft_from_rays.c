/*
 * Frusta around given rays: 16 frusta of 16 rays each from up to 256 rays
 * (ray k of frustum f = rays[16 f + k]), for rays that come from a renderer
 * rather than from a camera or a light's sample sets; Whitted's point-light
 * shadow rays, traced from the light, are the case it is made for.
 *
 * The kernels (mft_traverse.c) want ray k of a frustum as s + delta_k, and
 * its 2D parameters (a_k, b_k) such that the ray points along
 * s + a_k e1 + b_k e2; the corner rays are the corners of the (a, b) box.
 * Here every ray's direction is scaled to end at t = 1 (dir tfar), s lies
 * along N = e1 x e2 with e1, e2 across the batch's mean direction, and
 * (a_k, b_k) is where the ray's line crosses the plane {s + a e1 + b e2}. s
 * is far enough along N that every ray crosses that plane by t = 1, which is
 * what the kernels' plane cull assumes of a ray ending at tfar = 1. The
 * (a, b) come from the direction the kernels will trace, s + delta_k as
 * rounded, so the corner rays bound exactly the rays traced, and the box
 * gets a margin far above the rounding of a and b.
 *
 * One frustum per 16-wide pass; compiled once per ISA. So are the segments
 * from a light to points (fr_mft_rays_to_points), 16 at a time.
 */
#include <math.h>
#include <string.h>
#include "base/simd.h"
#include "base/simd_packet.h"
#include "base/vec3.h"
#include "trace/mft/mft.h"

#if P != 16
#error "a frustum is 16 rays, one per lane"
#endif
_Static_assert(sizeof(fr_ray) == 8 * sizeof(float), "rays are records of 8 floats");

/* Smallest cosine between a ray and the batch's axis: wider frusta cull
 * little, and past 90 degrees there is no plane to project onto. */
#define MIN_AXIS_COS 0.25f
/* How much the (a, b) box grows beyond its rays', relative to its size: far
 * above the float rounding of a and b (a few 2^-24), far below what changes
 * a cull. */
#define BOX_PAD 0x1p-16f

/* The batch's frame, in float: e1, e2 and N = e1 x e2. */
typedef struct frame { float e1[3], e2[3], N[3], nn; } frame;

FR_INLINE vpf dot3v(const vpf a[3], const float b[3]) {
  return vp_add(vp_add(vp_mul(a[0], vp(b[0])), vp_mul(a[1], vp(b[1]))), vp_mul(a[2], vp(b[2])));
}

/* 256 rays as lanes: field k (org x y z, tnear, dir x y z, tfar) of ray i
 * in f[k][i]; a last, partial frustum repeats its last ray. */
typedef struct ray_lanes {
  float f[8][FR_MFT_FRUSTA * FR_MFT_RAYS] __attribute__((aligned(64)));
} ray_lanes;

/* Frustum f from its 16 rays x (fields as ray_lanes', origin org the
 * first's); returns 0 where they make none. */
static int frustum_of(fr_mft_batch *b, fr_mft_set *S, int f, const vpf x[8], const float org[3], const frame *F) {
  const vpf zero = vp(0.0f), inf = vp(INFINITY);
  /* one origin, finite values, 0 <= tnear <= tfar < inf, tfar > 0 */
  unsigned ok = vpm_bits(vpm_and(vp_eq(x[0], vp(org[0])), vpm_and(vp_eq(x[1], vp(org[1])), vp_eq(x[2], vp(org[2])))));
  ok &= vpm_bits(vpm_and(vp_lt(vp_abs(x[0]), inf), vpm_and(vp_lt(vp_abs(x[1]), inf), vp_lt(vp_abs(x[2]), inf))));
  ok &= vpm_bits(vpm_and(vp_ge(x[3], zero), vpm_and(vp_le(x[3], x[7]), vpm_and(vp_gt(x[7], zero), vp_lt(x[7], inf)))));
  vpf d[3] = {vp_mul(x[4], x[7]), vp_mul(x[5], x[7]), vp_mul(x[6], x[7])};
  vpf p = dot3v(d, F->N), dd = vp_add(vp_add(vp_mul(d[0], d[0]), vp_mul(d[1], d[1])), vp_mul(d[2], d[2]));
  /* p > 0 and p^2 >= cos^2 |d|^2 |N|^2 (false for NaN and infinite directions) */
  ok &= vpm_bits(vpm_and(vp_gt(p, zero), vp_ge(vp_mul(p, p), vp_mul(dd, vp(MIN_AXIS_COS * MIN_AXIS_COS * F->nn)))));
  ok &= vpm_bits(vp_lt(dd, inf));
  if (ok != 0xFFFFu) return 0;
  /* s: N scaled to past every ray's crossing, with room for rounding */
  const float lam = vp_reduce_max(p) * (1.0f + 0x1p-12f) / F->nn;
  const float s[3] = {F->N[0] * lam, F->N[1] * lam, F->N[2] * lam};
  const float sn = s[0] * F->N[0] + s[1] * F->N[1] + s[2] * F->N[2];
  const float se1 = s[0] * F->e1[0] + s[1] * F->e1[1] + s[2] * F->e1[2];
  const float se2 = s[0] * F->e2[0] + s[1] * F->e2[1] + s[2] * F->e2[2];
  vpf delta[3], dt[3];
  float *dl[3] = {S->dx, S->dy, S->dz};
  for (int a = 0; a < 3; a++) {
    delta[a] = vp_sub(d[a], vp(s[a]));
    vp_store(dl[a], delta[a]);
    dt[a] = vp_add(vp(s[a]), delta[a]); /* the direction traced */
    S->lo[a] = vp_reduce_min(delta[a]);
    S->hi[a] = vp_reduce_max(delta[a]);
  }
  vpf pt = dot3v(dt, F->N);
  if (vpm_bits(vpm_and(vp_gt(pt, zero), vp_le(pt, vp(sn * (1.0f - 0x1p-20f))))) != 0xFFFFu) return 0;
  vpf scale = vp_div(vp(sn), pt);
  vpf va = vp_sub(vp_mul(dot3v(dt, F->e1), scale), vp(se1));
  vpf vb = vp_sub(vp_mul(dot3v(dt, F->e2), scale), vp(se2));
  vp_store(S->a, va);
  vp_store(S->b, vb);
  S->amin = vp_reduce_min(va); S->amax = vp_reduce_max(va);
  S->bmin = vp_reduce_min(vb); S->bmax = vp_reduce_max(vb);
  /* fr_maxf compiles to maxss, fmaxf to a call (NaN rules) */
  float big = fr_maxf(fr_maxf(fabsf(S->amin), fabsf(S->amax)), fr_maxf(fabsf(S->bmin), fabsf(S->bmax)));
  const float pad = BOX_PAD * (big + sqrtf(sn * lam));
  if (!(pad < INFINITY)) return 0;
  S->amin -= pad; S->amax += pad; S->bmin -= pad; S->bmax += pad;
  for (int a = 0; a < 3; a++) {
    b->org[a][f] = org[a];
    b->start[a][f] = s[a];
  }
  b->tnear[f] = vp_reduce_min(vp_div(x[3], x[7]));
  b->tfar[f] = 1.0f;
  b->set[f] = (uint8_t)f;
  return 1;
}

static void cross_d(const double a[3], const double b[3], double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

/* The segments from light to points[0..m) (m <= 16) as 16 lanes of ray
 * fields (ray_lanes'): unit direction, tnear 1e-4 of the way (for a light
 * on a surface), tfar eps short of the point; an empty ray (all zero but
 * the origin) where that leaves nothing or the point is not finite; lanes
 * past m repeat the last point. The same rounded operations in every lane,
 * so every ISA gives the same bits. */
static void point_lanes(const float light[3], const float *points, size_t m, float eps, vpf f[8]) {
  const vpf zero = vp(0.0f);
  vpf d[3];
  if (m == FR_MFT_RAYS) {
    vp_load_xyz(points, d);
  } else {
    float pad[3 * FR_MFT_RAYS];
    for (size_t k = 0; k < FR_MFT_RAYS; k++)
      for (int a = 0; a < 3; a++) pad[3 * k + (size_t)a] = points[3 * (k < m ? k : m - 1) + (size_t)a];
    vp_load_xyz(pad, d);
  }
  for (int a = 0; a < 3; a++) d[a] = vp_sub(d[a], vp(light[a]));
  const vpf dist = vp_sqrt(vp_add(vp_add(vp_mul(d[0], d[0]), vp_mul(d[1], d[1])), vp_mul(d[2], d[2])));
  const vpf tnear = vp_mul(vp(1e-4f), dist), tfar = vp_sub(dist, vp(eps));
  const vpm keep = vp_gt(tfar, tnear);
  for (int a = 0; a < 3; a++) {
    f[a] = vp(light[a]);
    f[4 + a] = vp_select(keep, vp_div(d[a], dist), zero);
  }
  f[3] = vp_select(keep, tnear, zero);
  f[7] = vp_select(keep, tfar, zero);
}

/* Frusta from n <= 256 rays as lanes (fr_mft_fns.from_rays). */
static unsigned frusta_of_lanes(fr_mft_batch *b, fr_mft_sets *t, const ray_lanes *L, size_t n) {
  memset(b, 0, sizeof *b);
  /* The axis: the mean direction (unit directions, for the renderers' rays).
   * Sixteen running sums, ray i in sum i % 16, then those in double in lane
   * order: the same additions on every ISA, so the same frusta, at a tenth
   * of the time of a scalar sum in double (which was 2% of museum's Whitted
   * frame). A non-finite direction is left out: one NaN spoils no batch. */
  float sum[3][FR_MFT_RAYS] __attribute__((aligned(64)));
  {
    vpf acc[3] = {vp(0.0f), vp(0.0f), vp(0.0f)};
    const vpf inf = vp(INFINITY);
    for (size_t i = 0; i < n; i += FR_MFT_RAYS) {
      const unsigned in = n - i >= FR_MFT_RAYS ? 0xFFFFu : (1u << (n - i)) - 1u;
      vpf d[3];
      for (int a = 0; a < 3; a++) d[a] = vp_load(L->f[4 + a] + i);
      vpm fin = vpm_and(vp_lt(vp_abs(d[0]), inf), vpm_and(vp_lt(vp_abs(d[1]), inf), vp_lt(vp_abs(d[2]), inf)));
      fin = vpm_and(fin, vpm_bits_to(in));
      for (int a = 0; a < 3; a++) acc[a] = vp_add(acc[a], vp_select(fin, d[a], vp(0.0f)));
    }
    for (int a = 0; a < 3; a++) vp_store(sum[a], acc[a]);
  }
  double m[3] = {0.0, 0.0, 0.0};
  for (int a = 0; a < 3; a++)
    for (int k = 0; k < FR_MFT_RAYS; k++) m[a] += sum[a][k];
  double ml = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  int ok_axis = ml > 0.0 && ml < INFINITY;
  frame F = {{0.0f}, {0.0f}, {0.0f}, 0.0f}; /* set where ok_axis */
  if (ok_axis) {
    for (int a = 0; a < 3; a++) m[a] /= ml;
    /* e1, e2 across it, orthonormal in double and rounded once */
    const double h[3] = {fabs(m[0]) < 0.6 ? 1.0 : 0.0, fabs(m[0]) < 0.6 ? 0.0 : 1.0, 0.0};
    double u[3], v[3], e1[3], e2[3], N[3];
    cross_d(m, h, u);
    double ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int a = 0; a < 3; a++) u[a] /= ul;
    cross_d(m, u, v);
    for (int a = 0; a < 3; a++) {
      F.e1[a] = t->e1[a] = (float)u[a];
      F.e2[a] = t->e2[a] = (float)v[a];
      e1[a] = F.e1[a];
      e2[a] = F.e2[a];
    }
    cross_d(e1, e2, N); /* of e1 and e2 as rounded */
    for (int a = 0; a < 3; a++) F.N[a] = (float)N[a];
    F.nn = F.N[0] * F.N[0] + F.N[1] * F.N[1] + F.N[2] * F.N[2];
  }
  t->count = FR_MFT_SETS;
  for (int f = 0; f < FR_MFT_FRUSTA; f++) {
    const size_t first = (size_t)f * FR_MFT_RAYS;
    const size_t cnt = first >= n ? 0 : n - first < FR_MFT_RAYS ? n - first : FR_MFT_RAYS;
    int made = 0;
    if (ok_axis && cnt) {
      vpf x[8];
      float org[3];
      for (int k = 0; k < 8; k++) x[k] = vp_load(L->f[k] + first);
      for (int a = 0; a < 3; a++) org[a] = L->f[a][first];
      made = frustum_of(b, &t->set[f], f, x, org, &F);
    }
    if (made) b->valid |= 1u << f;
    else memset(&t->set[f], 0, sizeof t->set[f]); /* what the kernels read of a frustum left out */
  }
  return b->valid;
}

unsigned FR_ISA_FN(fr_mft_from_rays)(fr_mft_batch *b, fr_mft_sets *t, const fr_ray *rays, size_t n) {
  if (n > FR_MFT_FRUSTA * FR_MFT_RAYS) n = FR_MFT_FRUSTA * FR_MFT_RAYS;
  ray_lanes L;
  for (size_t i = 0; i < n; i += FR_MFT_RAYS) {
    const size_t m = n - i < FR_MFT_RAYS ? n - i : FR_MFT_RAYS;
    vpf x[8];
    if (m == FR_MFT_RAYS) {
      vp_load_records8((const float *)(rays + i), x);
    } else {
      fr_ray pad[FR_MFT_RAYS]; /* a partial frustum repeats its last ray */
      for (size_t k = 0; k < FR_MFT_RAYS; k++) pad[k] = rays[i + (k < m ? k : m - 1)];
      vp_load_records8((const float *)pad, x);
    }
    for (int k = 0; k < 8; k++) vp_store(L.f[k] + i, x[k]);
  }
  return frusta_of_lanes(b, t, &L, n);
}

unsigned FR_ISA_FN(fr_mft_from_points)(fr_mft_batch *b, fr_mft_sets *t, const float light[3], const float *points,
                                       size_t n, float eps) {
  if (n > FR_MFT_FRUSTA * FR_MFT_RAYS) n = FR_MFT_FRUSTA * FR_MFT_RAYS;
  ray_lanes L;
  for (size_t i = 0; i < n; i += FR_MFT_RAYS) {
    vpf x[8];
    point_lanes(light, points + 3 * i, n - i < FR_MFT_RAYS ? n - i : FR_MFT_RAYS, eps, x);
    for (int k = 0; k < 8; k++) vp_store(L.f[k] + i, x[k]);
  }
  return frusta_of_lanes(b, t, &L, n);
}

void FR_ISA_FN(fr_mft_rays_to_points)(const float light[3], const float *points, size_t n, float eps, fr_ray *rays) {
  for (size_t j = 0; j < n; j += FR_MFT_RAYS) {
    const size_t m = n - j < FR_MFT_RAYS ? n - j : FR_MFT_RAYS;
    vpf f[8];
    point_lanes(light, points + 3 * j, m, eps, f);
    if (m == FR_MFT_RAYS) {
      vp_store_records((float *)(rays + j), f, 8);
    } else {
      fr_ray part[FR_MFT_RAYS];
      vp_store_records((float *)part, f, 8);
      memcpy(rays + j, part, m * sizeof *part);
    }
  }
}
