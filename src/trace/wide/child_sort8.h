/*
 * The hit children of an 8-wide node in traversal order without a branch on
 * their distances: a bitonic network of six compare-exchange layers over
 * integer keys, in 256-bit AVX-512 or AVX2 operations. The insertion sort it
 * replaces mispredicted often on rays that hit several children, which the
 * network does not (hairball diffuse8 and specular8 gained 9-14%). No
 * 512-bit operation: on Xeons one lowers the core's clock. tests/test_kernels.c checks both
 * levels against the scalar definition of the order below.
 *
 * A key is the entry distance as a monotone integer with its three low bits
 * replaced by the child's slot, so keys are unique (distances within 8 ulps
 * may swap, which only changes the visiting order); a missed slot gets the
 * smallest key. Sorted descending, the first popcount(mask) entries are the
 * hit children farthest first. Include after base/simd.h in a kernel
 * compiled for AVX-512 or AVX2.
 */
#ifndef FR_TRACE_CHILD_SORT8_H
#define FR_TRACE_CHILD_SORT8_H
#include <stdint.h>
#include <string.h>
#include "base/simd.h"

#if defined(FR_BUILD_ISA_AVX512) || defined(FR_BUILD_ISA_AVX2)
#define FR_HAVE_CHILD_SORT8 1

/* One layer: each lane meets lane ^ j; the lanes in imm keep the larger key.
 * The six (j, imm) pairs make a descending bitonic sort of eight lanes. */
#define FR_SORT8_LAYER(key, j, imm)                                                                        \
  do {                                                                                                     \
    __m256i other_ = _mm256_permutevar8x32_epi32(key, _mm256_xor_si256(lane, _mm256_set1_epi32(j)));      \
    key = _mm256_blend_epi32(_mm256_min_epi32(key, other_), _mm256_max_epi32(key, other_), imm);          \
  } while (0)

/* One child's key, as the network below makes it. */
static inline int32_t fr_child_key(float d, int slot) {
  int32_t b;
  memcpy(&b, &d, sizeof b);
  b ^= (int32_t)((uint32_t)(b >> 31) >> 1);
  return (b & ~7) | slot;
}

/* Exactly two hits: the same order from two scalar keys, picked by
 * conditional moves. It runs about as many instructions as
 * the network but gets the nearest child, whose node load comes next, some
 * 20 cycles sooner than the six dependent layers. The two distances come
 * out by lane permutes rather than a store and two reloads, which would
 * wait on store forwarding. */
FR_INLINE uint32_t fr_child_sort2(const uint32_t *child, int i0, int i1, __m256 dist, void *out) {
  const float d0 = _mm256_cvtss_f32(_mm256_permutevar8x32_ps(dist, _mm256_set1_epi32(i0)));
  const float d1 = _mm256_cvtss_f32(_mm256_permutevar8x32_ps(dist, _mm256_set1_epi32(i1)));
  int swap = fr_child_key(d1, i1) < fr_child_key(d0, i0);
  int nr = swap ? i1 : i0, fr = swap ? i0 : i1;
  const float dn = swap ? d1 : d0, df = swap ? d0 : d1;
  struct { uint32_t ref; float dist; } e[2] = {{child[fr], df}, {child[nr], dn}};
  memcpy(out, e, sizeof e);
  return child[nr];
}

/* Writes the hit children's (child, distance) pairs, farthest first, to out
 * (room for eight 8-byte entries, child in the low word; up to all eight are
 * written) and returns the nearest hit child. mask holds at least one hit. */
FR_INLINE uint32_t fr_child_sort8(const uint32_t *child, int mask, __m256 dist, void *out) {
  unsigned rest = (unsigned)mask & ((unsigned)mask - 1);
  if (rest && !(rest & (rest - 1))) return fr_child_sort2(child, __builtin_ctz((unsigned)mask), __builtin_ctz(rest), dist, out);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  __m256i bits = _mm256_castps_si256(dist);
  /* negative floats: flip all but the sign bit, so integer order is float order */
  __m256i key = _mm256_xor_si256(bits, _mm256_srli_epi32(_mm256_srai_epi32(bits, 31), 1));
  key = _mm256_or_si256(_mm256_andnot_si256(_mm256_set1_epi32(7), key), lane);
  __m256i lanebit = _mm256_sllv_epi32(_mm256_set1_epi32(1), lane);
  __m256i hit = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(mask), lanebit), lanebit);
  /* The nearest hit child first, by a three-step min over the keys: the
   * next node's loads wait for it, and the network's six dependent layers
   * below are then off that path (only the stack entries wait for them).
   * For exactly two hits fr_child_sort2's scalar keys are faster still. */
  __m256i near = _mm256_blendv_epi8(_mm256_set1_epi32(INT32_MAX), key, hit);
  near = _mm256_min_epi32(near, _mm256_shuffle_epi32(near, 0xB1));
  near = _mm256_min_epi32(near, _mm256_shuffle_epi32(near, 0x4E));
  near = _mm256_min_epi32(near, _mm256_permute4x64_epi64(near, 0x4E));
  const int nearest = _mm256_cvtsi256_si32(near) & 7;
  key = _mm256_blendv_epi8(_mm256_set1_epi32(INT32_MIN), key, hit);
  FR_SORT8_LAYER(key, 1, 102);
  FR_SORT8_LAYER(key, 2, 60);
  FR_SORT8_LAYER(key, 1, 90);
  FR_SORT8_LAYER(key, 4, 15);
  FR_SORT8_LAYER(key, 2, 51);
  FR_SORT8_LAYER(key, 1, 85);
  __m256i slot = _mm256_and_si256(key, _mm256_set1_epi32(7));
  __m256i kids = _mm256_permutevar8x32_epi32(_mm256_loadu_si256((const __m256i *)child), slot);
  __m256i d = _mm256_permutevar8x32_epi32(bits, slot);
  __m256i lo = _mm256_unpacklo_epi32(kids, d), hi = _mm256_unpackhi_epi32(kids, d);
  _mm256_storeu_si256((__m256i *)out, _mm256_permute2x128_si256(lo, hi, 0x20));
  _mm256_storeu_si256((__m256i *)out + 1, _mm256_permute2x128_si256(lo, hi, 0x31));
  return child[nearest];
}
#undef FR_SORT8_LAYER
#endif
#endif
