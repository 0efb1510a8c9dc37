/*
 * A ray stream's rays, set up for the node and triangle tests of
 * trace/bvhn_ray.h all at once: one array per quantity, filled in loops the
 * compiler vectorizes (16 rays to an instruction with AVX-512), and each
 * ray's values broadcast into a ray_pre where a test reads them
 * (stream_ray). Setting rays up one by one into ray_pre records (ray_setup:
 * six scalar divisions and some 400 bytes of broadcasts per ray) took a
 * fifth of the any-hit streams' time on kitchen's soft-shadow rays.
 * Bit for bit what ray_setup computes. Also the ray-major node test of 16
 * of a stream's rays (chunk_node). Include after base/simd.h with FR_WIDTH
 * defined.
 */
#ifndef FR_TRACE_STREAM_RAYS_H
#define FR_TRACE_STREAM_RAYS_H
#include "trace/wide/bvhn_ray.h"
#define FR_PACKET 16 /* a chunk of a stream: 16 rays (chunk_node) */
#include "base/simd_packet.h"

typedef struct stream_rays {
  float ox[FR_STREAM_MAX], oy[FR_STREAM_MAX], oz[FR_STREAM_MAX];
  float dx[FR_STREAM_MAX], dy[FR_STREAM_MAX], dz[FR_STREAM_MAX];
  float nrx[FR_STREAM_MAX], nry[FR_STREAM_MAX], nrz[FR_STREAM_MAX];
  float nrx_w[FR_STREAM_MAX], nry_w[FR_STREAM_MAX], nrz_w[FR_STREAM_MAX];
  float okx[FR_STREAM_MAX], oky[FR_STREAM_MAX], okz[FR_STREAM_MAX];
  float sx[FR_STREAM_MAX], sy[FR_STREAM_MAX], nsz[FR_STREAM_MAX];
  float tnear[FR_STREAM_MAX], tfar[FR_STREAM_MAX]; /* closest hits lower tfar as they go */
  int32_t kx4[FR_STREAM_MAX], ky4[FR_STREAM_MAX], kz4[FR_STREAM_MAX];
  int32_t near_x[FR_STREAM_MAX], near_y[FR_STREAM_MAX], near_z[FR_STREAM_MAX];
  const fr_ray *rays;   /* ray i is rays[idx[i]] */
  const uint32_t *idx;
} __attribute__((aligned(64))) stream_rays;

/* Ray i as ray_setup would have made it. Inlined into the tests, the
 * broadcasts fold into their operations and the unused fields vanish. */
FR_INLINE ray_pre stream_ray(const stream_rays *s, int i) {
  ray_pre r;
  r.ox = VN(s->ox[i]); r.oy = VN(s->oy[i]); r.oz = VN(s->oz[i]);
  r.nrx = VN(s->nrx[i]); r.nry = VN(s->nry[i]); r.nrz = VN(s->nrz[i]);
  r.nrx_w = VN(s->nrx_w[i]); r.nry_w = VN(s->nry_w[i]); r.nrz_w = VN(s->nrz_w[i]);
  r.o_k[0] = vf4(s->okx[i]); r.o_k[1] = vf4(s->oky[i]); r.o_k[2] = vf4(s->okz[i]);
  r.sx = vf4(s->sx[i]); r.sy = vf4(s->sy[i]); r.nsz = vf4(s->nsz[i]);
  r.kx4 = s->kx4[i]; r.ky4 = s->ky4[i]; r.kz4 = s->kz4[i];
  r.near_x = s->near_x[i]; r.near_y = s->near_y[i]; r.near_z = s->near_z[i];
  r.tnear = s->tnear[i];
  r.src = s->rays + s->idx[i];
  return r;
}

/* safe_rcp without a branch (fabsf and copysignf are bit operations) */
FR_INLINE float stream_rcp(float d) { return 1.0f / (fabsf(d) < 1e-18f ? copysignf(1e-18f, d) : d); }

/* rays[idx[0..n)] into s, n <= FR_STREAM_MAX; returns the valid rays' bits
 * (fr_ray_invalid), *uniform whether those all share the direction signs.
 * An invalid ray's values are made but never read. */
FR_INLINE uint64_t stream_setup(const fr_ray *rays, const uint32_t *idx, int n, stream_rays *s, int *uniform) {
  uint64_t active = 0;
  FR_COUNT(rays, (uint64_t)n);
  s->rays = rays;
  s->idx = idx;
  /* 16 records at a time, loaded by index and transposed in registers,
   * fr_ray_invalid's checks made lane by lane (test_stream_setup holds
   * the two to the same verdict): gathered one by one with the scalar
   * check, the rays of streams sorted by octant took 7% of dragon
   * soft16's stream time. */
  const vpf inf = vp(INFINITY), zero = vp(0.0f);
  for (int o = 0; o < n; o += 16) {
    const int k = n - o < 16 ? n - o : 16;
    vpf f[8]; /* org xyz, tnear, dir xyz, tfar (fr_ray's layout) */
    vp_load_records8_at((const float *)rays, sizeof(fr_ray) / sizeof(float), idx + o, k, f);
    vp_store(s->ox + o, f[0]); vp_store(s->oy + o, f[1]); vp_store(s->oz + o, f[2]); vp_store(s->tnear + o, f[3]);
    vp_store(s->dx + o, f[4]); vp_store(s->dy + o, f[5]); vp_store(s->dz + o, f[6]); vp_store(s->tfar + o, f[7]);
    unsigned ok = vpm_bits(vp_le(f[3], f[7]));
    ok &= ~(vpm_bits(vp_eq(f[4], zero)) & vpm_bits(vp_eq(f[5], zero)) & vpm_bits(vp_eq(f[6], zero)));
    for (int a = 0; a < 3; a++) ok &= vpm_bits(vp_lt(vp_abs(f[a]), inf)) & vpm_bits(vp_lt(vp_abs(f[4 + a]), inf));
    active |= (uint64_t)(ok & ((1u << k) - 1u)) << o;
  }
  for (int i = 0; i < n; i++) { /* the node test's values */
    const float rx = stream_rcp(s->dx[i]), ry = stream_rcp(s->dy[i]), rz = stream_rcp(s->dz[i]);
    s->nrx[i] = -rx; s->nry[i] = -ry; s->nrz[i] = -rz;
    s->nrx_w[i] = -rx * ROUND_UP; s->nry_w[i] = -ry * ROUND_UP; s->nrz_w[i] = -rz * ROUND_UP;
    s->near_x[i] = rx >= 0.0f ? 0 : W;
    s->near_y[i] = ry >= 0.0f ? 2 * W : 3 * W;
    s->near_z[i] = rz >= 0.0f ? 4 * W : 5 * W;
  }
  /* fr_wt_setup's axes and shear: every choice a select on values at hand
   * (an indexed read or a branch keeps the loop scalar) */
  for (int i = 0; i < n; i++) {
    const float dx = s->dx[i], dy = s->dy[i], dz = s->dz[i];
    const float ax = fabsf(dx), ay = fabsf(dy), az = fabsf(dz);
    const int z0 = (ax > ay) & (ax > az), z1 = (ax <= ay) & (ay > az); /* kz = 0, 1, else 2 */
    const float vz = z0 ? dx : z1 ? dy : dz;
    /* kx, ky: the next two axes after kz, swapped where vz < 0 (the winding) */
    const int neg = vz < 0.0f, k0 = z0 ? 1 : z1 ? 2 : 0, k1 = z0 ? 2 : z1 ? 0 : 1;
    const float u0 = z0 ? dy : z1 ? dz : dx, u1 = z0 ? dz : z1 ? dx : dy;
    const float p0 = z0 ? s->oy[i] : z1 ? s->oz[i] : s->ox[i], p1 = z0 ? s->oz[i] : z1 ? s->ox[i] : s->oy[i];
    s->sx[i] = (neg ? u1 : u0) / vz; s->sy[i] = (neg ? u0 : u1) / vz; s->nsz[i] = -(1.0f / vz);
    s->okx[i] = neg ? p1 : p0; s->oky[i] = neg ? p0 : p1; s->okz[i] = z0 ? s->ox[i] : z1 ? s->oy[i] : s->oz[i];
    s->kx4[i] = 4 * (neg ? k1 : k0); s->ky4[i] = 4 * (neg ? k0 : k1); s->kz4[i] = z0 ? 0 : z1 ? 4 : 8;
  }
  *uniform = 1;
  const int f = active ? __builtin_ctzll(active) : 0; /* the first valid ray */
  for (uint64_t m = active; m; m &= m - 1) {
    const int i = __builtin_ctzll(m);
    if (s->near_x[i] != s->near_x[f] || s->near_y[i] != s->near_y[f] || s->near_z[i] != s->near_z[f]) *uniform = 0;
  }
  return active;
}

/* Chunks of 16 rays of a stream where at least STREAM_DENSE of them reach
 * a node are tested child by child (ray-major, chunk_node), the rest ray
 * by ray (node-major: one ray against all W boxes). Ray-major fills 16
 * lanes where node-major fills W, but pays a mask per child; it pays only
 * where a register holds 16 floats. Of a kitchen soft16 stream's node
 * visits, a quarter have all 64 rays and a third at most 4 (dragon: 5% and
 * 61%). 12 of 16 is where chunks measured fastest. */
#if defined(FR_BUILD_ISA_AVX512)
#define STREAM_DENSE 12
#else
#define STREAM_DENSE 0 /* never */
#endif

/* The rays `lanes` of chunk o (rays o .. o + 15, all < the stream's n)
 * against node n's children, one child's planes against 16 rays at once:
 * each lane the operations of planes_test for that ray and child, so the
 * same bits. All rays share r0's direction signs. child_rays[c] gains
 * the rays that hit child c, *hit the children some ray hit. */
FR_INLINE void chunk_node(const node_t *n, const stream_rays *s, int o, unsigned lanes, const ray_pre *r0,
                          uint64_t child_rays[8], int *hit) {
  const float *f = (const float *)n;
  const vpf ox = vp_load(s->ox + o), oy = vp_load(s->oy + o), oz = vp_load(s->oz + o);
  const vpf nrx = vp_load(s->nrx + o), nry = vp_load(s->nry + o), nrz = vp_load(s->nrz + o);
  const vpf wx = vp_load(s->nrx_w + o), wy = vp_load(s->nry_w + o), wz = vp_load(s->nrz_w + o);
  const vpf tn0 = vp_load(s->tnear + o), tf0 = vp_mul(vp_load(s->tfar + o), vp(ROUND_UP));
  const int nx = r0->near_x, ny = r0->near_y, nz = r0->near_z;
  for (int c = 0; c < (int)n->nchildren; c++) {
    const vpf tnx = vp_mul(vp_sub(ox, vp(f[nx + c])), nrx), tny = vp_mul(vp_sub(oy, vp(f[ny + c])), nry);
    const vpf tnz = vp_mul(vp_sub(oz, vp(f[nz + c])), nrz);
    const vpf tfx = vp_mul(vp_sub(ox, vp(f[(nx ^ W) + c])), wx), tfy = vp_mul(vp_sub(oy, vp(f[(ny ^ W) + c])), wy);
    const vpf tfz = vp_mul(vp_sub(oz, vp(f[(nz ^ W) + c])), wz);
    const vpf tn = vp_imax(vp_imax(tnx, tny), vp_imax(tnz, tn0)), tf = vp_imin(vp_imin(tfx, tfy), vp_imin(tfz, tf0));
    const unsigned bits = vpm_bits(vp_le(tn, tf)) & lanes;
    child_rays[c] |= (uint64_t)bits << o;
    *hit |= (bits != 0) << c;
  }
}

/* Leaf blocks reached by at least LEAF_DENSE of a chunk's 16 rays are
 * tested ray-major (chunk_block_any, chunk_block_closest): each triangle
 * against those rays at once, 16 to a register, rather than two rays
 * against a block at a time (tri4_test2). Each ray has its own shear axes,
 * so every vertex coordinate is picked out per lane by a permute from the
 * block's rows. AVX-512 only: it needs 16 lanes and the permute. */
#if defined(FR_BUILD_ISA_AVX512)
#define LEAF_DENSE 8

/* The rays of the first chunk from *o on (o a multiple of 16, below n)
 * with at least LEAF_DENSE of m, *o its first ray; 0 where none is left. */
FR_INLINE unsigned next_dense_chunk(uint64_t m, int n, int *o) {
  for (; *o < n; *o += 16) {
    const unsigned lanes = (unsigned)(m >> *o) & 0xFFFFu;
    if (__builtin_popcount(lanes) >= LEAF_DENSE) return lanes;
  }
  return 0;
}

/* What the ray-major test reads of a chunk's rays, and the block's rows:
 * coordinate a of lane l of a vertex at 4 a + l (fr_tri4's layout). A
 * chunk past the stream's end reads stale lanes, which its masks leave out
 * (a permute reads only an index's low four bits). */
typedef struct chunk_leaf {
  __m512i kx, ky, kz;
  __m512 okx, oky, okz, sx, sy, nsz, tn;
  __m512 A, B, C;
} chunk_leaf;

FR_INLINE chunk_leaf chunk_leaf_load(const fr_tri4 *tr, const stream_rays *s, int o) {
  chunk_leaf c = {_mm512_load_si512((const void *)(s->kx4 + o)), _mm512_load_si512((const void *)(s->ky4 + o)),
                  _mm512_load_si512((const void *)(s->kz4 + o)), _mm512_load_ps(s->okx + o),
                  _mm512_load_ps(s->oky + o), _mm512_load_ps(s->okz + o), _mm512_load_ps(s->sx + o),
                  _mm512_load_ps(s->sy + o), _mm512_load_ps(s->nsz + o), _mm512_load_ps(s->tnear + o),
                  _mm512_loadu_ps(tr->v0[0]), _mm512_loadu_ps(tr->v1[0]), _mm512_loadu_ps(tr->v2[0])};
  return c;
}

/* Triangle l of the block against the rays `lanes`, each lane the
 * operations of tri4_test for that ray and triangle: the rays hit in
 * (tnear, tf), their t, edge values e1, e2 and 1 / det; *zeros gains the
 * rays with an edge value of exactly zero, left to tri4_test's exact path. */
FR_INLINE unsigned chunk_tri(const chunk_leaf *c, int l, __m512 tf, unsigned lanes, unsigned *zeros, __m512 *t,
                             __m512 *e1_out, __m512 *e2_out, __m512 *inv_out) {
  const __m512 zero = _mm512_setzero_ps();
  const __m512i L = _mm512_set1_epi32(l);
  const __m512i ix = _mm512_add_epi32(c->kx, L), iy = _mm512_add_epi32(c->ky, L), iz = _mm512_add_epi32(c->kz, L);
  const __m512 az = _mm512_sub_ps(c->okz, _mm512_permutexvar_ps(iz, c->A));
  const __m512 bz = _mm512_sub_ps(c->okz, _mm512_permutexvar_ps(iz, c->B));
  const __m512 cz = _mm512_sub_ps(c->okz, _mm512_permutexvar_ps(iz, c->C));
  const __m512 ax = _mm512_sub_ps(_mm512_sub_ps(c->okx, _mm512_permutexvar_ps(ix, c->A)), _mm512_mul_ps(c->sx, az));
  const __m512 ay = _mm512_sub_ps(_mm512_sub_ps(c->oky, _mm512_permutexvar_ps(iy, c->A)), _mm512_mul_ps(c->sy, az));
  const __m512 bx = _mm512_sub_ps(_mm512_sub_ps(c->okx, _mm512_permutexvar_ps(ix, c->B)), _mm512_mul_ps(c->sx, bz));
  const __m512 by = _mm512_sub_ps(_mm512_sub_ps(c->oky, _mm512_permutexvar_ps(iy, c->B)), _mm512_mul_ps(c->sy, bz));
  const __m512 cx = _mm512_sub_ps(_mm512_sub_ps(c->okx, _mm512_permutexvar_ps(ix, c->C)), _mm512_mul_ps(c->sx, cz));
  const __m512 cy = _mm512_sub_ps(_mm512_sub_ps(c->oky, _mm512_permutexvar_ps(iy, c->C)), _mm512_mul_ps(c->sy, cz));
  const __m512 e0 = _mm512_sub_ps(_mm512_mul_ps(cx, by), _mm512_mul_ps(cy, bx));
  const __m512 e1 = _mm512_sub_ps(_mm512_mul_ps(ax, cy), _mm512_mul_ps(ay, cx));
  const __m512 e2 = _mm512_sub_ps(_mm512_mul_ps(bx, ay), _mm512_mul_ps(by, ax));
  const unsigned z = (unsigned)(_mm512_cmp_ps_mask(e0, zero, _CMP_EQ_OQ) | _mm512_cmp_ps_mask(e1, zero, _CMP_EQ_OQ) |
                                _mm512_cmp_ps_mask(e2, zero, _CMP_EQ_OQ)) & lanes;
  *zeros |= z;
  const __m512 lo = _mm512_min_ps(e0, _mm512_min_ps(e1, e2)), hi = _mm512_max_ps(e0, _mm512_max_ps(e1, e2));
  const unsigned inside =
      (unsigned)(_mm512_cmp_ps_mask(lo, zero, _CMP_GE_OQ) | _mm512_cmp_ps_mask(hi, zero, _CMP_LE_OQ)) & lanes & ~z;
  if (!inside) return 0;
  const __m512 det = _mm512_add_ps(_mm512_add_ps(e0, e1), e2);
  const __m512 inv = _mm512_div_ps(_mm512_set1_ps(1.0f), det);
  const __m512 tz = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(e0, _mm512_mul_ps(c->nsz, az)),
                                                _mm512_mul_ps(e1, _mm512_mul_ps(c->nsz, bz))),
                                  _mm512_mul_ps(e2, _mm512_mul_ps(c->nsz, cz)));
  *t = _mm512_mul_ps(tz, inv);
  *e1_out = e1;
  *e2_out = e2;
  *inv_out = inv;
  return inside & (unsigned)(_mm512_cmp_ps_mask(det, zero, _CMP_NEQ_UQ) & _mm512_cmp_ps_mask(*t, c->tn, _CMP_GT_OQ) &
                             _mm512_cmp_ps_mask(*t, tf, _CMP_LT_OQ));
}

/* Rays `lanes` of chunk o (rays o .. o + 15) against block tr for any hit:
 * returns the rays with one. *redo gets the rays without one whose verdict
 * tri4_test must give: an exact zero, or a hit on a thin triangle only
 * (the plane's t). */
FR_INLINE unsigned chunk_block_any(const fr_tri4 *tr, const stream_rays *s, int o, unsigned lanes, unsigned *redo) {
  const chunk_leaf c = chunk_leaf_load(tr, s, o);
  const __m512 tf = _mm512_load_ps(s->tfar + o);
  unsigned hit = 0, zeros = 0, thin = 0;
  for (int l = 0; l < 4; l++) {
    const uint32_t id = tr->prim[l];
    if (id == FR_INVALID_ID) continue; /* NaN vertices: no hit */
    __m512 t, e1, e2, inv;
    const unsigned ok = chunk_tri(&c, l, tf, lanes, &zeros, &t, &e1, &e2, &inv);
    if (id & FR_TRI4_THIN) thin |= ok;
    else hit |= ok;
  }
  *redo = (zeros | thin) & ~hit;
  return hit;
}

/* The same for closest hits, as tri4_test and tri4_nearest give them for
 * block k: a ray takes the nearest of its lanes hit before its tfar, the
 * first on ties, into best[o + i] and tfar[o + i]; returns those rays.
 * *redo gets the rays for which tri4_test must decide the whole block
 * (an exact zero, or a hit on a thin triangle), left as they were. */
FR_INLINE unsigned chunk_block_closest(const fr_tri4 *tr, uint32_t k, stream_rays *s, int o, unsigned lanes,
                                       fr_subtree_hit *best, unsigned *redo) {
  const chunk_leaf c = chunk_leaf_load(tr, s, o);
  __m512 bt = _mm512_load_ps(s->tfar + o), bu = _mm512_setzero_ps(), bv = bu;
  __m512i bid = _mm512_setzero_si512();
  unsigned got = 0, zeros = 0, thin = 0;
  for (int l = 0; l < 4; l++) {
    const uint32_t id = tr->prim[l];
    if (id == FR_INVALID_ID) continue;
    __m512 t, e1, e2, inv;
    const unsigned ok = chunk_tri(&c, l, bt, lanes, &zeros, &t, &e1, &e2, &inv);
    if (!ok) continue;
    if (id & FR_TRI4_THIN) { thin |= ok; continue; }
    const __mmask16 m = (__mmask16)ok;
    bt = _mm512_mask_blend_ps(m, bt, t);
    bu = _mm512_mask_blend_ps(m, bu, _mm512_mul_ps(e1, inv));
    bv = _mm512_mask_blend_ps(m, bv, _mm512_mul_ps(e2, inv));
    bid = _mm512_mask_blend_epi32(m, bid, _mm512_set1_epi32((int)(4 * k + (uint32_t)l)));
    got |= ok;
  }
  *redo = zeros | thin;
  got &= ~*redo;
  if (got) {
    float T[16] __attribute__((aligned(64))), U[16] __attribute__((aligned(64))), V[16] __attribute__((aligned(64)));
    uint32_t I[16] __attribute__((aligned(64)));
    _mm512_store_ps(T, bt); _mm512_store_ps(U, bu); _mm512_store_ps(V, bv);
    _mm512_store_si512((void *)I, bid);
    for (unsigned g = got; g; g &= g - 1) {
      const int i = __builtin_ctz(g);
      s->tfar[o + i] = T[i];
      best[o + i] = (fr_subtree_hit){T[i], U[i], V[i], I[i]};
    }
  }
  return got;
}
#else
#define LEAF_DENSE 0 /* never */
#endif
#endif
