/*
 * Triangle kernels against each other on random triangles and rays: the
 * watertight test and Shevtsov's record against Möller–Trumbore (float) and a
 * double-precision reference; the axis-aligned fast path against the general
 * path; degenerate triangles never hit; nothing returns NaN.
 */
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>
#include "accel/bvhn.h"
#include "geom/tri_moller.h"
#include "geom/tri_shevtsov.h"
#include "geom/tri_watertight.h"
#include "trace/kernels.h"
#include "test_util.h"

static vec3 rnd3(fr_rng *r, float s) { return v3(urand(r, -s, s), urand(r, -s, s), urand(r, -s, s)); }

/* Barycentric distance to the nearest edge, in double (negative: outside). */
static double margin_of(vec3 o, vec3 d, vec3 a, vec3 b, vec3 c, double *t) {
  float pos[9] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z};
  uint32_t idx[3] = {0, 1, 2}, prim;
  double m;
  fr_ray ray = {{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
  *t = brute_force(pos, idx, 1, &ray, &prim, &m, 1);
  return prim == 0 ? m : -m;
}

static void test_agreement(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(3, 3);
  int compared = 0, hits = 0, fast_path = 0;
  for (int i = 0; i < 200000; i++) {
    vec3 a = rnd3(&r, 1), b = rnd3(&r, 1), c = rnd3(&r, 1);
    if (i % 3 == 0) { b.y = a.y; c.y = a.y; } /* axis-aligned: Shevtsov's fast path */
    vec3 o = rnd3(&r, 3), tgt = rnd3(&r, 0.7f), d = v3_sub(tgt, o);
    double tref;
    double m = margin_of(o, d, a, b, c, &tref);
    fr_tri_shevtsov rec;
    assert_true(fr_tri_shevtsov_make(&rec, a, b, c, 7));
    fast_path += rec.axis_aligned;
    fr_wt_ray w = fr_wt_setup(d);
    float t1 = 0, u1 = 0, v1 = 0, t2 = 0, u2 = 0, v2 = 0, t3 = 0, u3 = 0, v3 = 0;
    int h1 = fr_tri_moller(o, d, 0.0f, INFINITY, a, b, c, &t1, &u1, &v1);
    int h2 = fr_tri_shevtsov_test(&rec, o, d, 0.0f, INFINITY, &t2, &u2, &v2);
    int h3 = fr_tri_watertight(&w, o, d, 0.0f, INFINITY, a, b, c, &t3, &u3, &v3);
    if (fabs(m) < 1e-4) continue; /* within rounding of an edge */
    compared++;
    int want = m > 0 && isfinite(tref);
    assert_int_equal(h1, want);
    assert_int_equal(h2, want);
    assert_int_equal(h3, want);
    if (!want) continue;
    hits++;
    double tol = 1e-4 * fmax(1.0, tref);
    assert_true(fabs(t1 - tref) <= tol && fabs(t2 - tref) <= tol && fabs(t3 - tref) <= tol);
    assert_true(fabsf(u1 - u2) < 1e-3f && fabsf(v1 - v2) < 1e-3f);
    assert_true(fabsf(u1 - u3) < 1e-3f && fabsf(v1 - v3) < 1e-3f);
  }
  print_message("compared %d, hits %d, axis-aligned records %d\n", compared, hits, fast_path);
  assert_true(compared > 190000 && hits > 10000 && fast_path >= 60000);
}

/* The fast path computes what the general path computes for such a triangle. */
static void test_axis_aligned_fast_path(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(4, 4);
  for (int i = 0; i < 50000; i++) {
    vec3 a = rnd3(&r, 1), b = rnd3(&r, 1), c = rnd3(&r, 1);
    a.z = b.z = c.z = 0.25f;
    fr_tri_shevtsov rec;
    if (!fr_tri_shevtsov_make(&rec, a, b, c, 0)) continue;
    assert_true(rec.axis_aligned);
    fr_tri_shevtsov slow = rec;
    slow.axis_aligned = 0;
    vec3 o = rnd3(&r, 3), d = v3_sub(rnd3(&r, 1), o);
    float t1 = 0, u1 = 0, v1 = 0, t2 = 0, u2 = 0, v2 = 0;
    int h1 = fr_tri_shevtsov_test(&rec, o, d, 0.0f, INFINITY, &t1, &u1, &v1);
    int h2 = fr_tri_shevtsov_test(&slow, o, d, 0.0f, INFINITY, &t2, &u2, &v2);
    assert_int_equal(h1, h2); /* n_u = n_v = 0: both paths do the same arithmetic */
    if (h1) assert_true(t1 == t2 && u1 == u2 && v1 == v2);
  }
}

static void test_degenerate_and_nan(void **st) {
  (void)st;
  vec3 a = v3(0, 0, 0), b = v3(1, 1, 1), c = v3(2, 2, 2); /* collinear */
  fr_tri_shevtsov rec;
  assert_false(fr_tri_shevtsov_make(&rec, a, b, c, 0));
  assert_false(fr_tri_shevtsov_make(&rec, a, a, a, 0));
  fr_rng r = fr_rng_seed(5, 5);
  for (int i = 0; i < 10000; i++) {
    vec3 o = rnd3(&r, 3), d = v3_sub(rnd3(&r, 2), o);
    float t = NAN, u = NAN, v = NAN;
    fr_wt_ray w = fr_wt_setup(d);
    assert_false(fr_tri_moller(o, d, 0.0f, INFINITY, a, b, c, &t, &u, &v));
    assert_false(fr_tri_watertight(&w, o, d, 0.0f, INFINITY, a, b, c, &t, &u, &v));
    /* NaN anywhere: no hit */
    vec3 bad = v3(NAN, 0, 0);
    assert_false(fr_tri_moller(bad, d, 0.0f, INFINITY, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0), &t, &u, &v));
    fr_wt_ray wn = fr_wt_setup(v3(NAN, 1, 0));
    assert_false(fr_tri_watertight(&wn, o, v3(NAN, 1, 0), 0.0f, INFINITY, v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0), &t, &u, &v));
  }
}

uint32_t fr_test_child_sort8_avx2(const uint32_t *child, int mask, const float *dist, void *out);
uint32_t fr_test_child_sort8_avx512(const uint32_t *child, int mask, const float *dist, void *out);

/* The scalar definition of the order: key = the distance as a monotone
 * integer with its low three bits replaced by the slot, descending. */
static int64_t sort_key(float d, int slot) {
  int32_t b;
  memcpy(&b, &d, 4);
  if (b < 0) b ^= 0x7fffffff;
  return (int64_t)((b & ~7) | slot);
}

/* fr_child_sort8 at AVX2 and AVX-512 against that definition: every hit child
 * once, farthest first, with its exact distance; the nearest returned. */
static void test_child_sort8(void **st) {
  (void)st;
  typedef uint32_t (*sort_fn)(const uint32_t *, int, const float *, void *);
  const struct { fr_isa isa; sort_fn fn; } levels[] = {{FR_ISA_AVX2, fr_test_child_sort8_avx2},
                                                        {FR_ISA_AVX512, fr_test_child_sort8_avx512}};
  fr_rng r = fr_rng_seed(11, 5);
  int tested = 0;
  for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
    if (!fr_isa_supported(levels[l].isa)) continue;
    for (int it = 0; it < 200000; it++) {
      uint32_t child[8];
      float dist[8];
      int mask = (int)(fr_rng_u32(&r) & 0xff) | 1 << (it % 8);
      for (int i = 0; i < 8; i++) {
        child[i] = fr_rng_u32(&r);
        /* ties, values 1 ulp apart, negatives (a negative tnear), zeros */
        switch (it % 4) {
        case 0: dist[i] = urand(&r, 0.0f, 100.0f); break;
        case 1: dist[i] = (float)(fr_rng_u32(&r) % 3); break;
        case 2: dist[i] = nextafterf(1.0f, (fr_rng_u32(&r) & 1) ? 2.0f : 0.0f); break;
        default: dist[i] = urand(&r, -5.0f, 5.0f); break;
        }
      }
      struct { uint32_t ref; float dist; } out[8], want[8];
      /* the hit slots ordered by key, descending (at most 8: exchange sort) */
      int slot_of[8], n = 0;
      for (int i = 0; i < 8; i++)
        if ((mask >> i) & 1) slot_of[n++] = i;
      for (int a = 0; a < n; a++)
        for (int b = a + 1; b < n; b++)
          if (sort_key(dist[slot_of[b]], slot_of[b]) > sort_key(dist[slot_of[a]], slot_of[a])) {
            int t = slot_of[a]; slot_of[a] = slot_of[b]; slot_of[b] = t;
          }
      for (int a = 0; a < n; a++) { want[a].ref = child[slot_of[a]]; want[a].dist = dist[slot_of[a]]; }
      uint32_t nearest = levels[l].fn(child, mask, dist, out);
      assert_int_equal(nearest, want[n - 1].ref);
      for (int a = 0; a < n; a++) {
        assert_int_equal(out[a].ref, want[a].ref);
        assert_memory_equal(&out[a].dist, &want[a].dist, sizeof(float));
      }
      tested++;
    }
  }
  print_message("child order: %d nodes\n", tested);
}

typedef void (*add_where_fn)(const float *, int, const float *, float *, float *);
void fr_test_add_where_scalar(const float *a, int lanes, const float *b, float *out8, float *out4);
void fr_test_add_where_avx2(const float *a, int lanes, const float *b, float *out8, float *out4);
void fr_test_add_where_avx512(const float *a, int lanes, const float *b, float *out8, float *out4);

/* vf8_add_where and vf4_add_where on every level: a + b exactly in the lanes
 * asked for, a untouched in the others, whatever b holds there (the ray
 * streams pass entry distances that are infinite or NaN in missed lanes). */
static void test_add_where(void **st) {
  (void)st;
  const struct { fr_isa isa; add_where_fn fn; } levels[] = {{FR_ISA_SCALAR, fr_test_add_where_scalar},
                                                            {FR_ISA_AVX2, fr_test_add_where_avx2},
                                                            {FR_ISA_AVX512, fr_test_add_where_avx512}};
  fr_rng r = fr_rng_seed(12, 7);
  int tested = 0;
  for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
    if (!fr_isa_supported(levels[l].isa)) continue;
    for (int lanes = 0; lanes < 256; lanes++) {
      float a[8], b[8], out8[8], out4[4];
      for (int i = 0; i < 8; i++) {
        a[i] = urand(&r, -10.0f, 10.0f);
        b[i] = (lanes >> i) & 1 ? urand(&r, -10.0f, 10.0f) : (i % 3 == 0 ? NAN : i % 3 == 1 ? INFINITY : -INFINITY);
      }
      levels[l].fn(a, lanes, b, out8, out4);
      for (int i = 0; i < 8; i++) {
        float want = (lanes >> i) & 1 ? a[i] + b[i] : a[i];
        assert_memory_equal(&out8[i], &want, sizeof(float));
        if (i < 4) assert_memory_equal(&out4[i], &want, sizeof(float));
      }
      tested++;
    }
  }
  print_message("masked adds: %d lane sets\n", tested);
}

typedef void (*imin_imax_fn)(const float *, const float *, float *, float *, float *, float *);
void fr_test_imin_imax_scalar(const float *a, const float *b, float *min8, float *max8, float *min4, float *max4);
void fr_test_imin_imax_avx2(const float *a, const float *b, float *min8, float *max8, float *min4, float *max4);
void fr_test_imin_imax_avx512(const float *a, const float *b, float *min8, float *max8, float *min4, float *max4);

static int32_t float_bits(float f) {
  int32_t i;
  memcpy(&i, &f, sizeof i);
  return i;
}

/* A float from a mix that has the cases the node test meets: zeros of both
 * signs, infinities, and finite values of either sign and many scales. */
static float mixed_float(fr_rng *r) {
  static const float special[] = {0.0f, -0.0f, INFINITY, -INFINITY, 1.0f, -1.0f, 0x1p-149f, -0x1p-149f};
  const unsigned k = fr_rng_u32(r) % 16;
  if (k < 8) return special[k];
  return urand(r, -1.0f, 1.0f) * ldexpf(1.0f, (int)(fr_rng_u32(r) % 40) - 20);
}

/* max (or min) of v[0..3] as planes_test takes it, by a level's imax (imin) */
static float level_reduce(imin_imax_fn fn, const float *v, int want_max) {
  float a[8] = {v[0], v[2]}, b[8] = {v[1], v[3]}, mn[8], mx[8], mn4[4], mx4[4];
  fn(a, b, mn, mx, mn4, mx4);
  float a2[8] = {want_max ? mx[0] : mn[0]}, b2[8] = {want_max ? mx[1] : mn[1]};
  fn(a2, b2, mn, mx, mn4, mx4);
  return want_max ? mx[0] : mn[0];
}

/* vf8/vf4_imin and _imax on every level pick the operand whose bit pattern
 * is the lesser or greater signed integer. And the node test built on them
 * (bvhn_ray.h, planes_test): max(near distances, tnear) <= min(far
 * distances, tfar) never rejects what the float forms accept, and with
 * tnear >= +0 and no far value of -0 accepts the same. */
static void test_imin_imax(void **st) {
  (void)st;
  const struct { fr_isa isa; imin_imax_fn fn; } levels[] = {{FR_ISA_SCALAR, fr_test_imin_imax_scalar},
                                                            {FR_ISA_AVX2, fr_test_imin_imax_avx2},
                                                            {FR_ISA_AVX512, fr_test_imin_imax_avx512}};
  fr_rng r = fr_rng_seed(13, 5);
  int tested = 0, boxes = 0;
  for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
    if (!fr_isa_supported(levels[l].isa)) continue;
    for (int round = 0; round < 20000; round++) {
      float a[8], b[8], mn8[8], mx8[8], mn4[4], mx4[4];
      for (int i = 0; i < 8; i++) a[i] = mixed_float(&r), b[i] = mixed_float(&r);
      levels[l].fn(a, b, mn8, mx8, mn4, mx4);
      for (int i = 0; i < 8; i++) {
        const float lo = float_bits(a[i]) < float_bits(b[i]) ? a[i] : b[i];
        const float hi = float_bits(a[i]) > float_bits(b[i]) ? a[i] : b[i];
        assert_memory_equal(&mn8[i], &lo, sizeof(float));
        assert_memory_equal(&mx8[i], &hi, sizeof(float));
        if (i < 4) {
          assert_memory_equal(&mn4[i], &lo, sizeof(float));
          assert_memory_equal(&mx4[i], &hi, sizeof(float));
        }
      }
      /* a node test as planes_test reduces it: a[0..2] near distances,
       * a[3] tnear, a[4..6] far distances, a[7] tfar */
      const float tn = level_reduce(levels[l].fn, a, 1), tf = level_reduce(levels[l].fn, a + 4, 0);
      const float tn_float = fmaxf(fmaxf(a[0], a[1]), fmaxf(a[2], a[3]));
      const float tf_float = fminf(fminf(a[4], a[5]), fminf(a[6], a[7]));
      const int want = tn_float <= tf_float, got = tn <= tf;
      if (want) assert_true(got); /* never rejects what the float test accepts */
      int far_neg_zero = 0;
      for (int i = 4; i < 8; i++) far_neg_zero |= float_bits(a[i]) == float_bits(-0.0f);
      const int exact = float_bits(a[3]) >= 0 && !far_neg_zero;
      if (exact) assert_int_equal(got, want);
      tested++;
      boxes += exact;
    }
  }
  print_message("integer-order min/max: %d lane sets, %d node tests exact\n", tested, boxes);
}

typedef void (*load_records_fn)(const float *, size_t, const uint32_t *, int, float (*)[16], float (*)[16], float *);
void fr_test_load_records_scalar(const float *src, size_t stride, const uint32_t *idx, int n, float (*out8)[16],
                                 float (*out4)[16], float *back4);
void fr_test_load_records_avx2(const float *src, size_t stride, const uint32_t *idx, int n, float (*out8)[16],
                                 float (*out4)[16], float *back4);
void fr_test_load_records_avx512(const float *src, size_t stride, const uint32_t *idx, int n, float (*out8)[16],
                                 float (*out4)[16], float *back4);

/* The transposing record loads (and the 4-float store) on every level move bits: field k of record
 * i lands in lane i of output k, NaNs and all, at the strides the Whitted
 * shading (12) and the packets (8) use. Loads of the first n records only
 * (the multi-frusta leaves') repeat record n - 1 in the lanes past it and
 * read nothing after the n records: they end right before a page that
 * cannot be read. Loads by index (the ray streams') read the records
 * named, in their order. */
static void test_load_records(void **st) {
  (void)st;
  const struct { fr_isa isa; load_records_fn fn; } levels[] = {{FR_ISA_SCALAR, fr_test_load_records_scalar},
                                                               {FR_ISA_AVX2, fr_test_load_records_avx2},
                                                               {FR_ISA_AVX512, fr_test_load_records_avx512}};
  const size_t page = (size_t)sysconf(_SC_PAGESIZE);
  char *map = mmap(NULL, 2 * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  assert_true(map != MAP_FAILED);
  assert_int_equal(mprotect(map + page, page, PROT_NONE), 0);
  uint32_t src[12 * 16];
  for (size_t i = 0; i < sizeof src / sizeof src[0]; i++) src[i] = 0x7FC00000u + (uint32_t)i; /* distinct NaNs */
  static const int ns[] = {16, 15, 9, 8, 5, 1};
  int tested = 0;
  for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
    if (!fr_isa_supported(levels[l].isa)) continue;
    for (size_t stride = 8; stride <= 12; stride += 4)
      for (size_t j = 0; j < sizeof ns / sizeof ns[0]; j++) {
        const int n = ns[j];
        /* the last record's 8 floats end at the unreadable page (all 16
         * records: the 4-float loads read 64 floats from the start too) */
        const size_t bytes = (stride * (size_t)(n - 1) + 8) * sizeof(float);
        float *at = (float *)(map + page - bytes);
        memcpy(at, src, bytes);
        float out8[8][16], out4[4][16], back4[64];
        levels[l].fn(at, stride, NULL, n, out8, out4, back4);
        for (int i = 0; i < 16; i++) {
          const size_t rec = (size_t)(i < n ? i : n - 1);
          for (int k = 0; k < 8; k++) assert_memory_equal(&out8[k][i], &src[stride * rec + (size_t)k], 4);
        }
        /* by index: the records backwards, the last (by the page) twice */
        uint32_t idx[16];
        for (int i = 0; i < n; i++) idx[i] = (uint32_t)(n - 1 - i);
        if (n > 2) idx[1] = (uint32_t)(n - 1);
        levels[l].fn(at, stride, idx, n, out8, NULL, NULL);
        for (int i = 0; i < 16; i++) {
          const size_t rec = idx[i < n ? i : n - 1];
          for (int k = 0; k < 8; k++) assert_memory_equal(&out8[k][i], &src[stride * rec + (size_t)k], 4);
        }
        if (n == 16) {
          assert_memory_equal(back4, src, sizeof back4);
          for (int i = 0; i < 16; i++)
            for (int k = 0; k < 4; k++) assert_memory_equal(&out4[k][i], &src[4 * i + k], 4);
        }
        tested++;
      }
  }
  munmap(map, 2 * page);
  assert_true(tested >= 2 * 6);
  print_message("record loads: %d level/stride/row-count cases\n", tested);
}

typedef int (*tri4_pair_fn)(const fr_tri4 *, const fr_ray *, const fr_ray *, int *);
int fr_test_tri4_pair_scalar(const fr_tri4 *block, const fr_ray *a, const fr_ray *b, int *hits);
int fr_test_tri4_pair_avx2(const fr_tri4 *block, const fr_ray *a, const fr_ray *b, int *hits);
int fr_test_tri4_pair_avx512(const fr_tri4 *block, const fr_ray *a, const fr_ray *b, int *hits);

/* A block of four random triangles, or (grid) of axis-aligned ones on
 * integer points in z = 0, with an unused NaN lane in every fourth block. */
static void test_block(fr_rng *r, int n, int grid, fr_tri4 *blk) {
  for (int lane = 0; lane < 4; lane++) {
    vec3 v[3];
    for (int k = 0; k < 3; k++) {
      v[k] = grid ? v3((float)(int)urand(r, -3, 3), (float)(int)urand(r, -3, 3), 0.0f) : rnd3(r, 1.0f);
      const float *c = &v[k].x;
      float(*dst)[4] = k == 0 ? blk->v0 : k == 1 ? blk->v1 : blk->v2;
      for (int a = 0; a < 3; a++) dst[a][lane] = (lane == 3 && n % 4 == 1) ? NAN : c[a];
    }
    blk->prim[lane] = (uint32_t)lane;
  }
}

/* A ray at the block. Grid blocks: through a vertex or an edge's midpoint
 * of one of the triangles, from height z, straight down the z axis half the
 * time (no shear, so the edge values through the point are exactly zero:
 * the exact path). Random blocks: from a random point lifted by lift. */
static fr_ray test_ray(fr_rng *r, int grid, const fr_tri4 *blk, float z, float lift) {
  vec3 o, target;
  if (grid) {
    const int lane = (int)urand(r, 0, 3), k = (int)urand(r, 0, 3);
    const float(*src)[4] = k == 0 ? blk->v0 : k == 1 ? blk->v1 : blk->v2;
    const float(*nxt)[4] = k == 0 ? blk->v1 : k == 1 ? blk->v2 : blk->v0;
    const int mid = urand(r, 0, 1) < 0.5f;
    target = v3(src[0][lane], src[1][lane], src[2][lane]);
    if (mid) target = v3_scale(v3_add(target, v3(nxt[0][lane], nxt[1][lane], nxt[2][lane])), 0.5f);
    o = urand(r, 0, 1) < 0.5f ? v3(target.x, target.y, z)
                              : v3((float)(int)urand(r, -3, 3), (float)(int)urand(r, -3, 3), z);
  } else {
    o = v3_add(rnd3(r, 3.0f), v3(0.0f, 0.0f, lift));
    target = rnd3(r, 0.5f);
  }
  const vec3 d = v3_sub(target, o);
  return (fr_ray){{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, urand(r, 0, 1) < 0.2f ? 0.5f : INFINITY};
}

/* The ray streams test two rays against a block at once (tri4_test2): on
 * every level each ray's lanes must be exactly what the one-ray test
 * gives, for random triangles and rays, and for rays through the vertices
 * and edges of axis-aligned triangles, whose edge values are exactly zero
 * (the exact path), with an unused NaN lane in every fourth block. */
static void test_tri4_pair(void **st) {
  (void)st;
  const struct { fr_isa isa; tri4_pair_fn fn; } levels[] = {{FR_ISA_SCALAR, fr_test_tri4_pair_scalar},
                                                            {FR_ISA_AVX2, fr_test_tri4_pair_avx2},
                                                            {FR_ISA_AVX512, fr_test_tri4_pair_avx512}};
  fr_rng r = fr_rng_seed(43, 2);
  long hits = 0, tested = 0;
  for (int n = 0; n < 4000; n++) {
    fr_tri4 blk;
    const int grid = n % 2;
    test_block(&r, n, grid, &blk);
    fr_ray ray[2];
    for (int i = 0; i < 2; i++) ray[i] = test_ray(&r, grid, &blk, urand(&r, 0, 1) < 0.5f ? 4.0f : -4.0f, 0.0f);
    for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
      if (!fr_isa_supported(levels[l].isa)) continue;
      int h = 0;
      if (!levels[l].fn(&blk, &ray[0], &ray[1], &h)) fail_msg("level %zu, case %d: the pair test differs", l, n);
      hits += h;
      tested++;
    }
  }
  print_message("two-ray block tests: %ld across the levels, %ld rays hit\n", tested, hits);
  assert_true(hits > tested / 4);
}

typedef int (*block_chunk_fn)(const fr_tri4 *, const fr_ray *, unsigned, int *);
int fr_test_block_chunk_scalar(const fr_tri4 *blk, const fr_ray *rays, unsigned lanes, int *hits);
int fr_test_block_chunk_avx2(const fr_tri4 *blk, const fr_ray *rays, unsigned lanes, int *hits);
int fr_test_block_chunk_avx512(const fr_tri4 *blk, const fr_ray *rays, unsigned lanes, int *hits);

/* Ray streams test a leaf block reached by many of a chunk's 16 rays
 * ray-major (chunk_block_any and chunk_block_closest, stream_rays.h, where
 * the level has them): each ray's verdict and nearest hit must be the
 * one-ray test's, bit for bit, for rays of any directions
 * (every shear axis in one register) at random and at axis-aligned grid
 * blocks through vertices and edges (exact zeros, which the chunk sends
 * back to tri4_test), with a NaN lane in every fourth block and a thin
 * triangle in every third. */
static void test_block_chunk(void **st) {
  (void)st;
  const struct { fr_isa isa; block_chunk_fn fn; } levels[] = {{FR_ISA_SCALAR, fr_test_block_chunk_scalar},
                                                              {FR_ISA_AVX2, fr_test_block_chunk_avx2},
                                                              {FR_ISA_AVX512, fr_test_block_chunk_avx512}};
  fr_rng r = fr_rng_seed(61, 5);
  long tested = 0, hits = 0;
  for (int n = 0; n < 3000; n++) {
    fr_tri4 blk;
    const int grid = n % 2;
    test_block(&r, n, grid, &blk);
    if (n % 3 == 0) blk.prim[(int)urand(&r, 0, 3.99f)] |= FR_TRI4_THIN;
    fr_ray rays[16];
    for (int i = 0; i < 16; i++) rays[i] = test_ray(&r, grid, &blk, urand(&r, 0, 1) < 0.5f ? 4.0f : -4.0f, 0.0f);
    const unsigned lanes = n % 4 ? 0xFFFFu : (unsigned)(urand(&r, 0, 65535.99f));
    for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
      if (!fr_isa_supported(levels[l].isa)) continue;
      int h = 0;
      const int bad = levels[l].fn(&blk, rays, lanes, &h);
      if (bad == -3) continue; /* no ray-major leaf test on this level */
      if (bad == 16 || bad == 17) fail_msg("level %zu, case %d: an answer for a ray not asked about", l, n);
      if (bad >= 32) fail_msg("level %zu, case %d, ray %d: chunk_block_closest differs from tri4_nearest", l, n, bad - 32);
      if (bad >= 0) fail_msg("level %zu, case %d, ray %d: chunk_block_any differs from tri4_test", l, n, bad);
      hits += h;
      tested++;
    }
  }
  print_message("ray-major leaf blocks: %ld, %ld rays hit\n", tested, hits);
  if (fr_isa_supported(FR_ISA_AVX512)) assert_true(tested > 0 && hits > tested);
}

typedef int (*stream_setup_fn)(const fr_ray *, int, int, int *);
int fr_test_stream_setup_scalar(const fr_ray *rays, int n, int in_row, int *uniform);
int fr_test_stream_setup_avx2(const fr_ray *rays, int n, int in_row, int *uniform);
int fr_test_stream_setup_avx512(const fr_ray *rays, int n, int in_row, int *uniform);

/* A ray streams sets its rays up all at once, lane by lane
 * (stream_rays.h); every value the tests read must be ray_setup's, bit for
 * bit, on every level: for random directions, for directions with zero,
 * signed-zero and tiny components (the reciprocal's clamp) and with ties
 * between components' magnitudes (the shear axis), for invalid rays, and
 * streams of one octant (uniform) or several, their rays in a row or not
 * (loaded by index, 16 at a time, and checked lane by lane). */
static void test_stream_setup(void **st) {
  (void)st;
  const struct { fr_isa isa; stream_setup_fn fn; } levels[] = {{FR_ISA_SCALAR, fr_test_stream_setup_scalar},
                                                                {FR_ISA_AVX2, fr_test_stream_setup_avx2},
                                                                {FR_ISA_AVX512, fr_test_stream_setup_avx512}};
  static const float comp[] = {0.0f, -0.0f, 1e-20f, -1e-20f, 1e-18f, -1e-18f, 1.0f, -1.0f, 0.5f, -2.0f, 3e-5f, -7.0f};
  enum { NC = sizeof comp / sizeof comp[0] };
  fr_rng r = fr_rng_seed(47, 3);
  int tested = 0, uniform_streams = 0;
  for (int n = 0; n < 3000; n++) {
    fr_ray rays[FR_STREAM_MAX];
    const int len = 1 + (int)urand(&r, 0, FR_STREAM_MAX - 1), one_octant = n % 3 == 0;
    for (int i = 0; i < len; i++) {
      const vec3 o = rnd3(&r, 5.0f);
      vec3 d = rnd3(&r, 1.0f);
      float *dc = &d.x;
      for (int a = 0; a < 3; a++) { /* special components, and ties in magnitude */
        const float u = urand(&r, 0, 1);
        if (u < 0.25f) dc[a] = comp[(int)urand(&r, 0, NC - 0.01f)];
        else if (u < 0.4f && a > 0) dc[a] = urand(&r, 0, 1) < 0.5f ? dc[a - 1] : -dc[a - 1];
      }
      if (one_octant) d = v3(fabsf(d.x) + 1e-3f, -fabsf(d.y) - 1e-3f, fabsf(d.z) + 1e-3f);
      rays[i] = (fr_ray){{o.x, o.y, o.z}, urand(&r, 0, 1), {d.x, d.y, d.z}, urand(&r, 0, 1) < 0.5f ? 10.0f : INFINITY};
      const float v = urand(&r, 0, 1); /* now and then an invalid ray */
      if (v < 0.02f) rays[i].dir[(int)urand(&r, 0, 2.99f)] = NAN;
      else if (v < 0.04f) rays[i].tnear = 2.0f * rays[i].tfar + 1.0f;
      else if (v < 0.05f) rays[i].dir[0] = rays[i].dir[1] = rays[i].dir[2] = 0.0f;
    }
    for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
      if (!fr_isa_supported(levels[l].isa)) continue;
      int uniform = 0;
      const int bad = levels[l].fn(rays, len, n % 2, &uniform);
      if (bad == -2) fail_msg("level %zu, stream %d: uniform %d is wrong", l, n, uniform);
      if (bad >= 0)
        fail_msg("level %zu, stream %d, ray %d (dir %a %a %a): not ray_setup's", l, n, bad, rays[bad].dir[0],
                 rays[bad].dir[1], rays[bad].dir[2]);
      uniform_streams += uniform;
      tested++;
    }
  }
  print_message("stream set-ups: %d across the levels, %d of one octant\n", tested, uniform_streams);
  assert_true(uniform_streams > tested / 4);
}

typedef int (*stream_chunk_fn)(const float[6][8], int, const fr_ray *, unsigned, int *);
int fr_test_stream_chunk_scalar(const float planes[6][8], int nchildren, const fr_ray *rays, unsigned lanes, int *hits);
int fr_test_stream_chunk_avx2(const float planes[6][8], int nchildren, const fr_ray *rays, unsigned lanes, int *hits);
int fr_test_stream_chunk_avx512(const float planes[6][8], int nchildren, const fr_ray *rays, unsigned lanes, int *hits);

/* A stream tests dense chunks of 16 rays child by child (chunk_node,
 * stream_rays.h); each ray must get exactly the children the one-ray box
 * test gives it, on every level. The rays' tnear and tfar sit on a child's
 * entry and exit distances, a rounding either way, so a box is often
 * decided by the last bit of an end or by the far planes' widening. */
static void test_stream_chunk(void **st) {
  (void)st;
  const struct { fr_isa isa; stream_chunk_fn fn; } levels[] = {{FR_ISA_SCALAR, fr_test_stream_chunk_scalar},
                                                                {FR_ISA_AVX2, fr_test_stream_chunk_avx2},
                                                                {FR_ISA_AVX512, fr_test_stream_chunk_avx512}};
  static const float nudge[] = {1.0f - 0x1p-21f, 1.0f, 1.0f + 0x1p-22f, 1.0f + 0x1p-20f, 1.0f + 0x1p-19f};
  fr_rng r = fr_rng_seed(53, 7);
  long tested = 0, hits = 0;
  for (int n = 0; n < 3000; n++) {
    float planes[6][8];
    const int nchildren = 2 + (int)urand(&r, 0, 6.99f);
    vec3 lo[8], hi[8];
    for (int c = 0; c < 8; c++) {
      const vec3 a = rnd3(&r, 2.0f), e = v3(urand(&r, 0, 1), urand(&r, 0, 1), urand(&r, 0, 0.3f));
      lo[c] = c < nchildren ? a : v3(INFINITY, INFINITY, INFINITY); /* unused: inverted */
      hi[c] = c < nchildren ? v3_add(a, e) : v3(-INFINITY, -INFINITY, -INFINITY);
      planes[0][c] = lo[c].x; planes[1][c] = hi[c].x; planes[2][c] = lo[c].y;
      planes[3][c] = hi[c].y; planes[4][c] = lo[c].z; planes[5][c] = hi[c].z;
    }
    const vec3 sgn = v3(urand(&r, 0, 1) < 0.5f ? 1.0f : -1.0f, urand(&r, 0, 1) < 0.5f ? 1.0f : -1.0f, 1.0f);
    fr_ray rays[16];
    for (int i = 0; i < 16; i++) {
      vec3 d = rnd3(&r, 1.0f);
      d = v3(sgn.x * (fabsf(d.x) + 1e-3f), sgn.y * (fabsf(d.y) + 1e-3f), sgn.z * (fabsf(d.z) + 1e-3f));
      /* through a point of child c, at t = 4 */
      const int c = (int)urand(&r, 0, nchildren - 0.01f);
      const vec3 e = v3_sub(hi[c], lo[c]);
      const vec3 at = v3_add(lo[c], v3(urand(&r, 0, 1) * e.x, urand(&r, 0, 1) * e.y, urand(&r, 0, 1) * e.z));
      const vec3 o = v3_sub(at, v3_scale(d, 4.0f));
      rays[i] = (fr_ray){{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
      /* that child's slab distances (double): tnear or tfar on one of them */
      const double t0x = ((double)(d.x > 0 ? lo[c].x : hi[c].x) - o.x) / d.x;
      const double t0y = ((double)(d.y > 0 ? lo[c].y : hi[c].y) - o.y) / d.y;
      const double t0z = ((double)lo[c].z - o.z) / d.z;
      const double t1x = ((double)(d.x > 0 ? hi[c].x : lo[c].x) - o.x) / d.x;
      const double t1y = ((double)(d.y > 0 ? hi[c].y : lo[c].y) - o.y) / d.y;
      const double t1z = ((double)hi[c].z - o.z) / d.z;
      const double tin = fmax(fmax(t0x, t0y), t0z), tout = fmin(fmin(t1x, t1y), t1z);
      const float k = nudge[(int)urand(&r, 0, 4.99f)];
      const float u = urand(&r, 0, 1);
      if (u < 0.4f && tin > 0) rays[i].tfar = (float)tin * k;
      else if (u < 0.8f && tout > 0) rays[i].tnear = (float)tout * k;
      else if (u < 0.9f) rays[i].tnear = urand(&r, 0, 6), rays[i].tfar = rays[i].tnear + urand(&r, 0, 2);
    }
    const unsigned lanes = n % 4 ? 0xFFFFu : (unsigned)(urand(&r, 0, 65535.99f));
    for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
      if (!fr_isa_supported(levels[l].isa)) continue;
      int h = 0;
      const int bad = levels[l].fn(planes, nchildren, rays, lanes, &h);
      if (bad == -2) fail_msg("level %zu, case %d: the rays are not of one octant", l, n);
      if (bad == 16) fail_msg("level %zu, case %d: the children hit are not the rays' union", l, n);
      if (bad >= 0) fail_msg("level %zu, case %d, ray %d: chunk_node differs from the box test", l, n, bad);
      hits += h;
      tested++;
    }
  }
  print_message("stream chunks: %ld across the levels, %ld ray-child hits\n", tested, hits);
  assert_true(hits > tested * 8);
}

typedef int (*tri4_quad_fn)(const fr_tri4 *, const fr_ray *, int, int *);
#define QUAD_FNS(p)                                                                  \
  int fr_test_tri4_quad##p##_scalar(const fr_tri4 *, const fr_ray *, int, int *);   \
  int fr_test_tri4_quad##p##_avx2(const fr_tri4 *, const fr_ray *, int, int *);     \
  int fr_test_tri4_quad##p##_avx512(const fr_tri4 *, const fr_ray *, int, int *);
QUAD_FNS(8)
QUAD_FNS(16)

/* Each coordinate of p moved one axis on, rot times (x -> y -> z -> x). */
static void rotate3(float *p, int rot) {
  for (int i = 0; i < rot; i++) {
    const float z = p[2];
    p[2] = p[1]; p[1] = p[0]; p[0] = z;
  }
}

/* Packets test up to four rays against a block at once (quad_test) where
 * their rays share the shear axes: on every level and at both packet
 * sizes, each ray's lanes must be exactly the single-ray test's, for one
 * to eight rays per packet (two or more quad groups), on the cases of the
 * pair test above turned to each axis and both directions along it. */
static void test_tri4_quad(void **st) {
  (void)st;
  const struct { fr_isa isa; int p; tri4_quad_fn fn; } levels[] = {
      {FR_ISA_SCALAR, 8, fr_test_tri4_quad8_scalar},  {FR_ISA_SCALAR, 16, fr_test_tri4_quad16_scalar},
      {FR_ISA_AVX2, 8, fr_test_tri4_quad8_avx2},      {FR_ISA_AVX2, 16, fr_test_tri4_quad16_avx2},
      {FR_ISA_AVX512, 8, fr_test_tri4_quad8_avx512},  {FR_ISA_AVX512, 16, fr_test_tri4_quad16_avx512}};
  fr_rng r = fr_rng_seed(47, 2);
  long hits = 0, tested = 0, declined = 0;
  for (int n = 0; n < 3000; n++) {
    fr_tri4 blk;
    const int grid = n % 2, rot = (n / 2) % 3, nrays = 1 + (n / 6) % 8;
    const float z = (n / 48) % 2 ? 8.0f : -8.0f; /* beyond the grid's 6: z is every ray's largest axis */
    test_block(&r, n, grid, &blk);
    fr_ray rays[8];
    for (int i = 0; i < nrays; i++) rays[i] = test_ray(&r, grid, &blk, z, z);
    /* one ray in sixteen off the shared axes: the packet must decline */
    const int odd = n % 16 == 15 && nrays > 1;
    if (odd) { rays[1].dir[0] = 100.0f; rays[1].dir[1] = 0.5f; }
    for (int lane = 0; lane < 4; lane++)
      for (int k = 0; k < 3; k++) {
        float(*v)[4] = k == 0 ? blk.v0 : k == 1 ? blk.v1 : blk.v2;
        float c[3] = {v[0][lane], v[1][lane], v[2][lane]};
        rotate3(c, rot);
        for (int a = 0; a < 3; a++) v[a][lane] = c[a];
      }
    for (int i = 0; i < nrays; i++) { rotate3(rays[i].org, rot); rotate3(rays[i].dir, rot); }
    for (size_t l = 0; l < sizeof levels / sizeof levels[0]; l++) {
      if (!fr_isa_supported(levels[l].isa)) continue;
      int h = 0;
      const int res = levels[l].fn(&blk, rays, nrays, &h);
      if (res < 0) {
        if (!odd) fail_msg("level %zu (P=%d), case %d: rays along one axis declined", l, levels[l].p, n);
        declined++;
        continue;
      }
      if (odd) fail_msg("level %zu (P=%d), case %d: rays off the shared axes accepted", l, levels[l].p, n);
      if (!res) fail_msg("level %zu (P=%d), case %d: the quad test differs", l, levels[l].p, n);
      hits += h;
      tested++;
    }
  }
  print_message("quad block tests: %ld across levels and sizes (%ld declined), %ld rays hit\n", tested, declined, hits);
  assert_true(declined > 0 && hits > tested / 4);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_add_where),
      cmocka_unit_test(test_imin_imax),
      cmocka_unit_test(test_load_records),
      cmocka_unit_test(test_tri4_pair),
      cmocka_unit_test(test_stream_setup),
      cmocka_unit_test(test_stream_chunk),
      cmocka_unit_test(test_block_chunk),
      cmocka_unit_test(test_tri4_quad),
      cmocka_unit_test(test_agreement),
      cmocka_unit_test(test_child_sort8),
      cmocka_unit_test(test_axis_aligned_fast_path),
      cmocka_unit_test(test_degenerate_and_nan),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
