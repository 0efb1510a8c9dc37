/* The ray streams' set-up (stream_setup, trace/stream_rays.h) compiled for
 * one ISA, called by test_kernels through a plain-C signature. Returns the
 * index of the first ray that stream_setup calls valid or invalid where
 * fr_ray_invalid does not, or whose values differ in any bit from
 * ray_setup's (what the node and triangle tests read); -2 when the stream's
 * uniform verdict is wrong; -1 when all is the same. *uniform gets that
 * verdict. */
#include <string.h>
#include "base/simd.h"
#include "trace/wide/stream_rays.h"

#define NAME2(isa) fr_test_stream_setup_##isa
#define NAME(isa) NAME2(isa)

static int same_bits(const void *a, const void *b, size_t n) { return !memcmp(a, b, n); }

int NAME(FR_ISA_SUFFIX)(const fr_ray *rays, int n, int in_row, int *uniform);
int NAME(FR_ISA_SUFFIX)(const fr_ray *rays, int n, int in_row, int *uniform) {
  uint32_t idx[FR_STREAM_MAX]; /* the rays in a row or backwards */
  for (int i = 0; i < n; i++) idx[i] = (uint32_t)(in_row ? i : n - 1 - i);
  static stream_rays s __attribute__((aligned(64)));
  const uint64_t valid = stream_setup(rays, idx, n, &s, uniform);
  int signs = -1, uniform_want = 1;
  for (int i = 0; i < n; i++) {
    if ((int)((valid >> i) & 1) == fr_ray_invalid(&rays[idx[i]])) return (int)idx[i];
    if (!((valid >> i) & 1)) continue;
    ray_pre want, got = stream_ray(&s, i);
    ray_setup(&want, &rays[idx[i]]);
    const int si = want.near_x | want.near_y << 8 | want.near_z << 16;
    if (signs >= 0 && si != signs) uniform_want = 0;
    signs = si;
    float w[8] __attribute__((aligned(32))), g[8] __attribute__((aligned(32)));
#define SAME_VN(f) (VN_STORE(w, want.f), VN_STORE(g, got.f), same_bits(w, g, sizeof(float) * W))
#define SAME_V4(f) (vf4_store(w, want.f), vf4_store(g, got.f), same_bits(w, g, sizeof(float) * 4))
    const int same = SAME_VN(ox) && SAME_VN(oy) && SAME_VN(oz) && SAME_VN(nrx) && SAME_VN(nry) && SAME_VN(nrz) &&
                     SAME_VN(nrx_w) && SAME_VN(nry_w) && SAME_VN(nrz_w) && SAME_V4(o_k[0]) && SAME_V4(o_k[1]) &&
                     SAME_V4(o_k[2]) && SAME_V4(sx) && SAME_V4(sy) && SAME_V4(nsz) && want.kx4 == got.kx4 &&
                     want.ky4 == got.ky4 && want.kz4 == got.kz4 && want.near_x == got.near_x &&
                     want.near_y == got.near_y && want.near_z == got.near_z && same_bits(&want.tnear, &got.tnear, 4) &&
                     same_bits(&rays[idx[i]].tfar, &s.tfar[i], 4);
#undef SAME_VN
#undef SAME_V4
    if (!same) return (int)idx[i];
  }
  return *uniform == uniform_want ? -1 : -2;
}

/* chunk_node against planes_test, per ray of a stream of 16 and child of
 * a BVH8 node (its six planes as the node stores them, nchildren given):
 * returns the first ray whose children hit differ, -1 when none does;
 * *hits gets the ray-child pairs hit. */
#define CHUNK_NAME2(isa) fr_test_stream_chunk_##isa
#define CHUNK_NAME(isa) CHUNK_NAME2(isa)
int CHUNK_NAME(FR_ISA_SUFFIX)(const float planes[6][8], int nchildren, const fr_ray *rays, unsigned lanes, int *hits);
int CHUNK_NAME(FR_ISA_SUFFIX)(const float planes[6][8], int nchildren, const fr_ray *rays, unsigned lanes, int *hits) {
  static node_t node;
  memset(&node, 0, sizeof node);
  memcpy(&node, planes, sizeof(float) * 48);
  node.nchildren = (uint32_t)nchildren;
  uint32_t idx[16];
  for (int i = 0; i < 16; i++) idx[i] = (uint32_t)i;
  static stream_rays s __attribute__((aligned(64)));
  int uniform;
  stream_setup(rays, idx, 16, &s, &uniform);
  if (!uniform) return -2;
  const ray_pre r0 = stream_ray(&s, 0);
  uint64_t child_rays[8] = {0};
  int hit = 0;
  chunk_node(&node, &s, 0, lanes, &r0, child_rays, &hit);
  *hits = 0;
  for (int i = 0; i < 16; i++) {
    int want = 0;
    if ((lanes >> i) & 1) {
      const ray_pre ri = stream_ray(&s, i);
      box_test(&node, &ri, s.tfar[i], &want);
      want &= (1 << nchildren) - 1;
    }
    int got = 0;
    for (int c = 0; c < 8; c++) got |= (int)((child_rays[c] >> i) & 1) << c;
    if (got != want) return i;
    *hits += __builtin_popcount((unsigned)got);
  }
  int any = 0;
  for (int c = 0; c < 8; c++) any |= (child_rays[c] != 0) << c;
  return any == hit ? -1 : 16;
}

/* chunk_block_any against tri4_test, per ray of a stream of 16 (any
 * directions) and a block: a ray's verdict is its hit bit, or tri4_test's
 * where the chunk sends it back (*redo). Returns the first ray whose
 * verdict differs, -1 when none does, -3 where this level has no
 * ray-major leaf test; *hits gets the rays hit. Then chunk_block_closest
 * against tri4_test and tri4_nearest: 32 + the first ray whose nearest hit
 * differs in any bit, or that changed without a hit; 17 where it answers
 * for a ray not asked about or sent back. */
#define BLOCK_NAME2(isa) fr_test_block_chunk_##isa
#define BLOCK_NAME(isa) BLOCK_NAME2(isa)
int BLOCK_NAME(FR_ISA_SUFFIX)(const fr_tri4 *blk, const fr_ray *rays, unsigned lanes, int *hits);
int BLOCK_NAME(FR_ISA_SUFFIX)(const fr_tri4 *blk, const fr_ray *rays, unsigned lanes, int *hits) {
#if LEAF_DENSE
  uint32_t idx[16];
  for (int i = 0; i < 16; i++) idx[i] = (uint32_t)i;
  static stream_rays s __attribute__((aligned(64)));
  int uniform;
  const uint64_t valid = stream_setup(rays, idx, 16, &s, &uniform);
  lanes &= (unsigned)valid;
  unsigned redo;
  const unsigned hit = chunk_block_any(blk, &s, 0, lanes, &redo);
  if ((hit | redo) & ~lanes) return 16;
  *hits = 0;
  for (int i = 0; i < 16; i++) {
    if (!((lanes >> i) & 1)) continue;
    tri4_result res;
    const ray_pre ri = stream_ray(&s, i);
    tri4_test(blk, &ri, s.tfar[i], &res);
    const int want = res.mask != 0;
    int got = (int)((hit >> i) & 1);
    if ((redo >> i) & 1) got = want; /* sent back: tri4_test's own verdict */
    if (got != want) return i;
    *hits += got;
  }
  /* closest hits: the nearest lane's t, u, v and id, or nothing changed */
  fr_subtree_hit best[16];
  const fr_subtree_hit none = {-1.0f, -1.0f, -1.0f, 7u};
  float tfar0[16];
  for (int i = 0; i < 16; i++) best[i] = none, tfar0[i] = s.tfar[i];
  const uint32_t k = 5;
  const unsigned took = chunk_block_closest(blk, k, &s, 0, lanes, best, &redo);
  if ((took | redo) & ~lanes || took & redo) return 17;
  for (int i = 0; i < 16; i++) {
    if (!((took >> i) & 1)) {
      if (memcmp(&best[i], &none, sizeof none) || !same_bits(&s.tfar[i], &tfar0[i], 4)) return 32 + i;
      continue;
    }
    tri4_result res;
    const ray_pre ri = stream_ray(&s, i);
    tri4_test(blk, &ri, tfar0[i], &res);
    if (!res.mask) return 32 + i;
    fr_subtree_hit want;
    const float t = tri4_nearest(&res, k, &want);
    if (memcmp(&best[i], &want, sizeof want) || !same_bits(&s.tfar[i], &t, 4)) return 32 + i;
  }
  return -1;
#else
  (void)blk, (void)rays, (void)lanes, (void)hits;
  return -3;
#endif
}
