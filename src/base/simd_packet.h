/*
 * Packet-wide SIMD: vpf holds one float per ray of a packet of FR_PACKET = 8
 * or 16 rays, vpm a mask over them. Include after base/simd.h.
 *
 *   AVX-512  16 lanes in one zmm (8 in one ymm), masks in k registers
 *   AVX2     8 lanes in one ymm; 16 lanes as two 8-wide halves
 *   scalar   a loop over the lanes
 *
 * As in base/simd.h: no FMA contraction, min/max return the second operand
 * on NaN, compares are ordered (NaN is false), so every level gives the same
 * bits.
 */
#ifndef FR_BASE_SIMD_PACKET_H
#define FR_BASE_SIMD_PACKET_H
#include "base/simd.h"
#include <math.h>
#include <stdint.h>
#include <string.h>

#ifndef FR_PACKET
#error "define FR_PACKET (8 or 16)"
#endif
#define P FR_PACKET
#define FR_PACKET_ALL ((unsigned)((1u << P) - 1u))

#if defined(FR_BUILD_ISA_AVX512)
/* one register of P lanes (zmm for 16, ymm for 8), masks in k registers */
#if P == 16
#define FR_VP_OP(op) _mm512_##op
typedef __m512 fr_vp_reg;
typedef __mmask16 fr_vp_kmask;
#else
#define FR_VP_OP(op) _mm256_##op
typedef __m256 fr_vp_reg;
typedef __mmask8 fr_vp_kmask;
#endif
typedef struct vpf { fr_vp_reg v; } vpf;
typedef struct vpm { fr_vp_kmask m; } vpm;
FR_INLINE vpf vp(float a) { vpf r = {FR_VP_OP(set1_ps)(a)}; return r; }
FR_INLINE vpf vp_load(const float *p) { vpf r = {FR_VP_OP(load_ps)(p)}; return r; }
FR_INLINE vpf vp_loadu(const float *p) { vpf r = {FR_VP_OP(loadu_ps)(p)}; return r; }
FR_INLINE void vp_store(float *p, vpf a) { FR_VP_OP(store_ps)(p, a.v); }
/* P 16-bit integers as floats (exact) */
#if P == 16
FR_INLINE vpf vp_loadu_i16(const int16_t *p) { vpf r = {_mm512_cvtepi32_ps(_mm512_cvtepi16_epi32(_mm256_loadu_si256((const __m256i *)p)))}; return r; }
#else
FR_INLINE vpf vp_loadu_i16(const int16_t *p) { vpf r = {_mm256_cvtepi32_ps(_mm256_cvtepi16_epi32(_mm_loadu_si128((const __m128i *)p)))}; return r; }
#endif
#define FR_VP_BIN(name, op) FR_INLINE vpf name(vpf a, vpf b) { vpf r = {FR_VP_OP(op)(a.v, b.v)}; return r; }
FR_VP_BIN(vp_add, add_ps) FR_VP_BIN(vp_sub, sub_ps) FR_VP_BIN(vp_mul, mul_ps)
FR_VP_BIN(vp_div, div_ps) FR_VP_BIN(vp_min, min_ps) FR_VP_BIN(vp_max, max_ps)
FR_VP_BIN(vp_and, and_ps) FR_VP_BIN(vp_or, or_ps) FR_VP_BIN(vp_xor, xor_ps)
#define FR_VP_CMP(name, op) FR_INLINE vpm name(vpf a, vpf b) { vpm r = {FR_VP_OP(cmp_ps_mask)(a.v, b.v, op)}; return r; }
FR_INLINE vpm vpm_bits_to(unsigned b) { vpm r = {(fr_vp_kmask)b}; return r; }
FR_INLINE unsigned vpm_bits(vpm a) { return a.m; }
FR_INLINE vpm vpm_and(vpm a, vpm b) { vpm r = {(fr_vp_kmask)(a.m & b.m)}; return r; }
FR_INLINE vpf vp_select(vpm m, vpf t, vpf f) { vpf r = {FR_VP_OP(mask_blend_ps)(m.m, f.v, t.v)}; return r; }
FR_INLINE vpf vp_sqrt(vpf a) { vpf r = {FR_VP_OP(sqrt_ps)(a.v)}; return r; }
#if P == 16
/* min and max of the bit patterns as integers (see vf4_imin in base/simd.h) */
FR_INLINE vpf vp_imin(vpf a, vpf b) { vpf r = {_mm512_castsi512_ps(_mm512_min_epi32(_mm512_castps_si512(a.v), _mm512_castps_si512(b.v)))}; return r; }
FR_INLINE vpf vp_imax(vpf a, vpf b) { vpf r = {_mm512_castsi512_ps(_mm512_max_epi32(_mm512_castps_si512(a.v), _mm512_castps_si512(b.v)))}; return r; }
FR_INLINE float vp_reduce_min(vpf a) { return _mm512_reduce_min_ps(a.v); }
FR_INLINE float vp_reduce_max(vpf a) { return _mm512_reduce_max_ps(a.v); }
#else
FR_INLINE vpf vp_imin(vpf a, vpf b) { vpf r = {_mm256_castsi256_ps(_mm256_min_epi32(_mm256_castps_si256(a.v), _mm256_castps_si256(b.v)))}; return r; }
FR_INLINE vpf vp_imax(vpf a, vpf b) { vpf r = {_mm256_castsi256_ps(_mm256_max_epi32(_mm256_castps_si256(a.v), _mm256_castps_si256(b.v)))}; return r; }
#endif

#elif defined(FR_BUILD_ISA_AVX2)
/* AVX2: P / 8 halves of 8 lanes, masks as vectors of all-ones lanes */
#define FR_VP_HALVES (P / 8)
typedef struct vpf { __m256 v[FR_VP_HALVES]; } vpf;
typedef struct vpm { __m256 m[FR_VP_HALVES]; } vpm;
FR_INLINE vpf vp(float a) { vpf r; for (int h = 0; h < FR_VP_HALVES; h++) r.v[h] = _mm256_set1_ps(a); return r; }
FR_INLINE vpf vp_load(const float *p) { vpf r; for (int h = 0; h < FR_VP_HALVES; h++) r.v[h] = _mm256_load_ps(p + 8 * h); return r; }
FR_INLINE void vp_store(float *p, vpf a) { for (int h = 0; h < FR_VP_HALVES; h++) _mm256_store_ps(p + 8 * h, a.v[h]); }
#define FR_VP_BIN(name, in) FR_INLINE vpf name(vpf a, vpf b) { vpf r; for (int h = 0; h < FR_VP_HALVES; h++) r.v[h] = in(a.v[h], b.v[h]); return r; }
FR_VP_BIN(vp_add, _mm256_add_ps) FR_VP_BIN(vp_sub, _mm256_sub_ps) FR_VP_BIN(vp_mul, _mm256_mul_ps)
FR_VP_BIN(vp_div, _mm256_div_ps) FR_VP_BIN(vp_min, _mm256_min_ps) FR_VP_BIN(vp_max, _mm256_max_ps)
#define FR_VP_CMP(name, op) FR_INLINE vpm name(vpf a, vpf b) { vpm r; for (int h = 0; h < FR_VP_HALVES; h++) r.m[h] = _mm256_cmp_ps(a.v[h], b.v[h], op); return r; }
FR_INLINE unsigned vpm_bits(vpm a) {
  unsigned b = 0;
  for (int h = 0; h < FR_VP_HALVES; h++) b |= (unsigned)_mm256_movemask_ps(a.m[h]) << (8 * h);
  return b;
}
FR_INLINE vpm vpm_bits_to(unsigned b) {
  const __m256i sel = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  vpm r;
  for (int h = 0; h < FR_VP_HALVES; h++) {
    __m256i x = _mm256_and_si256(_mm256_set1_epi32((int)((b >> (8 * h)) & 0xFF)), sel);
    r.m[h] = _mm256_castsi256_ps(_mm256_cmpeq_epi32(x, sel));
  }
  return r;
}
FR_INLINE vpf vp_select(vpm m, vpf t, vpf f) { vpf r; for (int h = 0; h < FR_VP_HALVES; h++) r.v[h] = _mm256_blendv_ps(f.v[h], t.v[h], m.m[h]); return r; }
FR_INLINE vpm vpm_and(vpm a, vpm b) { vpm r; for (int h = 0; h < FR_VP_HALVES; h++) r.m[h] = _mm256_and_ps(a.m[h], b.m[h]); return r; }
FR_VP_BIN(vp_and, _mm256_and_ps) FR_VP_BIN(vp_or, _mm256_or_ps) FR_VP_BIN(vp_xor, _mm256_xor_ps)
FR_INLINE vpf vp_loadu(const float *p) { vpf r; for (int h = 0; h < FR_VP_HALVES; h++) r.v[h] = _mm256_loadu_ps(p + 8 * h); return r; }
FR_INLINE vpf vp_loadu_i16(const int16_t *p) {
  vpf r;
  for (int h = 0; h < FR_VP_HALVES; h++) r.v[h] = _mm256_cvtepi32_ps(_mm256_cvtepi16_epi32(_mm_loadu_si128((const __m128i *)(p + 8 * h))));
  return r;
}
FR_INLINE vpf vp_sqrt(vpf a) { vpf r; for (int h = 0; h < FR_VP_HALVES; h++) r.v[h] = _mm256_sqrt_ps(a.v[h]); return r; }
#define FR_VP_IBIN(name, op) \
  FR_INLINE vpf name(vpf a, vpf b) { vpf r; for (int h = 0; h < FR_VP_HALVES; h++) r.v[h] = _mm256_castsi256_ps(op(_mm256_castps_si256(a.v[h]), _mm256_castps_si256(b.v[h]))); return r; }
FR_VP_IBIN(vp_imin, _mm256_min_epi32) FR_VP_IBIN(vp_imax, _mm256_max_epi32)

#else /* scalar */
typedef struct vpf { float f[P]; } vpf;
typedef struct vpm { unsigned m; } vpm;
#define FR_VP_LANES(expr) { vpf r; for (int i = 0; i < P; i++) r.f[i] = (expr); return r; }
FR_INLINE vpf vp(float a) FR_VP_LANES(a)
FR_INLINE vpf vp_load(const float *p) FR_VP_LANES(p[i])
FR_INLINE void vp_store(float *p, vpf a) { for (int i = 0; i < P; i++) p[i] = a.f[i]; }
#define FR_VP_BIN(name, expr) FR_INLINE vpf name(vpf a, vpf b) FR_VP_LANES(expr)
FR_VP_BIN(vp_add, a.f[i] + b.f[i]) FR_VP_BIN(vp_sub, a.f[i] - b.f[i]) FR_VP_BIN(vp_mul, a.f[i] * b.f[i])
FR_VP_BIN(vp_div, a.f[i] / b.f[i]) FR_VP_BIN(vp_min, a.f[i] < b.f[i] ? a.f[i] : b.f[i])
FR_VP_BIN(vp_max, a.f[i] > b.f[i] ? a.f[i] : b.f[i])
#define FR_CMP_LT_OQ(a, b) ((a) < (b))
#define FR_CMP_LE_OQ(a, b) ((a) <= (b))
#define FR_CMP_GT_OQ(a, b) ((a) > (b))
#define FR_CMP_GE_OQ(a, b) ((a) >= (b))
#define FR_CMP_EQ_OQ(a, b) ((a) == (b))
#define FR_VP_CMP(name, op) FR_INLINE vpm name(vpf a, vpf b) { vpm r = {0}; for (int i = 0; i < P; i++) r.m |= (unsigned)FR##op(a.f[i], b.f[i]) << i; return r; }
FR_INLINE vpm vpm_bits_to(unsigned b) { vpm r = {b}; return r; }
FR_INLINE unsigned vpm_bits(vpm a) { return a.m; }
FR_INLINE vpf vp_select(vpm m, vpf t, vpf f) FR_VP_LANES(((m.m >> i) & 1) ? t.f[i] : f.f[i])
FR_INLINE vpm vpm_and(vpm a, vpm b) { vpm r = {a.m & b.m}; return r; }
FR_INLINE float fr_vp_bits_and(float a, float b) {
  union { float f; uint32_t u; } x = {a}, y = {b};
  x.u &= y.u;
  return x.f;
}
FR_INLINE float fr_vp_bits_or(float a, float b) {
  union { float f; uint32_t u; } x = {a}, y = {b};
  x.u |= y.u;
  return x.f;
}
FR_INLINE float fr_vp_bits_xor(float a, float b) {
  union { float f; uint32_t u; } x = {a}, y = {b};
  x.u ^= y.u;
  return x.f;
}
FR_VP_BIN(vp_and, fr_vp_bits_and(a.f[i], b.f[i])) FR_VP_BIN(vp_or, fr_vp_bits_or(a.f[i], b.f[i]))
FR_VP_BIN(vp_xor, fr_vp_bits_xor(a.f[i], b.f[i]))
FR_INLINE vpf vp_loadu(const float *p) FR_VP_LANES(p[i])
FR_INLINE vpf vp_loadu_i16(const int16_t *p) FR_VP_LANES((float)p[i])
FR_INLINE vpf vp_sqrt(vpf a) FR_VP_LANES(sqrtf(a.f[i]))
FR_VP_BIN(vp_imin, fr_f2i(a.f[i]) < fr_f2i(b.f[i]) ? a.f[i] : b.f[i])
FR_VP_BIN(vp_imax, fr_f2i(a.f[i]) > fr_f2i(b.f[i]) ? a.f[i] : b.f[i])
FR_INLINE float vp_reduce_min(vpf a) { float r = a.f[0]; for (int i = 1; i < P; i++) r = a.f[i] < r ? a.f[i] : r; return r; }
FR_INLINE float vp_reduce_max(vpf a) { float r = a.f[0]; for (int i = 1; i < P; i++) r = a.f[i] > r ? a.f[i] : r; return r; }
#endif

/* a * b + c, fused where the level has FMA, a multiply and an add where
 * not. The one exception to "every level the same bits": only for bounds
 * that allow for the rounding of either form (the frusta's corner-ray
 * culls, whose guard covers the unfused form, which errs more). */
#if defined(FR_BUILD_ISA_AVX512)
FR_INLINE vpf vp_madd_bound(vpf a, vpf b, vpf c) { vpf r = {FR_VP_OP(fmadd_ps)(a.v, b.v, c.v)}; return r; }
#elif defined(FR_BUILD_ISA_AVX2)
FR_INLINE vpf vp_madd_bound(vpf a, vpf b, vpf c) {
  vpf r;
  for (int h = 0; h < FR_VP_HALVES; h++) r.v[h] = _mm256_fmadd_ps(a.v[h], b.v[h], c.v[h]);
  return r;
}
#else
FR_INLINE vpf vp_madd_bound(vpf a, vpf b, vpf c) { return vp_add(vp_mul(a, b), c); }
#endif

/* A triangle id as the bits of a float lane, and a packet's ids as both:
 * closest-hit kernels keep their hits' ids in a register, one select per
 * hit instead of a store per lane. */
FR_INLINE vpf vp_id(uint32_t id) {
  union { uint32_t u; float f; } c = {id};
  return vp(c.f);
}
typedef union { float f[P]; uint32_t u[P]; } __attribute__((aligned(64))) lane_ids;

/* (scalar: FR##op pastes to the FR_CMP_* macros above) */
FR_VP_CMP(vp_lt, _CMP_LT_OQ) FR_VP_CMP(vp_le, _CMP_LE_OQ) FR_VP_CMP(vp_gt, _CMP_GT_OQ)
FR_VP_CMP(vp_ge, _CMP_GE_OQ) FR_VP_CMP(vp_eq, _CMP_EQ_OQ)

/* bitwise on the float patterns: |a|, and b with a's sign */
FR_INLINE vpf vp_abs(vpf a) {
  union { uint32_t u; float f; } m = {0x7FFFFFFFu};
  return vp_and(a, vp(m.f));
}
FR_INLINE vpf vp_copysign(vpf mag, vpf sgn) { return vp_or(vp_abs(mag), vp_and(sgn, vp(-0.0f))); }

/* P points of 3 floats each at p (3 P floats, any alignment) as their x, y
 * and z lanes: with AVX-512 three loads and two permutes per coordinate,
 * elsewhere a loop. Plain moves, the same bits on every level. */
#if defined(FR_BUILD_ISA_AVX512) && P == 16
FR_INLINE void vp_load_xyz(const float *p, vpf xyz[3]) {
  /* coordinate c of point k is float 3 k + c: from the first two loads
   * where that is below 32, then from the third */
  static const int32_t from_ab[3][16] __attribute__((aligned(64))) = {
      {0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 0, 0, 0, 0, 0},
      {1, 4, 7, 10, 13, 16, 19, 22, 25, 28, 31, 0, 0, 0, 0, 0},
      {2, 5, 8, 11, 14, 17, 20, 23, 26, 29, 0, 0, 0, 0, 0, 0}};
  static const int32_t from_c[3][16] __attribute__((aligned(64))) = {
      {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 17, 20, 23, 26, 29},
      {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 18, 21, 24, 27, 30},
      {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 16, 19, 22, 25, 28, 31}};
  const __m512 a = _mm512_loadu_ps(p), b = _mm512_loadu_ps(p + 16), c = _mm512_loadu_ps(p + 32);
  for (int k = 0; k < 3; k++) {
    const __m512 ab = _mm512_permutex2var_ps(a, _mm512_load_si512((const void *)from_ab[k]), b);
    xyz[k].v = _mm512_permutex2var_ps(ab, _mm512_load_si512((const void *)from_c[k]), c);
  }
}
#else
FR_INLINE void vp_load_xyz(const float *p, vpf xyz[3]) {
  float t[3][P] __attribute__((aligned(64)));
  for (int k = 0; k < P; k++)
    for (int c = 0; c < 3; c++) t[c][k] = p[3 * k + c];
  for (int c = 0; c < 3; c++) xyz[c] = vp_load(t[c]);
}
#endif

/* Memory by lane: vp_gather reads base[idx[i]] (idx: P aligned int32, each a
 * valid index), vp_store_mask writes lane i of a to p[i] where bit i of mask is
 * set, vp_scatter writes it to base[idx[i]] (distinct indices). Plain moves,
 * so every level gives the same bits; uint32 fields pass through as float
 * bit patterns (memcpy in plain C, so no access breaks type aliasing). */
#if defined(FR_BUILD_ISA_AVX512)
#if P == 16
FR_INLINE vpf vp_gather(const float *base, const int32_t *idx) {
  vpf r = {_mm512_i32gather_ps(_mm512_load_si512((const void *)idx), base, 4)};
  return r;
}
FR_INLINE void vp_scatter(float *base, const int32_t *idx, unsigned mask, vpf a) {
  _mm512_mask_i32scatter_ps(base, (__mmask16)mask, _mm512_load_si512((const void *)idx), a.v, 4);
}
#else
FR_INLINE vpf vp_gather(const float *base, const int32_t *idx) {
  vpf r = {_mm256_i32gather_ps(base, _mm256_load_si256((const __m256i *)idx), 4)};
  return r;
}
FR_INLINE void vp_scatter(float *base, const int32_t *idx, unsigned mask, vpf a) {
  _mm256_mask_i32scatter_ps(base, (__mmask8)mask, _mm256_load_si256((const __m256i *)idx), a.v, 4);
}
#endif
FR_INLINE void vp_store_mask(float *p, unsigned mask, vpf a) { FR_VP_OP(mask_storeu_ps)(p, (fr_vp_kmask)mask, a.v); }
#elif defined(FR_BUILD_ISA_AVX2)
FR_INLINE vpf vp_gather(const float *base, const int32_t *idx) {
  vpf r;
  for (int h = 0; h < FR_VP_HALVES; h++) r.v[h] = _mm256_i32gather_ps(base, _mm256_load_si256((const __m256i *)(idx + 8 * h)), 4);
  return r;
}
FR_INLINE void vp_store_mask(float *p, unsigned mask, vpf a) {
  vpm m = vpm_bits_to(mask);
  for (int h = 0; h < FR_VP_HALVES; h++) _mm256_maskstore_ps(p + 8 * h, _mm256_castps_si256(m.m[h]), a.v[h]);
}
FR_INLINE void vp_scatter(float *base, const int32_t *idx, unsigned mask, vpf a) {
  float t[P] __attribute__((aligned(32)));
  vp_store(t, a);
  for (; mask; mask &= mask - 1) { int i = __builtin_ctz(mask); memcpy(base + idx[i], &t[i], sizeof(float)); }
}
#else
FR_INLINE vpf vp_gather(const float *base, const int32_t *idx) { vpf r; for (int i = 0; i < P; i++) memcpy(&r.f[i], base + idx[i], sizeof(float)); return r; }
FR_INLINE void vp_store_mask(float *p, unsigned mask, vpf a) {
  for (; mask; mask &= mask - 1) { int i = __builtin_ctz(mask); memcpy(p + i, &a.f[i], sizeof(float)); }
}
FR_INLINE void vp_scatter(float *base, const int32_t *idx, unsigned mask, vpf a) {
  for (; mask; mask &= mask - 1) { int i = __builtin_ctz(mask); memcpy(base + idx[i], &a.f[i], sizeof(float)); }
}
#endif

/* Lanes from lanes: vp_bcast4 gives lane i = p[i % 4] (p 16-byte aligned),
 * vp_permute lane i = a[idx[i]] (idx: P aligned int32 in 0..P-1). */
#if defined(FR_BUILD_ISA_AVX512) && P == 16
FR_INLINE vpf vp_bcast4(const float *p) { vpf r = {_mm512_broadcast_f32x4(_mm_load_ps(p))}; return r; }
FR_INLINE vpf vp_permute(vpf a, const int32_t *idx) {
  vpf r = {_mm512_permutexvar_ps(_mm512_load_si512((const void *)idx), a.v)};
  return r;
}
#elif defined(FR_BUILD_ISA_AVX512) /* P == 8 */
FR_INLINE vpf vp_bcast4(const float *p) { vpf r = {_mm256_broadcast_ps((const __m128 *)p)}; return r; }
FR_INLINE vpf vp_permute(vpf a, const int32_t *idx) {
  vpf r = {_mm256_permutevar8x32_ps(a.v, _mm256_load_si256((const __m256i *)idx))};
  return r;
}
#elif defined(FR_BUILD_ISA_AVX2) && P == 8
FR_INLINE vpf vp_bcast4(const float *p) { vpf r; r.v[0] = _mm256_broadcast_ps((const __m128 *)p); return r; }
FR_INLINE vpf vp_permute(vpf a, const int32_t *idx) {
  vpf r;
  r.v[0] = _mm256_permutevar8x32_ps(a.v[0], _mm256_load_si256((const __m256i *)idx));
  return r;
}
#elif defined(FR_BUILD_ISA_AVX2) /* P == 16: two halves */
FR_INLINE vpf vp_bcast4(const float *p) { vpf r; r.v[0] = r.v[1] = _mm256_broadcast_ps((const __m128 *)p); return r; }
FR_INLINE vpf vp_permute(vpf a, const int32_t *idx) {
  vpf r;
  for (int h = 0; h < 2; h++) {
    const __m256i i = _mm256_load_si256((const __m256i *)(idx + 8 * h));
    const __m256 from_hi = _mm256_castsi256_ps(_mm256_cmpgt_epi32(i, _mm256_set1_epi32(7)));
    r.v[h] = _mm256_blendv_ps(_mm256_permutevar8x32_ps(a.v[0], i), _mm256_permutevar8x32_ps(a.v[1], i), from_hi);
  }
  return r;
}
#else
FR_INLINE vpf vp_bcast4(const float *p) FR_VP_LANES(p[i & 3])
FR_INLINE vpf vp_permute(vpf a, const int32_t *idx) FR_VP_LANES(a.f[idx[i]])
#endif

/* Structure-of-arrays to records: record i (nf = 7 or 8 floats, at dst +
 * nf * i) gets lane i of f[0..nf), for the P lanes. Whole 8-float rows are
 * transposed in registers and stored at once; storing lane by lane cost a
 * store per float. */
#if defined(FR_BUILD_ISA_SCALAR)
FR_INLINE void vp_store_records(float *dst, const vpf *f, int nf) {
  for (int i = 0; i < P; i++)
    for (int k = 0; k < nf; k++) memcpy(dst + nf * i + k, &f[k].f[i], sizeof(float));
}
FR_INLINE void vp_load_records8_at(const float *src, size_t stride, const uint32_t *idx, int n, vpf f[8]) {
  for (int i = 0; i < P; i++) {
    const size_t row = (size_t)(i < n ? i : n - 1);
    for (int k = 0; k < 8; k++) memcpy(&f[k].f[i], src + stride * (idx ? idx[row] : row) + k, sizeof(float));
  }
}
FR_INLINE void vp_load_records4(const float *src, vpf f[4]) {
  for (int i = 0; i < P; i++)
    for (int k = 0; k < 4; k++) memcpy(&f[k].f[i], src + 4 * i + k, sizeof(float));
}
FR_INLINE void vp_store_records4(float *dst, const vpf f[4]) {
  for (int i = 0; i < P; i++)
    for (int k = 0; k < 4; k++) memcpy(dst + 4 * i + k, &f[k].f[i], sizeof(float));
}
#else
/* rows r[0..8) of 8 lanes to records 0..7 (8 floats each), in place */
FR_INLINE void fr_transpose8(__m256 r[8]) {
  __m256 t[8], s[8];
  for (int i = 0; i < 4; i++) {
    t[2 * i] = _mm256_unpacklo_ps(r[2 * i], r[2 * i + 1]);
    t[2 * i + 1] = _mm256_unpackhi_ps(r[2 * i], r[2 * i + 1]);
  }
  for (int h = 0; h < 2; h++) { /* fields 0-3 from t[0..3], fields 4-7 from t[4..7] */
    s[4 * h] = _mm256_shuffle_ps(t[4 * h], t[4 * h + 2], 0x44);
    s[4 * h + 1] = _mm256_shuffle_ps(t[4 * h], t[4 * h + 2], 0xEE);
    s[4 * h + 2] = _mm256_shuffle_ps(t[4 * h + 1], t[4 * h + 3], 0x44);
    s[4 * h + 3] = _mm256_shuffle_ps(t[4 * h + 1], t[4 * h + 3], 0xEE);
  }
  for (int i = 0; i < 4; i++) { /* s[i] holds records i | i + 4, fields 0-3; s[4 + i] fields 4-7 */
    r[i] = _mm256_permute2f128_ps(s[i], s[4 + i], 0x20);
    r[4 + i] = _mm256_permute2f128_ps(s[i], s[4 + i], 0x31);
  }
}
FR_INLINE __m256 fr_vp_half(vpf a, int h) {
#if defined(FR_BUILD_ISA_AVX512) && P == 16
  return h ? _mm512_extractf32x8_ps(a.v, 1) : _mm512_castps512_ps256(a.v);
#elif defined(FR_BUILD_ISA_AVX512)
  (void)h;
  return a.v;
#else
  return a.v[h];
#endif
}
/* lane k of f gets halves[0][k] | halves[1][k] | ... (8 lanes each) */
FR_INLINE vpf fr_vp_from_halves(const __m256 *halves) {
  vpf f;
#if defined(FR_BUILD_ISA_AVX512) && P == 16
  f.v = _mm512_insertf32x8(_mm512_castps256_ps512(halves[0]), halves[1], 1);
#elif defined(FR_BUILD_ISA_AVX512)
  f.v = halves[0];
#else
  for (int h = 0; h < P / 8; h++) f.v[h] = halves[h];
#endif
  return f;
}
/* The inverse for the first 8 floats of records `stride` floats apart:
 * f[k] gets field k of records 0..n-1 (record i at src + stride * idx[i],
 * or stride * i where idx is NULL), 1 <= n <= P, lanes past n repeating
 * record n - 1, so nothing after the n records is read (and with n <= 8
 * only one half is loaded and transposed). Eight rows are loaded and
 * transposed at a time, where a gather per field loads each float on its
 * own. */
FR_INLINE void vp_load_records8_at(const float *src, size_t stride, const uint32_t *idx, int n, vpf f[8]) {
  __m256 r[8][P / 8];
  for (int h = 0; h < P / 8; h++) {
    __m256 row[8];
    if (h && n <= 8) { /* record n - 1 from the first half */
      for (int k = 0; k < 8; k++) r[k][h] = _mm256_permutevar8x32_ps(r[k][0], _mm256_set1_epi32(n - 1));
      continue;
    }
    for (int i = 0; i < 8; i++) {
      const size_t r = (size_t)(8 * h + i < n ? 8 * h + i : n - 1);
      row[i] = _mm256_loadu_ps(src + stride * (idx ? idx[r] : r));
    }
    fr_transpose8(row);
    for (int k = 0; k < 8; k++) r[k][h] = row[k];
  }
  for (int k = 0; k < 8; k++) f[k] = fr_vp_from_halves(r[k]);
}
/* The same for records of 4 floats: rows i and i + 4 share a register, so
 * one in-lane 4x4 transpose serves 8 records. */
FR_INLINE void vp_load_records4(const float *src, vpf f[4]) {
  __m256 r[4][P / 8];
  for (int h = 0; h < P / 8; h++) {
    const float *s = src + 32 * h;
    __m256 row[4], t[4];
    for (int i = 0; i < 4; i++) row[i] = _mm256_set_m128(_mm_loadu_ps(s + 4 * (i + 4)), _mm_loadu_ps(s + 4 * i));
    t[0] = _mm256_unpacklo_ps(row[0], row[1]); /* x0 x1 y0 y1 | x4 x5 y4 y5 */
    t[1] = _mm256_unpackhi_ps(row[0], row[1]); /* z0 z1 w0 w1 | ... */
    t[2] = _mm256_unpacklo_ps(row[2], row[3]);
    t[3] = _mm256_unpackhi_ps(row[2], row[3]);
    r[0][h] = _mm256_shuffle_ps(t[0], t[2], 0x44);
    r[1][h] = _mm256_shuffle_ps(t[0], t[2], 0xEE);
    r[2][h] = _mm256_shuffle_ps(t[1], t[3], 0x44);
    r[3][h] = _mm256_shuffle_ps(t[1], t[3], 0xEE);
  }
  for (int k = 0; k < 4; k++) f[k] = fr_vp_from_halves(r[k]);
}
/* ... and its inverse */
FR_INLINE void vp_store_records4(float *dst, const vpf f[4]) {
  for (int h = 0; h < P / 8; h++) {
    __m256 t[4], r[4];
    t[0] = _mm256_unpacklo_ps(fr_vp_half(f[0], h), fr_vp_half(f[1], h)); /* x0 y0 x1 y1 | x4 y4 x5 y5 */
    t[1] = _mm256_unpackhi_ps(fr_vp_half(f[0], h), fr_vp_half(f[1], h)); /* x2 y2 x3 y3 | ... */
    t[2] = _mm256_unpacklo_ps(fr_vp_half(f[2], h), fr_vp_half(f[3], h));
    t[3] = _mm256_unpackhi_ps(fr_vp_half(f[2], h), fr_vp_half(f[3], h));
    r[0] = _mm256_shuffle_ps(t[0], t[2], 0x44); /* record 0 | record 4 */
    r[1] = _mm256_shuffle_ps(t[0], t[2], 0xEE);
    r[2] = _mm256_shuffle_ps(t[1], t[3], 0x44);
    r[3] = _mm256_shuffle_ps(t[1], t[3], 0xEE);
    float *d = dst + 32 * h;
    for (int i = 0; i < 4; i++) {
      _mm_storeu_ps(d + 4 * i, _mm256_castps256_ps128(r[i]));
      _mm_storeu_ps(d + 4 * (i + 4), _mm256_extractf128_ps(r[i], 1));
    }
  }
}
FR_INLINE void vp_store_records(float *dst, const vpf *f, int nf) {
  for (int h = 0; h < P / 8; h++) {
    __m256 r[8];
    for (int k = 0; k < 8; k++) r[k] = k < nf ? fr_vp_half(f[k], h) : _mm256_setzero_ps();
    fr_transpose8(r);
    /* Records shorter than 8 are written 8 floats at a time in order, each
     * spilling into the next record, which overwrites it; only the last one
     * is masked. VEX masked stores are slow on AMD (vmaskmovps took half of
     * dragon's primary-ray expand step), EVEX ones are not. */
    for (int i = 0; i < 8; i++) {
      float *rec = dst + nf * (8 * h + i);
      if (nf == 8 || 8 * h + i < P - 1) _mm256_storeu_ps(rec, r[i]);
#if defined(FR_BUILD_ISA_AVX512)
      else _mm256_mask_storeu_ps(rec, (__mmask8)((1u << nf) - 1u), r[i]);
#else
      else _mm256_maskstore_ps(rec, _mm256_cmpgt_epi32(_mm256_set1_epi32(nf), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)), r[i]);
#endif
    }
  }
}
#endif

/* The first n records `stride` floats apart at src (vp_load_records8_at without indices) */
FR_INLINE void vp_load_records8_rows(const float *src, size_t stride, int n, vpf f[8]) {
  vp_load_records8_at(src, stride, NULL, n, f);
}
/* P records of 8 floats in a row (n = P folds the row clamps away) */
FR_INLINE void vp_load_records8(const float *src, vpf f[8]) { vp_load_records8_rows(src, 8, P, f); }

#if !(defined(FR_BUILD_ISA_AVX512) && P == 16) && !defined(FR_BUILD_ISA_SCALAR)
/* horizontal min/max of 8 lanes: halves, quarters, pairs */
#define FR_VP_HREDUCE(name, op128, opss)                                                \
  FR_INLINE float name(__m256 v) {                                                     \
    __m128 m = op128(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));          \
    m = op128(m, _mm_movehl_ps(m, m));                                                 \
    return _mm_cvtss_f32(opss(m, _mm_movehdup_ps(m)));                                 \
  }
FR_VP_HREDUCE(fr_hmin8, _mm_min_ps, _mm_min_ss)
FR_VP_HREDUCE(fr_hmax8, _mm_max_ps, _mm_max_ss)
#if defined(FR_BUILD_ISA_AVX512)
FR_INLINE float vp_reduce_min(vpf a) { return fr_hmin8(a.v); }
FR_INLINE float vp_reduce_max(vpf a) { return fr_hmax8(a.v); }
#else
FR_INLINE float vp_reduce_min(vpf a) {
  __m256 m = a.v[0];
  for (int h = 1; h < FR_VP_HALVES; h++) m = _mm256_min_ps(m, a.v[h]);
  return fr_hmin8(m);
}
FR_INLINE float vp_reduce_max(vpf a) {
  __m256 m = a.v[0];
  for (int h = 1; h < FR_VP_HALVES; h++) m = _mm256_max_ps(m, a.v[h]);
  return fr_hmax8(m);
}
#endif
#endif
#endif
