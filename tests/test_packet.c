/*
 * Packet and hybrid kernels against the single-ray kernels and brute force,
 * on random scenes: every ISA, packets of 8 and 16, BVH4 and BVH8, pure
 * packets and the hybrid at several thresholds, and each measurement switch
 * (mailbox, axis-aligned path, interval culling) on and off. Packets come in
 * the kinds the renderers make: a common origin with a narrow cone (camera),
 * many origins to one point (shadows), a common origin with directions of
 * every sign (ambient occlusion), and unrelated rays, with holes in the
 * valid mask and invalid rays (NaN, zero direction) among them.
 */
#include <string.h>
#include "geom/tri_shevtsov.h"
#include "geom/tri_watertight.h"
#include "io/rayfile.h"
#include "random_scene.h"
#include "test_util.h"

enum { KIND_CAMERA, KIND_SHADOW, KIND_HEMISPHERE, KIND_RANDOM, KIND_COUNT };

static void make_packet(fr_rng *r, int kind, vec3 center, float size, const scene_data *sd, fr_ray *rays) {
  vec3 o = v3_add(center, v3(urand(r, -2 * size, 2 * size), urand(r, -2 * size, 2 * size), urand(r, -2 * size, 2 * size)));
  vec3 aim = v3_add(center, v3(urand(r, -size, size), urand(r, -size, size), urand(r, -size, size)));
  float spread = size * 0.05f;
  for (int i = 0; i < 16; i++) {
    vec3 ro = o, d;
    float tfar = INFINITY;
    uint32_t src;
    switch (kind) {
    case KIND_CAMERA:
      d = v3_sub(v3_add(aim, v3((float)(i & 3) * spread, (float)(i >> 2) * spread, 0.0f)), o);
      break;
    case KIND_SHADOW: /* from scattered points to one light; tfar stops short of it */
      ro = v3_add(aim, v3(urand(r, -spread, spread) * 4, urand(r, -spread, spread) * 4, urand(r, -spread, spread) * 4));
      d = v3_sub(o, ro);
      tfar = 1.0f - 1e-4f;
      break;
    case KIND_HEMISPHERE:
      ro = aim;
      d = v3(urand(r, -1, 1), urand(r, -1, 1), urand(r, -1, 1));
      break;
    default: {
      fr_ray x = random_ray(r, center, size, sd, (int)(fr_rng_u32(r) % 4), &src);
      rays[i] = x;
      continue;
    }
    }
    rays[i] = (fr_ray){{ro.x, ro.y, ro.z}, 0.0f, {d.x, d.y, d.z}, tfar};
  }
}

static void to_ray16(const fr_ray *rays, fr_ray16 *p) {
  for (int i = 0; i < 16; i++) {
    p->org_x[i] = rays[i].org[0]; p->org_y[i] = rays[i].org[1]; p->org_z[i] = rays[i].org[2];
    p->dir_x[i] = rays[i].dir[0]; p->dir_y[i] = rays[i].dir[1]; p->dir_z[i] = rays[i].dir[2];
    p->tnear[i] = rays[i].tnear; p->tfar[i] = rays[i].tfar;
  }
}

/* The configurations under test; each is compared with the single-ray kernels. */
typedef struct config {
  const char *name;
  fr_trace_mode mode;
  int threshold, width, mailbox, axis_aligned, ia, prefetch;
  float spread; /* auto's stream_spread; 0: the default */
  int coherent; /* coherent_threshold, which hybrid16's one-octant packets use too; 0: the default */
  int no_quad;  /* quad_leaves off */
} config;
static const config configs[] = {
    {"packet16", FR_TRACE_PACKET16, 0, 4, 0, 1, 1, 0, 0.0f, 0, 0},  {"packet8", FR_TRACE_PACKET8, 0, 4, 0, 1, 1, 0, 0.0f, 0, 0},
    {"hybrid16", FR_TRACE_HYBRID16, 7, 4, 0, 1, 1, 0, 0.0f, 0, 0},  {"hybrid16/t3", FR_TRACE_HYBRID16, 3, 4, 0, 1, 1, 0, 0.0f, 3, 0},
    {"hybrid16/t16", FR_TRACE_HYBRID16, 16, 4, 0, 1, 1, 0, 0.0f, 16, 0}, {"packet16/bvh8", FR_TRACE_PACKET16, 0, 8, 0, 1, 1, 0, 0.0f, 0, 0},
    {"hybrid16/bvh8", FR_TRACE_HYBRID16, 7, 8, 0, 1, 1, 0, 0.0f, 0, 0}, {"packet16/mailbox", FR_TRACE_PACKET16, 0, 4, 1, 1, 1, 0, 0.0f, 0, 0},
    {"packet16/no-aa", FR_TRACE_PACKET16, 0, 4, 0, 0, 1, 0, 0.0f, 0, 0}, {"packet16/no-ia", FR_TRACE_PACKET16, 0, 4, 0, 1, 0, 0, 0.0f, 0, 0},
    {"auto", FR_TRACE_AUTO, 7, 4, 0, 1, 1, 0, 0.0f, 0, 0},
    /* auto with every group a packet, and with the packet/stream split
       inside the camera and shadow packets too */
    {"auto/packets", FR_TRACE_AUTO, 7, 4, 0, 1, 1, 0, 2.0f, 0, 0},
    {"auto/split", FR_TRACE_AUTO, 7, 8, 0, 1, 1, 0, 0.1f, 0, 0},
    {"raystream", FR_TRACE_RAYSTREAM, 7, 4, 0, 1, 1, 0, 0.0f, 0, 0},
    /* prefetching, which these small scenes leave off by default */
    {"hybrid16/bvh8/prefetch", FR_TRACE_HYBRID16, 7, 8, 0, 1, 1, 1, 0.0f, 0, 0},
    /* every leaf one triangle against all the packet's rays */
    {"packet16/bvh8/no-quad", FR_TRACE_PACKET16, 0, 8, 0, 1, 1, 0, 0.0f, 0, 1},
    {"packet8/no-quad", FR_TRACE_PACKET8, 0, 4, 0, 1, 1, 0, 0.0f, 0, 1},
};
#define NCONFIGS (sizeof configs / sizeof configs[0])

static void set_config(fr_scene *s, const config *c) {
  fr_tuning o;
  fr_tuning_default(&o);
  o.mode = c->mode;
  o.hybrid_threshold = c->threshold;
  o.packet_bvh_width = c->width;
  o.mailbox = c->mailbox;
  o.axis_aligned = c->axis_aligned;
  o.ia_cull = c->ia;
  o.quad_leaves = !c->no_quad;
  o.prefetch = c->prefetch ? 1 : -1;
  if (c->spread > 0.0f) o.stream_spread = c->spread;
  if (c->coherent > 0) o.coherent_threshold = c->coherent;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
}

/* The single-ray answers of a packet's 16 rays (scalar ISA, default
 * tuning), checked against brute force where a ray is clear of edges
 * (clear[i]); returns how many valid rays hit. */
static long single_answers(fr_scene *s, const scene_data *sd, float size, const fr_ray rays[16], unsigned valid, int p,
                           fr_hit single[16], int occ1[16], int clear[16]) {
  long hits = 0;
  assert_int_equal(fr_set_isa(FR_ISA_SCALAR), FR_OK);
  fr_tuning dflt;
  fr_tuning_default(&dflt);
  fr_scene_set_tuning(s, &dflt);
  for (int i = 0; i < 16; i++) {
    fr_intersect1(s, &rays[i], &single[i]);
    occ1[i] = fr_occluded1(s, &rays[i]);
    uint32_t bp;
    double margin;
    double bt = brute_force(sd->pos, sd->idx, sd->nt, &rays[i], &bp, &margin, 1);
    clear[i] = margin >= 1e-4 && (rays[i].tnear == 0.0f || single[i].prim == FR_INVALID_ID || single[i].t > 1e-3f * size);
    if (clear[i] && !(isinf(bt) ? single[i].prim == FR_INVALID_ID : fabs(single[i].t - bt) <= 1e-4 * fmax(1.0, fabs(bt))))
      fail_msg("single-ray kernel disagrees with brute force (packet %d ray %d)", p, i);
    hits += (valid >> i & 1) && single[i].prim != FR_INVALID_ID;
  }
  return hits;
}

static void check_scene(vec3 center, float size, uint64_t seed) {
  fr_rng r = fr_rng_seed(seed, 3);
  scene_data sd = make_scene(&r, 3000, center, size);
  fr_scene *s = commit_scene(&sd);
  long compared = 0, hits = 0;
  for (int p = 0; p < 160; p++) {
    fr_ray rays[16];
    int kind = p % KIND_COUNT;
    make_packet(&r, kind, center, size, &sd, rays);
    unsigned valid = (p % 3 == 0) ? 0xFFFFu : (fr_rng_u32(&r) & 0xFFFFu);
    if (p % 7 == 0) { rays[3].dir[0] = NAN; rays[5].dir[0] = rays[5].dir[1] = rays[5].dir[2] = 0.0f; }
    fr_hit single[16];
    int occ1[16], clear[16];
    hits += single_answers(s, &sd, size, rays, valid, p, single, occ1, clear);
    fr_ray16 r16;
    to_ray16(rays, &r16);
    /* every ISA runs the same arithmetic: bit-identical packet answers */
    fr_hit16 first[NCONFIGS];
    unsigned first_occ[NCONFIGS];
    int have_first = 0;
    for (int isa = 0; isa < 3; isa++) {
      if (!fr_isa_supported((fr_isa)isa)) continue;
      assert_int_equal(fr_set_isa((fr_isa)isa), FR_OK);
      for (size_t c = 0; c < NCONFIGS; c++) {
        set_config(s, &configs[c]);
        fr_hit16 h16;
        memset(&h16, 0x5A, sizeof h16); /* lanes outside valid must stay as they are */
        fr_hit hs[16];
        uint8_t occs[16];
        fr_ray copy[16];
        memcpy(copy, rays, sizeof copy);
        memset(hs, 0x5A, sizeof hs); /* every ray must be answered */
        memset(occs, 0x5A, sizeof occs);
        fr_intersect_stream(s, copy, hs, 16);
        fr_occluded_stream(s, copy, occs, 16);
        fr_intersect16(s, valid, &r16, &h16);
        unsigned occ16 = fr_occluded16(s, valid, &r16);
        if (!have_first) {
          first[c] = h16;
          first_occ[c] = occ16;
        } else {
          assert_int_equal(occ16, first_occ[c]);
          assert_memory_equal(&h16, &first[c], sizeof h16);
        }
        for (int i = 0; i < 16; i++) {
          const char *cn = configs[c].name;
          if (!((valid >> i) & 1)) {
            assert_int_equal(h16.prim[i], 0x5A5A5A5Au);
            assert_false((occ16 >> i) & 1);
          } else {
            assert_true(h16.t[i] == h16.t[i]); /* never NaN */
            if (clear[i]) {
              if (!fr_hits_agree(h16.t[i], single[i].t))
                fail_msg("%s isa %d packet %d (kind %d) ray %d: t %g vs single %g", cn, isa, p, kind, i, h16.t[i], single[i].t);
              if (h16.prim[i] == single[i].prim && h16.prim[i] != FR_INVALID_ID)
                assert_memory_equal(&h16.t[i], &single[i].t, sizeof(float)); /* t refined the same way */
              if ((int)((occ16 >> i) & 1) != occ1[i] && !fr_occlusion_near_boundary(&rays[i], single[i].t))
                fail_msg("%s isa %d packet %d ray %d: occluded %d vs single %d", cn, isa, p, i, (occ16 >> i) & 1, occ1[i]);
            }
          }
          /* all lanes valid, packet kernel only: the stream ran the very
           * packet the packet call did (its rays loaded and its answers
           * stored as whole records), so even the triangle must match.
           * (In packet8 mode the call is still one packet of 16, which
           * takes quad leaves at other counts of active rays.) */
          const int same_packet = valid == 0xFFFFu && configs[c].threshold == 0 &&
                                  (configs[c].mode == FR_TRACE_PACKET16 ||
                                   (configs[c].mode == FR_TRACE_PACKET8 && configs[c].no_quad));
          if (same_packet && hs[i].prim != h16.prim[i])
            fail_msg("%s stream isa %d packet %d ray %d: prim %u vs the packet's %u", configs[c].name, isa, p, i,
                     hs[i].prim, h16.prim[i]);
          if (((valid >> i) & 1) && hs[i].prim == h16.prim[i]) {
            /* the stream's gathered rays and scattered answers: every field
             * as the packet call's (u, v only where both ran the packet
             * kernel on the same lanes: a hybrid's single-ray phase and
             * the quad leaves, which depend on the packet's other rays,
             * give the watertight test's u, v) */
            const int same_kernel = same_packet || (configs[c].threshold == 0 && configs[c].no_quad &&
                                                    configs[c].mode != FR_TRACE_AUTO && configs[c].mode != FR_TRACE_RAYSTREAM);
            float a[6] = {h16.t[i], h16.ng_x[i], h16.ng_y[i], h16.ng_z[i], h16.u[i], h16.v[i]};
            float b[6] = {hs[i].t, hs[i].ng[0], hs[i].ng[1], hs[i].ng[2], hs[i].u, hs[i].v};
            if (memcmp(a, b, (same_kernel ? 6 : 4) * sizeof(float)))
              fail_msg("%s stream isa %d packet %d ray %d: answer differs from the packet's", configs[c].name, isa, p, i);
          }
          if (clear[i]) {
            if (!fr_hits_agree(hs[i].t, single[i].t))
              fail_msg("%s stream isa %d packet %d ray %d: t %g vs single %g", cn, isa, p, i, hs[i].t, single[i].t);
            if (occs[i] != occ1[i] && !fr_occlusion_near_boundary(&rays[i], single[i].t))
              fail_msg("%s stream isa %d packet %d ray %d: occluded", cn, isa, p, i);
            compared++;
          }
        }
      }
      have_first = 1;
    }
  }
  print_message("compared %ld packet lanes with single rays, %ld single hits\n", compared, hits);
  assert_true(compared > 10000);
  assert_true(hits > 300);
  fr_scene_release(s);
  free_scene(&sd);
}

static void test_packets_origin(void **st) { (void)st; check_scene(v3(0, 0, 0), 1.0f, 21); }
static void test_packets_far(void **st) { (void)st; check_scene(v3(1e4f, -2e4f, 5e3f), 50.0f, 22); }
static void test_packets_tiny(void **st) { (void)st; check_scene(v3(0.1f, 0.2f, 0.3f), 1e-3f, 23); }

/* The packet leaf test lane by lane against the scalar Shevtsov test
 * (geom/tri_shevtsov.h) on one-triangle scenes: the same hits, t as
 * fr_tri_refine_t makes it from its t, and u and v to rounding, at every
 * ISA, with and without the axis-aligned path. */
static void test_leaf_against_scalar(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(31, 1);
  long hits = 0;
  for (int tri = 0; tri < 200; tri++) {
    float v[9];
    for (int k = 0; k < 9; k++) v[k] = urand(&r, -1, 1);
    if (tri % 3 == 0) v[2] = v[5] = v[8] = 0.25f; /* axis-aligned */
    const uint32_t idx[3] = {0, 1, 2};
    fr_scene *s;
    assert_int_equal(fr_scene_from_arrays(v, 3, idx, 1, &s), FR_OK);
    assert_int_equal(fr_scene_commit(s), FR_OK);
    if (fr_scene_triangle_count(s) == 0 || fr_scene_skipped_triangles(s)) { fr_scene_release(s); continue; }
    fr_tri_shevtsov rec;
    if (!fr_tri_shevtsov_make(&rec, v3(v[0], v[1], v[2]), v3(v[3], v[4], v[5]), v3(v[6], v[7], v[8]), 0)) {
      fr_scene_release(s);
      continue;
    }
    fr_ray rays[16];
    vec3 o = v3(urand(&r, -2, 2), urand(&r, -2, 2), urand(&r, 2, 3));
    for (int i = 0; i < 16; i++) {
      vec3 target = v3(urand(&r, -1, 1), urand(&r, -1, 1), urand(&r, -1, 1));
      vec3 d = v3_sub(target, o);
      rays[i] = (fr_ray){{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
    }
    fr_ray16 r16;
    to_ray16(rays, &r16);
    for (int isa = 0; isa < 3; isa++) {
      if (!fr_isa_supported((fr_isa)isa)) continue;
      fr_set_isa((fr_isa)isa);
      for (int aa = 0; aa < 2; aa++) {
        config c = {"leaf", FR_TRACE_PACKET16, 0, 4, 0, aa, 1, 0, 0.0f, 0, 1}; /* every leaf by Shevtsov's test */
        set_config(s, &c);
        fr_tri_shevtsov use = rec;
        if (!aa) use.axis_aligned = 0;
        fr_hit16 h;
        fr_intersect16(s, 0xFFFF, &r16, &h);
        for (int i = 0; i < 16; i++) {
          float t, u, w;
          int hit = fr_tri_shevtsov_test(&use, v3_load(rays[i].org), v3_load(rays[i].dir), 0.0f, INFINITY, &t, &u, &w);
          assert_int_equal(hit, h.prim[i] == 0);
          if (!hit) continue;
          hits++;
          /* t made again from the plane (fr_tri_refine_t), u and v those of its point */
          float et = fr_tri_refine_t(v3_load(rays[i].org), v3_load(rays[i].dir), 0.0f, INFINITY, v3(v[0], v[1], v[2]),
                                     v3(v[3], v[4], v[5]), v3(v[6], v[7], v[8]), t);
          assert_memory_equal(&et, &h.t[i], sizeof et);
          assert_true(fabsf(u - h.u[i]) <= 1e-4f && fabsf(w - h.v[i]) <= 1e-4f);
        }
      }
    }
    fr_scene_release(s);
  }
  assert_true(hits > 500);
}

/* Ray streams (FR_TRACE_RAYSTREAM): one call over a long stream of every
 * kind of ray, octants mixed, some invalid, at both BVH widths and every ISA,
 * must give each ray exactly the single-ray kernel's any-hit answer and its
 * closest hit (the same t, and the same triangle unless another lies at that
 * very t): the stream runs the same box and triangle tests per ray, only in
 * another order. */
static void test_raystream(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(31, 5);
  vec3 center = v3(3.0f, -2.0f, 1.0f);
  float size = 2.0f;
  scene_data sd = make_scene(&r, 3000, center, size);
  fr_scene *s = commit_scene(&sd);
  enum { N = 16 * 150 };
  static fr_ray rays[N];
  static uint8_t occ[N];
  static fr_hit hit[N], expect_hit[2][N];
  int expect[2][N];
  for (int p = 0; p < N / 16; p++) make_packet(&r, p % KIND_COUNT, center, size, &sd, rays + 16 * p);
  rays[17].dir[1] = NAN;
  rays[40].tnear = 5.0f; rays[40].tfar = 1.0f;
  long occluded = 0, hits = 0, ties = 0;
  for (int wi = 0; wi < 2; wi++) {
    int width = wi ? 8 : 4;
    assert_int_equal(fr_scene_set_bvh_width(s, width), FR_OK);
    assert_int_equal(fr_set_isa(FR_ISA_SCALAR), FR_OK);
    for (int i = 0; i < N; i++) {
      expect[wi][i] = fr_occluded1(s, &rays[i]);
      fr_intersect1(s, &rays[i], &expect_hit[wi][i]);
    }
    for (int isa = 0; isa < 3; isa++) {
      if (!fr_isa_supported((fr_isa)isa)) continue;
      assert_int_equal(fr_set_isa((fr_isa)isa), FR_OK);
      fr_tuning o;
      fr_tuning_default(&o);
      o.mode = FR_TRACE_RAYSTREAM;
      assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
      memset(occ, 0x5A, sizeof occ);
      fr_occluded_stream(s, rays, occ, N);
      for (int i = 0; i < N; i++)
        if (occ[i] != expect[wi][i])
          fail_msg("raystream width %d isa %d ray %d: occluded %d vs single %d", width, isa, i, occ[i], expect[wi][i]);
      memset(hit, 0x5A, sizeof hit);
      fr_intersect_stream(s, rays, hit, N);
      for (int i = 0; i < N; i++) {
        const fr_hit *e = &expect_hit[wi][i], *h = &hit[i];
        if (memcmp(&h->t, &e->t, sizeof(float)) || (h->prim == FR_INVALID_ID) != (e->prim == FR_INVALID_ID))
          fail_msg("raystream width %d isa %d ray %d: t %g prim %u vs single %g prim %u", width, isa, i, h->t, h->prim,
                   e->t, e->prim);
        if (h->prim == e->prim && memcmp(h, e, sizeof *h))
          fail_msg("raystream width %d isa %d ray %d: same triangle, another answer", width, isa, i);
        ties += h->prim != e->prim;
      }
    }
  }
  for (int i = 0; i < N; i++) occluded += expect[1][i], hits += expect_hit[1][i].prim != FR_INVALID_ID;
  print_message("%d rays, %ld occluded, %ld hit (%ld ties), raystream = single at both widths\n", N, occluded, hits,
                ties);
  assert_true(occluded > N / 10 && occluded < N - N / 10);
  assert_true(hits > N / 10 && hits < N - N / 10);
  assert_int_equal(expect[1][17], 0);
  assert_int_equal(expect[1][40], 0);
  fr_scene_release(s);
  free_scene(&sd);
}

/* FR_TRACE_AUTO's occlusion streams drop packets for ray streams where the
 * packets reach most leaves with half of their rays or fewer: long streams
 * of shadow packets over a fog of small triangles, which part there. The
 * answers stay the single rays' (but at a triangle's boundary, where the
 * packet test is not watertight), on every ISA, whichever way each group
 * went. */
static void test_auto_sparse_shadows(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(41, 5);
  vec3 center = v3(-1.0f, 2.0f, 0.5f);
  float size = 1.0f;
  scene_data sd = make_scene(&r, 20000, center, size);
  fr_scene *s = commit_scene(&sd);
  enum { N = 16 * 256 };
  static fr_ray rays[N];
  static uint8_t occ[N];
  static int expect[N];
  for (int p = 0; p < N / 16; p++) make_packet(&r, KIND_SHADOW, center, size, &sd, rays + 16 * p);
  assert_int_equal(fr_set_isa(FR_ISA_SCALAR), FR_OK);
  long occluded = 0;
  for (int i = 0; i < N; i++) occluded += expect[i] = fr_occluded1(s, &rays[i]);
  assert_int_equal(fr_scene_set_trace_mode(s, FR_TRACE_AUTO), FR_OK);
  long boundary = 0;
  for (int isa = 0; isa < 3; isa++) {
    if (!fr_isa_supported((fr_isa)isa)) continue;
    assert_int_equal(fr_set_isa((fr_isa)isa), FR_OK);
    memset(occ, 0x5A, sizeof occ);
    fr_occluded_stream(s, rays, occ, N);
    for (int i = 0; i < N; i++) {
      if (occ[i] == expect[i]) continue;
      fr_hit h;
      fr_intersect1(s, &rays[i], &h);
      if (!fr_occlusion_near_boundary(&rays[i], h.t))
        fail_msg("auto isa %d ray %d: occluded %d vs single %d", isa, i, occ[i], expect[i]);
      boundary++;
    }
  }
  print_message("%d shadow rays in packets of 16, %ld occluded, %ld at a boundary\n", N, occluded, boundary);
  assert_true(occluded > N / 10 && occluded < N - N / 10);
  fr_scene_release(s);
  free_scene(&sd);
}

/* The option checks of the API. */
static void test_options(void **st) {
  (void)st;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  fr_tuning o;
  fr_tuning_default(&o);
  assert_int_equal(o.hybrid_threshold, 7);
  o.hybrid_threshold = 17;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_ERR_ARG);
  o.hybrid_threshold = 7;
  o.packet_bvh_width = 6;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_ERR_ARG);
  o.packet_bvh_width = 8;
  assert_int_equal(o.prefetch, -1);
  o.prefetch = 2;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_ERR_ARG);
  o.prefetch = -1;
  assert_true(o.stream_spread == FR_STREAM_SPREAD_DEFAULT);
  o.stream_spread = NAN;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_ERR_ARG);
  o.stream_spread = 2.5f;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_ERR_ARG);
  o.stream_spread = 0.0f;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
  assert_int_equal(o.coherent_threshold, 2);
  o.coherent_threshold = -1;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_ERR_ARG);
  o.coherent_threshold = 17;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_ERR_ARG);
  o.coherent_threshold = 2;
  /* an uncommitted scene: misses, nothing occluded */
  fr_ray16 r16;
  memset(&r16, 0, sizeof r16);
  fr_hit16 h;
  fr_intersect16(s, 0xFFFF, &r16, &h);
  assert_int_equal(h.prim[0], FR_INVALID_ID);
  assert_int_equal(fr_occluded16(s, 0xFFFF, &r16), 0);
  fr_scene_release(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_packets_origin),
      cmocka_unit_test(test_packets_far),
      cmocka_unit_test(test_packets_tiny),
      cmocka_unit_test(test_leaf_against_scalar),
      cmocka_unit_test(test_raystream),
      cmocka_unit_test(test_auto_sparse_shadows),
      cmocka_unit_test(test_options),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
