/*
 * The thin SIMD wrapper the kernels are written against.
 *
 * A kernel source includes this header and is compiled once per ISA with one
 * of FR_BUILD_ISA_AVX512, FR_BUILD_ISA_AVX2 or FR_BUILD_ISA_SCALAR defined; FR_ISA_FN(name)
 * gives each compilation its own symbol names. Semantics are identical on every
 * level (min/max return the second operand when one is NaN, like minps), and no
 * level contracts a*b+c into an FMA, so all three give bit-identical answers;
 * the tests hold them to that.
 *
 *   vfloat4 / vmask4   four lanes: BVH4 node tests, 4-triangle leaves
 *   vfloat8            eight lanes: BVH8 node tests, two rays' 4-triangle tests
 *                      (comparisons give bit masks)
 *   vbits8             eight 64-bit sets: per child, the rays of a stream that hit it
 */
#ifndef FR_BASE_SIMD_H
#define FR_BASE_SIMD_H

#include <stdint.h>
#include <string.h>

#if defined(FR_BUILD_ISA_AVX512)
#define FR_ISA_SUFFIX avx512
#elif defined(FR_BUILD_ISA_AVX2)
#define FR_ISA_SUFFIX avx2
#elif defined(FR_BUILD_ISA_SCALAR)
#define FR_ISA_SUFFIX scalar
#else
#error "define one of FR_BUILD_ISA_AVX512, FR_BUILD_ISA_AVX2, FR_BUILD_ISA_SCALAR"
#endif
#define FR_CAT2(a, b) a##_##b
#define FR_CAT(a, b) FR_CAT2(a, b)
#define FR_ISA_FN(name) FR_CAT(name, FR_ISA_SUFFIX)

#define FR_INLINE static inline __attribute__((always_inline))

#if defined(FR_BUILD_ISA_AVX512) || defined(FR_BUILD_ISA_AVX2)
#include <immintrin.h>

typedef struct vfloat4 { __m128 v; } vfloat4;
#if defined(FR_BUILD_ISA_AVX512)
typedef struct vmask4 { __mmask8 m; } vmask4;
#else
typedef struct vmask4 { __m128 m; } vmask4;
#endif

FR_INLINE vfloat4 vf4(float a) { vfloat4 r = {_mm_set1_ps(a)}; return r; }
FR_INLINE vfloat4 vf4_load(const float *p) { vfloat4 r = {_mm_load_ps(p)}; return r; }
FR_INLINE void vf4_store(float *p, vfloat4 a) { _mm_store_ps(p, a.v); }
FR_INLINE vfloat4 vf4_add(vfloat4 a, vfloat4 b) { vfloat4 r = {_mm_add_ps(a.v, b.v)}; return r; }
FR_INLINE vfloat4 vf4_sub(vfloat4 a, vfloat4 b) { vfloat4 r = {_mm_sub_ps(a.v, b.v)}; return r; }
FR_INLINE vfloat4 vf4_mul(vfloat4 a, vfloat4 b) { vfloat4 r = {_mm_mul_ps(a.v, b.v)}; return r; }
FR_INLINE vfloat4 vf4_div(vfloat4 a, vfloat4 b) { vfloat4 r = {_mm_div_ps(a.v, b.v)}; return r; }
FR_INLINE vfloat4 vf4_min(vfloat4 a, vfloat4 b) { vfloat4 r = {_mm_min_ps(a.v, b.v)}; return r; }
FR_INLINE vfloat4 vf4_max(vfloat4 a, vfloat4 b) { vfloat4 r = {_mm_max_ps(a.v, b.v)}; return r; }
/* Min and max of the bit patterns as signed integers (one cycle of latency
 * where the float forms take two on AMD Zen 4 and 5): the float min and max
 * where both are >= +0 or one is >= +0 and the other < -0; among negatives
 * the order reverses, and -0 is the least of all. */
FR_INLINE vfloat4 vf4_imin(vfloat4 a, vfloat4 b) { vfloat4 r = {_mm_castsi128_ps(_mm_min_epi32(_mm_castps_si128(a.v), _mm_castps_si128(b.v)))}; return r; }
FR_INLINE vfloat4 vf4_imax(vfloat4 a, vfloat4 b) { vfloat4 r = {_mm_castsi128_ps(_mm_max_epi32(_mm_castps_si128(a.v), _mm_castps_si128(b.v)))}; return r; }
FR_INLINE vfloat4 vf4_neg(vfloat4 a) { vfloat4 r = {_mm_xor_ps(a.v, _mm_set1_ps(-0.0f))}; return r; }

#if defined(FR_BUILD_ISA_AVX512)
#define FR_CMP4(a, b, op) { _mm_cmp_ps_mask((a).v, (b).v, op) }
FR_INLINE vmask4 vm4_and(vmask4 a, vmask4 b) { vmask4 r = {(__mmask8)(a.m & b.m)}; return r; }
FR_INLINE vmask4 vm4_or(vmask4 a, vmask4 b) { vmask4 r = {(__mmask8)(a.m | b.m)}; return r; }
FR_INLINE int vm4_bits(vmask4 a) { return a.m & 0xF; }
FR_INLINE vfloat4 vf4_select(vmask4 m, vfloat4 t, vfloat4 f) { vfloat4 r = {_mm_mask_blend_ps(m.m, f.v, t.v)}; return r; }
/* a + b in the lanes set in `lanes` (bit i: lane i), a in the others */
FR_INLINE vfloat4 vf4_add_where(vfloat4 a, int lanes, vfloat4 b) { vfloat4 r = {_mm_mask_add_ps(a.v, (__mmask8)lanes, a.v, b.v)}; return r; }
#else
#define FR_CMP4(a, b, op) { _mm_cmp_ps((a).v, (b).v, op) }
FR_INLINE vmask4 vm4_and(vmask4 a, vmask4 b) { vmask4 r = {_mm_and_ps(a.m, b.m)}; return r; }
FR_INLINE vmask4 vm4_or(vmask4 a, vmask4 b) { vmask4 r = {_mm_or_ps(a.m, b.m)}; return r; }
FR_INLINE int vm4_bits(vmask4 a) { return _mm_movemask_ps(a.m); }
FR_INLINE vfloat4 vf4_select(vmask4 m, vfloat4 t, vfloat4 f) { vfloat4 r = {_mm_blendv_ps(f.v, t.v, m.m)}; return r; }
FR_INLINE vfloat4 vf4_add_where(vfloat4 a, int lanes, vfloat4 b) {
  const __m128i bit = _mm_setr_epi32(1, 2, 4, 8);
  __m128 sel = _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(lanes), bit), bit));
  vfloat4 r = {_mm_add_ps(a.v, _mm_and_ps(sel, b.v))}; /* b's other lanes may be inf or NaN: and them away */
  return r;
}
#endif
FR_INLINE vmask4 vf4_lt(vfloat4 a, vfloat4 b) { vmask4 r = FR_CMP4(a, b, _CMP_LT_OQ); return r; }
FR_INLINE vmask4 vf4_le(vfloat4 a, vfloat4 b) { vmask4 r = FR_CMP4(a, b, _CMP_LE_OQ); return r; }
FR_INLINE vmask4 vf4_gt(vfloat4 a, vfloat4 b) { vmask4 r = FR_CMP4(a, b, _CMP_GT_OQ); return r; }
FR_INLINE vmask4 vf4_ge(vfloat4 a, vfloat4 b) { vmask4 r = FR_CMP4(a, b, _CMP_GE_OQ); return r; }
FR_INLINE vmask4 vf4_ne(vfloat4 a, vfloat4 b) { vmask4 r = FR_CMP4(a, b, _CMP_NEQ_UQ); return r; }
FR_INLINE vmask4 vf4_eq(vfloat4 a, vfloat4 b) { vmask4 r = FR_CMP4(a, b, _CMP_EQ_OQ); return r; }


/* eight lanes: 8-wide BVH node tests */
typedef struct vfloat8 { __m256 v; } vfloat8;
FR_INLINE vfloat8 vf8(float a) { vfloat8 r = {_mm256_set1_ps(a)}; return r; }
FR_INLINE vfloat8 vf8_load(const float *p) { vfloat8 r = {_mm256_load_ps(p)}; return r; }
FR_INLINE void vf8_store(float *p, vfloat8 a) { _mm256_store_ps(p, a.v); }
FR_INLINE vfloat8 vf8_sub(vfloat8 a, vfloat8 b) { vfloat8 r = {_mm256_sub_ps(a.v, b.v)}; return r; }
FR_INLINE vfloat8 vf8_mul(vfloat8 a, vfloat8 b) { vfloat8 r = {_mm256_mul_ps(a.v, b.v)}; return r; }
FR_INLINE vfloat8 vf8_min(vfloat8 a, vfloat8 b) { vfloat8 r = {_mm256_min_ps(a.v, b.v)}; return r; }
FR_INLINE vfloat8 vf8_max(vfloat8 a, vfloat8 b) { vfloat8 r = {_mm256_max_ps(a.v, b.v)}; return r; }
FR_INLINE vfloat8 vf8_imin(vfloat8 a, vfloat8 b) {
  vfloat8 r = {_mm256_castsi256_ps(_mm256_min_epi32(_mm256_castps_si256(a.v), _mm256_castps_si256(b.v)))};
  return r;
}
FR_INLINE vfloat8 vf8_imax(vfloat8 a, vfloat8 b) {
  vfloat8 r = {_mm256_castsi256_ps(_mm256_max_epi32(_mm256_castps_si256(a.v), _mm256_castps_si256(b.v)))};
  return r;
}
FR_INLINE vfloat8 vf8_div(vfloat8 a, vfloat8 b) { vfloat8 r = {_mm256_div_ps(a.v, b.v)}; return r; }
FR_INLINE vfloat8 vf8_add(vfloat8 a, vfloat8 b) { vfloat8 r = {_mm256_add_ps(a.v, b.v)}; return r; }
/* lanes 0-3 from lo, 4-7 from hi: two rays' four-lane values side by side */
FR_INLINE vfloat8 vf8_join(vfloat4 lo, vfloat4 hi) { vfloat8 r = {_mm256_set_m128(hi.v, lo.v)}; return r; }
FR_INLINE vfloat4 vf8_lo(vfloat8 a) { vfloat4 r = {_mm256_castps256_ps128(a.v)}; return r; }
FR_INLINE vfloat4 vf8_hi(vfloat8 a) { vfloat4 r = {_mm256_extractf128_ps(a.v, 1)}; return r; }
#if defined(FR_BUILD_ISA_AVX512)
#define FR_CMP8_BITS(a, b, op) _mm256_cmp_ps_mask((a).v, (b).v, op)
#else
#define FR_CMP8_BITS(a, b, op) _mm256_movemask_ps(_mm256_cmp_ps((a).v, (b).v, op))
#endif
FR_INLINE int vf8_lt_bits(vfloat8 a, vfloat8 b) { return FR_CMP8_BITS(a, b, _CMP_LT_OQ); }
FR_INLINE int vf8_gt_bits(vfloat8 a, vfloat8 b) { return FR_CMP8_BITS(a, b, _CMP_GT_OQ); }
FR_INLINE int vf8_ge_bits(vfloat8 a, vfloat8 b) { return FR_CMP8_BITS(a, b, _CMP_GE_OQ); }
FR_INLINE int vf8_eq_bits(vfloat8 a, vfloat8 b) { return FR_CMP8_BITS(a, b, _CMP_EQ_OQ); }
FR_INLINE int vf8_ne_bits(vfloat8 a, vfloat8 b) { return FR_CMP8_BITS(a, b, _CMP_NEQ_UQ); }
#if defined(FR_BUILD_ISA_AVX512)
FR_INLINE int vf8_le_bits(vfloat8 a, vfloat8 b) { return _mm256_cmp_ps_mask(a.v, b.v, _CMP_LE_OQ); }
FR_INLINE vfloat8 vf8_add_where(vfloat8 a, int lanes, vfloat8 b) { vfloat8 r = {_mm256_mask_add_ps(a.v, (__mmask8)lanes, a.v, b.v)}; return r; }
#else
FR_INLINE int vf8_le_bits(vfloat8 a, vfloat8 b) { return _mm256_movemask_ps(_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)); }
FR_INLINE vfloat8 vf8_add_where(vfloat8 a, int lanes, vfloat8 b) {
  const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  __m256 sel = _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(lanes), bit), bit));
  vfloat8 r = {_mm256_add_ps(a.v, _mm256_and_ps(sel, b.v))};
  return r;
}
#endif

/* eight 64-bit sets, one per child of a node: which rays of a stream hit it */
#if defined(FR_BUILD_ISA_AVX512)
typedef struct vbits8 { __m512i v; } vbits8;
FR_INLINE vbits8 vb8_zero(void) { vbits8 r = {_mm512_setzero_si512()}; return r; }
FR_INLINE void vb8_store(uint64_t *p, vbits8 a) { _mm512_storeu_si512((void *)p, a.v); }
/* adds bit to the sets of the lanes in `lanes` */
FR_INLINE vbits8 vb8_or_where(vbits8 a, int lanes, uint64_t bit) {
  vbits8 r = {_mm512_mask_or_epi64(a.v, (__mmask8)lanes, a.v, _mm512_set1_epi64((long long)bit))};
  return r;
}
#else
/* AVX2: children 0-3 in lo, 4-7 in hi */
typedef struct vbits8 { __m256i lo, hi; } vbits8;
FR_INLINE vbits8 vb8_zero(void) { vbits8 r = {_mm256_setzero_si256(), _mm256_setzero_si256()}; return r; }
FR_INLINE void vb8_store(uint64_t *p, vbits8 a) {
  _mm256_storeu_si256((__m256i *)p, a.lo);
  _mm256_storeu_si256((__m256i *)(p + 4), a.hi);
}
FR_INLINE vbits8 vb8_or_where(vbits8 a, int lanes, uint64_t bit) {
  const __m256i lane_lo = _mm256_setr_epi64x(1, 2, 4, 8), lane_hi = _mm256_setr_epi64x(16, 32, 64, 128);
  const __m256i l = _mm256_set1_epi64x(lanes), b = _mm256_set1_epi64x((long long)bit);
  __m256i sel_lo = _mm256_cmpeq_epi64(_mm256_and_si256(l, lane_lo), lane_lo);
  __m256i sel_hi = _mm256_cmpeq_epi64(_mm256_and_si256(l, lane_hi), lane_hi);
  vbits8 r = {_mm256_or_si256(a.lo, _mm256_and_si256(sel_lo, b)), _mm256_or_si256(a.hi, _mm256_and_si256(sel_hi, b))};
  return r;
}
#endif

#else /* FR_ISA_SCALAR: plain C, one lane at a time */

typedef struct vfloat4 { float f[4]; } vfloat4;
typedef struct vmask4 { unsigned m; } vmask4;

#define FR_LANES4(expr) { vfloat4 r; for (int i = 0; i < 4; i++) r.f[i] = (expr); return r; }
#define FR_MASK4(expr) { vmask4 r = {0}; for (int i = 0; i < 4; i++) r.m |= (unsigned)(expr) << i; return r; }
FR_INLINE vfloat4 vf4(float a) FR_LANES4(a)
FR_INLINE vfloat4 vf4_load(const float *p) FR_LANES4(p[i])
FR_INLINE void vf4_store(float *p, vfloat4 a) { for (int i = 0; i < 4; i++) p[i] = a.f[i]; }
FR_INLINE vfloat4 vf4_add(vfloat4 a, vfloat4 b) FR_LANES4(a.f[i] + b.f[i])
FR_INLINE vfloat4 vf4_sub(vfloat4 a, vfloat4 b) FR_LANES4(a.f[i] - b.f[i])
FR_INLINE vfloat4 vf4_mul(vfloat4 a, vfloat4 b) FR_LANES4(a.f[i] * b.f[i])
FR_INLINE vfloat4 vf4_div(vfloat4 a, vfloat4 b) FR_LANES4(a.f[i] / b.f[i])
FR_INLINE vfloat4 vf4_min(vfloat4 a, vfloat4 b) FR_LANES4(a.f[i] < b.f[i] ? a.f[i] : b.f[i])
FR_INLINE vfloat4 vf4_max(vfloat4 a, vfloat4 b) FR_LANES4(a.f[i] > b.f[i] ? a.f[i] : b.f[i])
FR_INLINE int32_t fr_f2i(float f) { int32_t i; memcpy(&i, &f, sizeof i); return i; }
FR_INLINE vfloat4 vf4_imin(vfloat4 a, vfloat4 b) FR_LANES4(fr_f2i(a.f[i]) < fr_f2i(b.f[i]) ? a.f[i] : b.f[i])
FR_INLINE vfloat4 vf4_imax(vfloat4 a, vfloat4 b) FR_LANES4(fr_f2i(a.f[i]) > fr_f2i(b.f[i]) ? a.f[i] : b.f[i])
FR_INLINE vfloat4 vf4_neg(vfloat4 a) FR_LANES4(-a.f[i])
FR_INLINE vmask4 vf4_lt(vfloat4 a, vfloat4 b) FR_MASK4(a.f[i] < b.f[i])
FR_INLINE vmask4 vf4_le(vfloat4 a, vfloat4 b) FR_MASK4(a.f[i] <= b.f[i])
FR_INLINE vmask4 vf4_gt(vfloat4 a, vfloat4 b) FR_MASK4(a.f[i] > b.f[i])
FR_INLINE vmask4 vf4_ge(vfloat4 a, vfloat4 b) FR_MASK4(a.f[i] >= b.f[i])
FR_INLINE vmask4 vf4_ne(vfloat4 a, vfloat4 b) FR_MASK4(!(a.f[i] == b.f[i]))
FR_INLINE vmask4 vf4_eq(vfloat4 a, vfloat4 b) FR_MASK4(a.f[i] == b.f[i])
FR_INLINE vmask4 vm4_and(vmask4 a, vmask4 b) { vmask4 r = {a.m & b.m}; return r; }
FR_INLINE vmask4 vm4_or(vmask4 a, vmask4 b) { vmask4 r = {a.m | b.m}; return r; }
FR_INLINE int vm4_bits(vmask4 a) { return (int)a.m; }
FR_INLINE vfloat4 vf4_select(vmask4 m, vfloat4 t, vfloat4 f) FR_LANES4(((m.m >> i) & 1) ? t.f[i] : f.f[i])
FR_INLINE vfloat4 vf4_add_where(vfloat4 a, int lanes, vfloat4 b) FR_LANES4(((lanes >> i) & 1) ? a.f[i] + b.f[i] : a.f[i])

typedef struct vfloat8 { float f[8]; } vfloat8;
#define FR_LANES8(expr) { vfloat8 r; for (int i = 0; i < 8; i++) r.f[i] = (expr); return r; }
FR_INLINE vfloat8 vf8(float a) FR_LANES8(a)
FR_INLINE vfloat8 vf8_load(const float *p) FR_LANES8(p[i])
FR_INLINE void vf8_store(float *p, vfloat8 a) { for (int i = 0; i < 8; i++) p[i] = a.f[i]; }
FR_INLINE vfloat8 vf8_sub(vfloat8 a, vfloat8 b) FR_LANES8(a.f[i] - b.f[i])
FR_INLINE vfloat8 vf8_mul(vfloat8 a, vfloat8 b) FR_LANES8(a.f[i] * b.f[i])
FR_INLINE vfloat8 vf8_min(vfloat8 a, vfloat8 b) FR_LANES8(a.f[i] < b.f[i] ? a.f[i] : b.f[i])
FR_INLINE vfloat8 vf8_max(vfloat8 a, vfloat8 b) FR_LANES8(a.f[i] > b.f[i] ? a.f[i] : b.f[i])
FR_INLINE vfloat8 vf8_imin(vfloat8 a, vfloat8 b) FR_LANES8(fr_f2i(a.f[i]) < fr_f2i(b.f[i]) ? a.f[i] : b.f[i])
FR_INLINE vfloat8 vf8_imax(vfloat8 a, vfloat8 b) FR_LANES8(fr_f2i(a.f[i]) > fr_f2i(b.f[i]) ? a.f[i] : b.f[i])
FR_INLINE int vf8_le_bits(vfloat8 a, vfloat8 b) { int m = 0; for (int i = 0; i < 8; i++) m |= (a.f[i] <= b.f[i]) << i; return m; }
FR_INLINE vfloat8 vf8_div(vfloat8 a, vfloat8 b) FR_LANES8(a.f[i] / b.f[i])
FR_INLINE vfloat8 vf8_add(vfloat8 a, vfloat8 b) FR_LANES8(a.f[i] + b.f[i])
FR_INLINE vfloat8 vf8_join(vfloat4 lo, vfloat4 hi) FR_LANES8(i < 4 ? lo.f[i] : hi.f[i - 4])
FR_INLINE vfloat4 vf8_lo(vfloat8 a) FR_LANES4(a.f[i])
FR_INLINE vfloat4 vf8_hi(vfloat8 a) FR_LANES4(a.f[i + 4])
#define FR_BITS8(expr) { int m = 0; for (int i = 0; i < 8; i++) m |= (expr) << i; return m; }
FR_INLINE int vf8_lt_bits(vfloat8 a, vfloat8 b) FR_BITS8(a.f[i] < b.f[i])
FR_INLINE int vf8_gt_bits(vfloat8 a, vfloat8 b) FR_BITS8(a.f[i] > b.f[i])
FR_INLINE int vf8_ge_bits(vfloat8 a, vfloat8 b) FR_BITS8(a.f[i] >= b.f[i])
FR_INLINE int vf8_eq_bits(vfloat8 a, vfloat8 b) FR_BITS8(a.f[i] == b.f[i])
FR_INLINE int vf8_ne_bits(vfloat8 a, vfloat8 b) FR_BITS8(!(a.f[i] == b.f[i]))
FR_INLINE vfloat8 vf8_add_where(vfloat8 a, int lanes, vfloat8 b) FR_LANES8(((lanes >> i) & 1) ? a.f[i] + b.f[i] : a.f[i])

typedef struct vbits8 { uint64_t u[8]; } vbits8;
FR_INLINE vbits8 vb8_zero(void) { vbits8 r = {{0}}; return r; }
FR_INLINE void vb8_store(uint64_t *p, vbits8 a) { for (int i = 0; i < 8; i++) p[i] = a.u[i]; }
FR_INLINE vbits8 vb8_or_where(vbits8 a, int lanes, uint64_t bit) {
  for (; lanes; lanes &= lanes - 1) a.u[__builtin_ctz((unsigned)lanes)] |= bit;
  return a;
}
#endif

/* cross and dot of 3-vectors held as three vfloat4 (structure of arrays) */
typedef struct vec3f4 { vfloat4 x, y, z; } vec3f4;
FR_INLINE vec3f4 v3f4_sub(vec3f4 a, vec3f4 b) { vec3f4 r = {vf4_sub(a.x, b.x), vf4_sub(a.y, b.y), vf4_sub(a.z, b.z)}; return r; }
FR_INLINE vec3f4 v3f4_add(vec3f4 a, vec3f4 b) { vec3f4 r = {vf4_add(a.x, b.x), vf4_add(a.y, b.y), vf4_add(a.z, b.z)}; return r; }
FR_INLINE vec3f4 v3f4_cross(vec3f4 a, vec3f4 b) {
  vec3f4 r = {vf4_sub(vf4_mul(a.y, b.z), vf4_mul(a.z, b.y)),
              vf4_sub(vf4_mul(a.z, b.x), vf4_mul(a.x, b.z)),
              vf4_sub(vf4_mul(a.x, b.y), vf4_mul(a.y, b.x))};
  return r;
}
FR_INLINE vfloat4 v3f4_dot(vec3f4 a, vec3f4 b) {
  return vf4_add(vf4_add(vf4_mul(a.x, b.x), vf4_mul(a.y, b.y)), vf4_mul(a.z, b.z));
}
#endif

