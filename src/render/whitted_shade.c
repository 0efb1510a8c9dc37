/*
 * Whitted shading of 16 hits (see whitted_shade.h), compiled once per ISA.
 * The operations and their order are those of the scalar formulas written
 * next to them, so every level, lane by lane, gives the same bits; only the
 * Phong highlight's powf runs lane by lane.
 */
#include <math.h>
#include <stddef.h>
#include "base/simd_packet.h"
#include "render/whitted_shade.h"

typedef struct v3p { vpf x, y, z; } v3p;

FR_INLINE v3p v3p_splat(const float *a) { v3p r = {vp(a[0]), vp(a[1]), vp(a[2])}; return r; }
FR_INLINE vpf vp_neg(vpf a) { return vp_xor(a, vp(-0.0f)); }
FR_INLINE v3p v3p_add(v3p a, v3p b) { v3p r = {vp_add(a.x, b.x), vp_add(a.y, b.y), vp_add(a.z, b.z)}; return r; }
FR_INLINE v3p v3p_sub(v3p a, v3p b) { v3p r = {vp_sub(a.x, b.x), vp_sub(a.y, b.y), vp_sub(a.z, b.z)}; return r; }
FR_INLINE v3p v3p_mul(v3p a, v3p b) { v3p r = {vp_mul(a.x, b.x), vp_mul(a.y, b.y), vp_mul(a.z, b.z)}; return r; }
FR_INLINE v3p v3p_scale(v3p a, vpf s) { v3p r = {vp_mul(a.x, s), vp_mul(a.y, s), vp_mul(a.z, s)}; return r; }
FR_INLINE vpf v3p_dot(v3p a, v3p b) { return vp_add(vp_add(vp_mul(a.x, b.x), vp_mul(a.y, b.y)), vp_mul(a.z, b.z)); }
FR_INLINE vpf v3p_max3(v3p a) { return vp_max(a.x, vp_max(a.y, a.z)); }
FR_INLINE v3p v3p_select(vpm m, v3p a, v3p b) {
  v3p r = {vp_select(m, a.x, b.x), vp_select(m, a.y, b.y), vp_select(m, a.z, b.z)};
  return r;
}
FR_INLINE void v3p_store(float (*dst)[FR_WS_LANES], v3p a) { vp_store(dst[0], a.x); vp_store(dst[1], a.y); vp_store(dst[2], a.z); }
/* v3_norm: a / |a|, a itself when |a| is 0 */
FR_INLINE v3p v3p_norm(v3p a) {
  vpf l = vp_sqrt(v3p_dot(a, a));
  return v3p_select(vp_gt(l, vp(0.0f)), v3p_scale(a, vp_div(vp(1.0f), l)), a);
}
/* field f of each lane's material; when all lanes share one material (the
 * common case for 16 neighbouring rays) a broadcast rather than a gather */
typedef struct mat_lanes { const float *soa; size_t count; const int32_t *idx; int same; } mat_lanes;
FR_INLINE vpf mat_field(const mat_lanes *m, int f) {
  const float *field = m->soa + (size_t)f * m->count;
  return m->same ? vp(field[m->idx[0]]) : vp_gather(field, m->idx);
}
FR_INLINE v3p mat_field3(const mat_lanes *m, int f) {
  v3p r = {mat_field(m, f), mat_field(m, f + 1), mat_field(m, f + 2)};
  return r;
}

void FR_ISA_FN(fr_whitted_shade16)(const fr_wshade_in *in, fr_wshade_out *out) {
  enum { HIT = sizeof(fr_hit) / sizeof(float) };
  _Static_assert(sizeof(fr_hit) % sizeof(float) == 0, "whole floats");
  _Static_assert(sizeof(fr_ray) == 8 * sizeof(float) && offsetof(fr_ray, dir) == 4 * sizeof(float),
                 "a ray record: org, tnear, dir, tfar");
  _Static_assert(sizeof(fr_wpath) == 4 * sizeof(float) && sizeof(fr_surface) == 4 * sizeof(float),
                 "path and surface records of 4 floats");
  int32_t hi[FR_WS_LANES] __attribute__((aligned(64)));
  int32_t mi[FR_WS_LANES] __attribute__((aligned(64))); /* the gathers want aligned indices */
  const fr_ray *ray = in->ray;
  const fr_wpath *path = in->path;
  const fr_surface *surf = in->surf;
  fr_ray ray_pad[FR_WS_LANES];
  fr_wpath path_pad[FR_WS_LANES];
  fr_surface surf_pad[FR_WS_LANES];
  int first = __builtin_ctz(in->valid);
  if (in->valid != (1u << FR_WS_LANES) - 1u) { /* absent lanes copy a present one: whole records load below */
    for (int l = 0; l < FR_WS_LANES; l++) {
      int s = (in->valid >> l) & 1 ? l : first;
      ray_pad[l] = ray[s];
      path_pad[l] = path[s];
      surf_pad[l] = surf[s];
    }
    ray = ray_pad;
    path = path_pad;
    surf = surf_pad;
  }
  int same = 1;
  for (int l = 0; l < FR_WS_LANES; l++) {
    int s = (in->valid >> l) & 1 ? l : first;
    hi[l] = s * HIT; mi[l] = surf[l].mat;
    same &= mi[l] == mi[0];
  }
  const mat_lanes M = {in->mats, in->mat_count, mi, same};
  const float *hf = (const float *)in->hit;
  /* whole records, transposed */
  vpf rf[8], pf[4], sf[4];
  vp_load_records8((const float *)ray, rf);
  vp_load_records4((const float *)path, pf);
  vp_load_records4((const float *)surf, sf);
  v3p o = {rf[0], rf[1], rf[2]}, d = {rf[4], rf[5], rf[6]}, w = {pf[0], pf[1], pf[2]};
  vp_store((float *)out->pk, pf[3]);
  vpf t = vp_gather(hf + offsetof(fr_hit, t) / sizeof(float), hi);
  vpm hit = vpm_bits_to(in->hits);

  /* a miss sees the background, a hit the ambient term: w * (kd * AMBIENT) */
  v3p kd = mat_field3(&M, FR_WM_KD), ks = mat_field3(&M, FR_WM_KS);
  v3p amb = v3p_mul(w, v3p_scale(kd, vp(FR_WHITTED_AMBIENT)));
  v3p_store(out->add, v3p_select(hit, amb, v3p_scale(w, vp(FR_WHITTED_BACKGROUND))));
  out->shadow = out->refl = out->refr = 0;
  if (!in->hits) return;

  v3p p = v3p_add(o, v3p_scale(d, t));
  v3p_store(out->p, p);
  v3p ng = v3p_norm((v3p){sf[0], sf[1], sf[2]});
  vpm entering = vp_lt(v3p_dot(ng, d), vp(0.0f));
  v3p nf = v3p_select(entering, ng, v3p_scale(ng, vp(-1.0f)));

  /* direct light: a shadow ray wherever the surface has a colour of its own */
  v3p to = v3p_sub(v3p_splat(in->light), p);
  vpf dist = vp_sqrt(v3p_dot(to, to));
  v3p l = v3p_scale(to, vp_div(vp(1.0f), dist));
  vpf ndl = v3p_dot(nf, l);
  vpm lights = vpm_and(vpm_and(hit, vp_gt(mat_field(&M, FR_WM_LIGHTS), vp(0.0f))),
                       vpm_and(vp_gt(ndl, vp(0.0f)), vp_gt(dist, vp(0.0f))));
  out->shadow = vpm_bits(lights);
  if (out->shadow) {
    v3p lit = v3p_scale(kd, ndl);
    /* Phong: r = nf * (2 ndl) - l, highlight ks * (-r.d)^ns where positive */
    v3p r = v3p_sub(v3p_scale(nf, vp_mul(vp(2.0f), ndl)), l);
    vpf rv = vp_neg(v3p_dot(r, d));
    unsigned phong = vpm_bits(vpm_and(lights, vpm_and(vp_gt(mat_field(&M, FR_WM_PHONG), vp(0.0f)), vp_gt(rv, vp(0.0f)))));
    if (phong) {
      float rvs[FR_WS_LANES] __attribute__((aligned(64))), ns[FR_WS_LANES] __attribute__((aligned(64)));
      float hl[FR_WS_LANES] __attribute__((aligned(64))) = {0};
      vp_store(rvs, rv);
      vp_store(ns, mat_field(&M, FR_WM_NS));
      for (unsigned m = phong; m; m &= m - 1) {
        int i = __builtin_ctz(m);
        hl[i] = powf(rvs[i], ns[i]);
      }
      vpm ph = vpm_bits_to(phong);
      lit = v3p_select(ph, v3p_add(lit, v3p_scale(ks, vp_load(hl))), lit);
    }
    v3p_store(out->l, l);
    vp_store(out->ldist, dist);
    v3p_store(out->lw, v3p_mul(w, lit));
  }
  if (!in->bounce) return;
  vpm bounces = vpm_and(hit, vp_gt(mat_field(&M, FR_WM_BOUNCES), vp(0.0f)));
  if (!vpm_bits(bounces)) return;

  /* mirror reflection, and for glass Fresnel's split between reflection and refraction */
  vpf cosi = vp_neg(v3p_dot(d, nf));
  v3p refl = v3p_add(d, v3p_scale(nf, vp_mul(vp(2.0f), cosi)));
  v3p wr = v3p_mul(w, ks), wt = {vp(0.0f), vp(0.0f), vp(0.0f)}, tdir = wt;
  vpm glass = vpm_and(bounces, vp_gt(mat_field(&M, FR_WM_GLASS), vp(0.0f)));
  if (vpm_bits(glass)) {
    vpf ior = mat_field(&M, FR_WM_IOR);
    vpf eta = vp_select(entering, vp_div(vp(1.0f), ior), ior);
    /* k = 1 - eta^2 (1 - cosi^2); k <= 0: total internal reflection, F = 1 */
    vpf k = vp_sub(vp(1.0f), vp_mul(vp_mul(eta, eta), vp_sub(vp(1.0f), vp_mul(cosi, cosi))));
    vpm tir = vp_le(k, vp(0.0f));
    vpf cost = vp_select(tir, vp(0.0f), vp_sqrt(vp_max(k, vp(0.0f))));
    vpf ec = vp_mul(eta, cosi), et = vp_mul(eta, cost);
    vpf rs = vp_div(vp_sub(ec, cost), vp_add(ec, cost)), rp = vp_div(vp_sub(et, cosi), vp_add(et, cosi));
    vpf F = vp_select(tir, vp(1.0f), vp_mul(vp(0.5f), vp_add(vp_mul(rs, rs), vp_mul(rp, rp))));
    wr = v3p_select(glass, v3p_scale(w, F), wr);
    wt = v3p_select(glass, v3p_scale(v3p_mul(w, mat_field3(&M, FR_WM_KT)), vp_sub(vp(1.0f), F)), wt);
    tdir = v3p_add(v3p_scale(d, eta), v3p_scale(nf, vp_sub(ec, cost)));
  }
  out->refl = vpm_bits(vpm_and(bounces, vp_gt(v3p_max3(wr), vp(FR_WHITTED_MIN_WEIGHT))));
  out->refr = vpm_bits(vpm_and(glass, vp_gt(v3p_max3(wt), vp(FR_WHITTED_MIN_WEIGHT))));
  v3p_store(out->rd, refl);
  v3p_store(out->rw, wr);
  if (out->refr) {
    v3p_store(out->td, v3p_norm(tdir));
    v3p_store(out->tw, wt);
  }
}

/* Lanes `mask` of the 16 records just stored at r[0..16), p[0..16) moved
 * down to r[0..popcount), in lane order. */
static void compact(fr_ray *r, fr_wpath *p, unsigned mask) {
  if (mask == (1u << FR_WS_LANES) - 1u) return;
  for (size_t j = 0; mask; mask &= mask - 1, j++) {
    int l = __builtin_ctz(mask);
    r[j] = r[l];
    p[j] = p[l];
  }
}

/* Appends lanes `mask` of rays (org, tnear, dir, tfar) carrying (w, pk) to k:
 * all 16 records stored at once (two transposes), then the absent ones
 * squeezed out. */
static void emit(fr_wsink *k, unsigned mask, v3p org, vpf tnear, v3p dir, vpf tfar, v3p w, const uint32_t *pk) {
  if (!mask) return;
  vpf rec[8] = {org.x, org.y, org.z, tnear, dir.x, dir.y, dir.z, tfar};
  vpf path[4] = {w.x, w.y, w.z, vp_load((const float *)pk)};
  vp_store_records((float *)(k->r + k->n), rec, 8);
  vp_store_records4((float *)(k->p + k->n), path);
  compact(k->r + k->n, k->p + k->n, mask);
  k->n += (size_t)__builtin_popcount(mask);
}

FR_INLINE v3p v3p_load(const float (*a)[FR_WS_LANES]) {
  v3p r = {vp_load(a[0]), vp_load(a[1]), vp_load(a[2])};
  return r;
}

void FR_ISA_FN(fr_whitted_emit16)(const fr_wshade_out *out, const float light[3], float eps, fr_wsink *shadow,
                                  fr_wsink *next) {
  uint32_t pk[FR_WS_LANES] __attribute__((aligned(64)));
  if (out->shadow) {
    /* shadow rays carry key / 2: their block's packet */
    for (int l = 0; l < FR_WS_LANES; l++) pk[l] = (out->pk[l] & 0xFFFFu) | ((out->pk[l] >> 17) << 16);
    vpf dist = vp_load(out->ldist);
    v3p l = v3p_load(out->l);
    v3p from = {vp_neg(l.x), vp_neg(l.y), vp_neg(l.z)};
    emit(shadow, out->shadow, v3p_splat(light), vp_mul(dist, vp(1e-4f)), from, vp_sub(dist, vp(eps)),
         v3p_load(out->lw), pk);
  }
  if (!(out->refl | out->refr)) return;
  v3p p = v3p_load(out->p);
  if (out->refl) {
    for (int l = 0; l < FR_WS_LANES; l++) pk[l] = out->pk[l] & ~(1u << 16); /* key & ~1 */
    emit(next, out->refl, p, vp(eps), v3p_load(out->rd), vp(INFINITY), v3p_load(out->rw), pk);
  }
  if (out->refr) {
    for (int l = 0; l < FR_WS_LANES; l++) pk[l] = out->pk[l] | (1u << 16); /* key | 1 */
    emit(next, out->refr, p, vp(eps), v3p_load(out->td), vp(INFINITY), v3p_load(out->tw), pk);
  }
}
