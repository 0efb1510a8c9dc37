/*
 * Multi-frusta kernels against the single-ray kernels, ray by ray, on random
 * scenes and on the built-in scene: soft-shadow frusta (16 hit points, 16
 * interleaved light samples each) with any-hit, camera frusta (16 blocks of
 * 4x4 pixels) with closest hit, and those turned back into rays of unit
 * direction. Every ISA; corner-ray culling off, for every triangle, and only
 * where it pays (the default); shrinking off, of the corner rays alone and
 * of corner rays and intervals (the default): all must agree bit for bit.
 *
 * The MFT test and the single-ray test are both watertight but round
 * differently, so a ray that passes within rounding of an edge may get either
 * answer; every disagreement must be such a ray (brute force in double
 * precision), or lie within 1e-4 of tnear/tfar (rayfile.md's rule).
 */
#include <string.h>
#include "api/scene.h"
#include "render/views.h"
#include "random_scene.h"
#include "render/mft_rays.h"
#include "render/softshadow.h"
#include "test_util.h"
#include "trace/kernels.h"
#include "trace/mft/mft.h"

static const fr_mft_fns *isa_fns[] = {&fr_mft_scalar, &fr_mft_avx2, &fr_mft_avx512};
static const fr_isa isas[] = {FR_ISA_SCALAR, FR_ISA_AVX2, FR_ISA_AVX512};

/* Soft-shadow frusta from random points of the scene to a quad light. */

static void make_shadow_batch(fr_rng *r, const mesh_ref *m, vec3 lc, float eps, fr_mft_batch *b) {
  memset(b, 0, sizeof *b);
  for (int f = 0; f < 16; f++) {
    vec3 p = random_surface_point(r, m);
    vec3 s = v3_sub(lc, p);
    b->org[0][f] = p.x; b->org[1][f] = p.y; b->org[2][f] = p.z;
    b->start[0][f] = s.x; b->start[1][f] = s.y; b->start[2][f] = s.z;
    b->tnear[f] = eps / v3_len(s);
    b->tfar[f] = 1.0f - 1e-4f;
    b->set[f] = (uint8_t)f;
    if (fr_rng_u32(r) % 8) b->valid |= 1u << f;
  }
}

typedef struct tally { long rays, disagree, excused, cache_filled, plane_rays, planes_only, shafts, planes_left_out; } tally;

/* A shaft (fr_mft_shaft) around every ray of batch b: from the box of its
 * origins to the box of its rays' ends, origin + start + the box of the
 * set's deltas. */
static int batch_shaft(const fr_bvh2 *tree, const fr_mft_batch *b, const fr_mft_sets *T, fr_mft_shaft *sh,
                       uint32_t *planes_off) {
  float plo[3] = {INFINITY, INFINITY, INFINITY}, phi[3] = {-INFINITY, -INFINITY, -INFINITY};
  float qlo[3] = {INFINITY, INFINITY, INFINITY}, qhi[3] = {-INFINITY, -INFINITY, -INFINITY};
  if (!(b->valid & 0xFFFFu)) return 0;
  for (int f = 0; f < 16; f++) {
    if (!((b->valid >> f) & 1)) continue;
    const fr_mft_set *S = &T->set[b->set[f]];
    for (int a = 0; a < 3; a++) {
      const float o = b->org[a][f], e = o + b->start[a][f];
      plo[a] = fminf(plo[a], o); phi[a] = fmaxf(phi[a], o);
      qlo[a] = fminf(qlo[a], e + S->lo[a]); qhi[a] = fmaxf(qhi[a], e + S->hi[a]);
    }
  }
  *planes_off = fr_mft_shaft_planes_off(tree, plo, phi, qlo, qhi);
  return fr_mft_shaft_build(tree, plo, phi, qlo, qhi, sh);
}

/* The same rays as 16 packets of 16 (one per frustum), traced as pure packets. */
static void packet16_occluded(fr_scene *s, const fr_mft_batch *b, const fr_mft_sets *T, uint16_t occ[16]) {
  fr_tuning o, saved;
  fr_scene_get_tuning(s, &saved);
  o = saved;
  o.mode = FR_TRACE_PACKET16;
  fr_scene_set_tuning(s, &o);
  for (int f = 0; f < 16; f++) {
    occ[f] = 0;
    if (!((b->valid >> f) & 1)) continue;
    fr_ray16 p;
    for (int k = 0; k < 16; k++) {
      float org[3], dir[3];
      fr_mft_ray(b, T, f, k, org, dir);
      p.org_x[k] = org[0]; p.org_y[k] = org[1]; p.org_z[k] = org[2];
      p.dir_x[k] = dir[0]; p.dir_y[k] = dir[1]; p.dir_z[k] = dir[2];
      p.tnear[k] = b->tnear[f]; p.tfar[k] = b->tfar[f];
    }
    occ[f] = (uint16_t)fr_occluded16(s, 0xFFFFu, &p);
  }
  fr_scene_set_tuning(s, &saved);
}

static void check_shadows_vs(const fr_scene *s, const fr_mft_batch *b, const fr_mft_sets *T, tally *tl,
                             const uint16_t *packet_occ) {
  mesh_ref m = scene_mesh(s);
  uint16_t ref[16];
  int first = 1;
  /* corner: 0 off, 1 for every triangle, 2 where it pays by the default cost */
  for (int corner = 0; corner < 3; corner++)
    for (int shrink = FR_MFT_SHRINK_OFF; shrink <= FR_MFT_SHRINK_ALL; shrink++)
      for (int i = 0; i < 3; i++) {
        if (!fr_isa_supported(isas[i])) continue;
        fr_mft_opts o = {corner != 0, shrink, corner == 2 ? fr_mft_opts_default().corner_cost : 0.0f};
        uint16_t occ[16];
        memset(occ, 0xAB, sizeof occ); /* poison: every frustum must be written */
        fr_mft_budget none = {0, 0, ~0u, -1, 0};
        isa_fns[i]->occluded(&s->bvh2_mft, &o, b, T, occ, &none, NULL);
        assert_true(none.visited != ~0u && none.stopped == 0);
        /* the shadow tree with the scene's planar occluders tested first
         * (accel/plane_occluders.h) gives the same bits as without them */
        if (s->bvh2.planes) {
          uint16_t occ_p[16], occ_b[16];
          fr_bvh2 bare = s->bvh2;
          bare.planes = NULL;
          isa_fns[i]->occluded(&s->bvh2, &o, b, T, occ_p, NULL, NULL);
          isa_fns[i]->occluded(&bare, &o, b, T, occ_b, NULL, NULL);
          assert_memory_equal(occ_p, occ_b, sizeof occ_p);
          /* the occluders alone (the fall-back's batches): a stopped batch
           * whose bits are answers, some of the whole batch's */
          uint16_t occ_o[16];
          fr_mft_budget only = {0, 0, 0, 0, 1};
          isa_fns[i]->occluded(&s->bvh2, &o, b, T, occ_o, &only, NULL);
          assert_true(only.stopped);
          for (int f = 0; f < 16; f++) {
            assert_int_equal(occ_o[f] & ~occ_p[f], 0);
            tl->planes_only += __builtin_popcount(occ_o[f]);
          }
        }
        /* occluders cached from the previous batch, and from this batch
         * itself (its best leaves then occlude rays before any traversal),
         * change no answer */
        for (int own = 0; own < 2; own++) {
          static fr_mft_occluders carried;
          fr_mft_occluders c = carried;
          uint16_t occ_c[16];
          if (own) {
            memset(&c, 0, sizeof c);
            isa_fns[i]->occluded(&s->bvh2_mft, &o, b, T, occ_c, NULL, &c);
            tl->cache_filled += c.n > 0;
          }
          isa_fns[i]->occluded(&s->bvh2_mft, &o, b, T, occ_c, NULL, &c);
          assert_memory_equal(occ_c, occ, sizeof occ);
          if (!own) carried = c;
        }
        /* the leaves of a shaft around the batch in place of the walk
         * (fr_mft_shaft), alone and after cached occluders: the same bits
         * (with the default switches at every ISA) */
        fr_mft_shaft sh;
        uint32_t off = 0;
        const fr_bvh2 *st = &s->bvh2; /* soft shadows' tree, with the planar occluders */
        if (corner == 2 && shrink == FR_MFT_SHRINK_ALL && batch_shaft(st, b, T, &sh, &off)) {
          uint16_t occ_w[16];
          isa_fns[i]->occluded(st, &o, b, T, occ_w, NULL, NULL);
          for (int cached = 0; cached < 2; cached++) {
            fr_mft_occluders c = {{0}, 0, &sh, off};
            uint16_t occ_s[16];
            if (cached) {
              c.shaft = NULL;
              isa_fns[i]->occluded(st, &o, b, T, occ_s, NULL, &c);
              c.shaft = &sh;
            }
            isa_fns[i]->occluded(st, &o, b, T, occ_s, NULL, &c);
            assert_memory_equal(occ_s, occ_w, sizeof occ_w);
          }
          /* the planar occluders alone (a fall-back's batches), with and
           * without those the shaft leaves out: the same bits */
          if (st->planes) {
            fr_mft_occluders c = {{0}, 0, NULL, off};
            fr_mft_budget only = {0, 0, 0, 0, 1};
            uint16_t occ_o[16], occ_a[16];
            isa_fns[i]->occluded(st, &o, b, T, occ_o, &only, &c);
            isa_fns[i]->occluded(st, &o, b, T, occ_a, &only, NULL);
            assert_memory_equal(occ_o, occ_a, sizeof occ_a);
          }
          /* the planar occluders the shaft leaves out claim none of its rays */
          const fr_plane_occluders *po = st->planes;
          for (size_t q = 0; i == 0 && po && q < po->n && q < 32; q++) {
            if (!((off >> q) & 1u)) continue;
            for (int f = 0; f < 16; f++)
              for (int k = 0; ((b->valid >> f) & 1) && k < 16; k++) {
                fr_ray r;
                fr_mft_ray(b, T, f, k, r.org, r.dir);
                assert_false(fr_plane_occluder_hit(&po->list[q], r.org, r.dir, b->tnear[f], b->tfar[f]));
              }
            tl->planes_left_out++;
          }
          tl->shafts++;
        }
        if (first) {
          memcpy(ref, occ, sizeof ref);
          first = 0;
          for (int f = 0; f < 16; f++) {
            if (!((b->valid >> f) & 1)) { assert_int_equal(occ[f], 0); continue; }
            for (int k = 0; k < 16; k++) {
              fr_ray r;
              fr_mft_ray(b, T, f, k, r.org, r.dir);
              r.tnear = b->tnear[f];
              r.tfar = b->tfar[f];
              int single = fr_occluded1(s, &r), mft = (occ[f] >> k) & 1;
              tl->rays++;
              /* a ray a planar occluder claims is occluded by the tree
               * alone (the single-ray kernel without them), without excuse */
              for (size_t q = 0; q < s->planes.n; q++)
                if (fr_plane_occluder_hit(&s->planes.list[q], r.org, r.dir, r.tnear, r.tfar)) {
                  fr_bvhn bare = s->bvh8;
                  bare.planes = NULL;
                  tl->plane_rays++;
                  assert_int_equal(fr_trace_w8_scalar.occluded1(&bare, &r), 1);
                  break;
                }
              if (packet_occ && ((packet_occ[f] >> k) & 1) != mft && single == mft) {
                tl->disagree++;
                if (!ambiguous(&m, &r)) {
                  print_error("frustum %d ray %d: mft %d packet16 %d\n", f, k, mft, !mft);
                  fail();
                }
                tl->excused++;
              }
              if (single != mft) {
                tl->disagree++;
                if (!ambiguous(&m, &r)) {
                  uint32_t bp;
                  double margin, bt = brute_force(m.pos, m.idx, m.nt, &r, &bp, &margin, 1);
                  print_error("frustum %d ray %d: mft %d single %d (double: t=%g prim %u margin %g; tnear %g)\n", f, k,
                              mft, single, bt, bp, margin, r.tnear);
                  fail();
                }
                tl->excused++;
              }
            }
          }
        } else {
          /* every ISA and switch gives the same bits */
          assert_memory_equal(occ, ref, sizeof ref);
        }
      }
}

static void check_shadows(const fr_scene *s, const fr_mft_batch *b, const fr_mft_sets *T, tally *tl) {
  check_shadows_vs(s, b, T, tl, NULL);
}

/* A kernel's expand against the scalar formulas, bit for bit: ray k of
 * frustum f as fr_mft_ray makes it with its direction divided by its
 * length, and its t times that length. */
static void check_expand(const fr_mft_fns *fns, const fr_mft_batch *b, const fr_mft_sets *T, const fr_mft_hits *h) {
  static fr_ray rays[256];
  static fr_hit hits[256];
  memset(rays, 0xAB, sizeof rays);
  memset(hits, 0xAB, sizeof hits);
  fns->expand(b, T, h, rays, hits);
  for (int f = 0; f < 16; f++)
    for (int k = 0; k < 16; k++) {
      fr_ray r = {{0}, 0.0f, {0}, INFINITY};
      fr_mft_ray(b, T, f, k, r.org, r.dir);
      float len = sqrtf(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2]);
      for (int a = 0; a < 3; a++) r.dir[a] /= len;
      uint32_t prim = h->prim[f][k];
      fr_hit e = {prim == FR_INVALID_ID ? INFINITY : h->t[f][k] * len, h->u[f][k], h->v[f][k], prim, {0, 0, 0}};
      assert_memory_equal(&rays[16 * f + k], &r, sizeof r);
      assert_memory_equal(&hits[16 * f + k], &e, sizeof e);
    }
}

/* b with its last valid frustum moved far away and made too short to reach
 * any box; returns that frustum. */
static int move_last_frustum(const fr_mft_batch *b, fr_mft_batch *moved) {
  *moved = *b;
  const int f = 31 - __builtin_clz(b->valid | 1u);
  for (int a = 0; a < 3; a++) moved->org[a][f] = b->org[a][f] + 1e3f * (1.0f + fabsf(b->org[a][f]));
  moved->tnear[f] = 0.0f;
  moved->tfar[f] = 1e-6f;
  return f;
}

/* Camera frusta share one origin, and the kernel then makes a leaf's cross
 * products once for all of them (leaf_edges_shared); moving one frustum's
 * origin away sends the batch down the per-frustum path instead. The moved
 * frustum reaches no box, so the traversal is the same, and every other
 * frustum must get the same answers bit for bit. */
static void check_shared_origin(const fr_scene *s, const fr_mft_fns *fns, const fr_mft_opts *o, const fr_mft_batch *b,
                                const fr_mft_sets *T, const fr_mft_hits *h) {
  static fr_mft_hits g;
  fr_mft_batch moved;
  const int f = move_last_frustum(b, &moved);
  memset(&g, 0xAB, sizeof g);
  fns->intersect(&s->bvh2_mft, o, &moved, T, &g);
  for (int e = 0; e < 16; e++) {
    if (e == f) continue;
    assert_memory_equal(g.t[e], h->t[e], sizeof g.t[e]);
    assert_memory_equal(g.u[e], h->u[e], sizeof g.u[e]);
    assert_memory_equal(g.v[e], h->v[e], sizeof g.v[e]);
    assert_memory_equal(g.prim[e], h->prim[e], sizeof g.prim[e]);
  }
  for (int k = 0; k < 16; k++) assert_int_equal(g.prim[f][k], FR_INVALID_ID);
}

static void check_camera(const fr_scene *s, const fr_camera *cam, int x0, int y0, tally *tl) {
  mesh_ref m = scene_mesh(s);
  fr_mft_sets T;
  fr_mft_batch b;
  fr_mft_sets_camera(&T, cam);
  fr_mft_batch_camera(&b, cam, x0, y0);
  static fr_mft_hits ref, h;
  int first = 1;
  for (int corner = 0; corner < 3; corner++)
    for (int i = 0; i < 3; i++) {
      if (!fr_isa_supported(isas[i])) continue;
      fr_mft_opts o = {corner != 0, 0, corner == 2 ? fr_mft_opts_default().corner_cost : 0.0f};
      memset(&h, 0xAB, sizeof h);
      isa_fns[i]->intersect(&s->bvh2_mft, &o, &b, &T, &h);
      check_expand(isa_fns[i], &b, &T, &h);
      check_shared_origin(s, isa_fns[i], &o, &b, &T, &h);
      if (!first) {
        assert_memory_equal(&h, &ref, sizeof h);
        continue;
      }
      ref = h;
      first = 0;
      for (int f = 0; f < 16; f++)
        for (int k = 0; k < 16; k++) {
          if (!((b.valid >> f) & 1)) { assert_int_equal(h.prim[f][k], FR_INVALID_ID); continue; }
          fr_ray r;
          fr_hit sh;
          fr_mft_ray(&b, &T, f, k, r.org, r.dir);
          r.tnear = 0.0f;
          r.tfar = INFINITY;
          fr_intersect1(s, &r, &sh);
          tl->rays++;
          float t1 = h.t[f][k], t2 = sh.t;
          int agree = (t1 == INFINITY && t2 == INFINITY) ||
                      (t1 < INFINITY && t2 < INFINITY && fabsf(t1 - t2) <= 1e-4f * fmaxf(1.0f, fabsf(t1)));
          if (agree && t1 < INFINITY) {
            /* the barycentrics describe the reported triangle's hit point */
            assert_true(h.u[f][k] >= -1e-3f && h.v[f][k] >= -1e-3f && h.u[f][k] + h.v[f][k] <= 1.001f);
          }
          if (!agree) {
            tl->disagree++;
            if (!ambiguous(&m, &r)) {
              print_error("block (%d,%d) frustum %d ray %d: mft t=%g prim %u, single t=%g prim %u\n", x0, y0, f, k,
                          t1, h.prim[f][k], t2, sh.prim);
              fail();
            }
            tl->excused++;
          }
        }
    }
}

static void random_scenes(void **state) {
  (void)state;
  fr_rng r = fr_rng_seed(11, 3);
  tally tl = {0};
  for (int round = 0; round < FR_TEST_ROUNDS(6); round++) {
    vec3 center = round % 3 == 2 ? v3(1e4f, -3e3f, 2e3f) : v3(0, 0, 0);
    float size = round % 2 ? 1.0f : 30.0f;
    scene_data sd = make_scene(&r, 600 + 300 * (size_t)round, center, size);
    fr_scene *s = commit_scene(&sd);
    mesh_ref m = scene_mesh(s);
    float e1[3] = {size * 0.5f, 0, 0}, e2[3] = {0, 0, size * 0.4f};
    vec3 lc = v3_add(center, v3(urand(&r, -size, size), 2.5f * size, urand(&r, -size, size)));
    fr_mft_sets T;
    fr_mft_sets_light(&T, e1, e2, (uint64_t)round, round & 1 ? FR_LIGHT_SETS_CELLS : FR_LIGHT_SETS_SPREAD);
    for (int n = 0; n < 40; n++) {
      fr_mft_batch b;
      make_shadow_batch(&r, &m, lc, 1e-4f * size, &b);
      check_shadows(s, &b, &T, &tl);
    }
    fr_camera cam;
    vec3 eye = v3_add(center, v3(urand(&r, -3, 3) * size, urand(&r, -3, 3) * size, 3.0f * size));
    assert_int_equal(fr_camera_setup(&cam, eye, center, v3(0, 1, 0), 50.0f, 64, 48), FR_OK);
    for (int y = 0; y < 48; y += 16)
      for (int x = 0; x < 64; x += 16) check_camera(s, &cam, x, y, &tl);
    fr_scene_release(s);
    free_scene(&sd);
  }
  print_message("random scenes: %ld rays, %ld disagreements (all at edges or range ends), %ld batches with cached occluders\n",
                tl.rays, tl.disagree, tl.cache_filled);
  assert_true(tl.disagree * 1000 < tl.rays);
  assert_true(tl.cache_filled > 0);
}

/* Frusta around given rays (fr_mft_fns.from_rays), as Whitted's shadow rays
 * from a point light make them: groups of 16 rays from one origin to
 * points on the scene, each unit direction with [eps, dist - eps]. Every
 * ISA makes the same batch; the rays it makes are the given ones scaled to
 * end at t = 1; groups that break a rule make no frustum; and the frusta
 * traced (corner-ray culls for every triangle, every shrinking) agree with
 * the single-ray kernel ray by ray, which checks that the corner rays bound
 * the rays. A node budget stops a batch short with a subset of the answers. */
static void rays_batch(fr_rng *r, const mesh_ref *m, vec3 light, float eps, fr_ray rays[256], int bad_group) {
  for (int i = 0; i < 256; i++) {
    vec3 d = v3_sub(random_surface_point(r, m), light);
    float dist = v3_len(d);
    d = v3_scale(d, 1.0f / dist);
    rays[i] = (fr_ray){{light.x, light.y, light.z}, dist * 1e-4f, {d.x, d.y, d.z}, dist - eps};
  }
  fr_ray *g = rays + 16 * bad_group;
  switch (bad_group % 4) {
  case 0: g[5].org[1] += 1.0f; break;                   /* two origins */
  case 1: g[3].dir[0] = NAN; break;                     /* NaN */
  case 2: g[9].tfar = INFINITY; break;                  /* unbounded */
  default: /* a ray against the others */
    for (int a = 0; a < 3; a++) g[7].dir[a] = -g[6].dir[a];
  }
}

/* The same for shadow frusta from one point (a point light's, as
 * Whitted's): the shared-origin leaves give the same occlusion bits as the
 * per-frustum path, at every ISA level, cull and shrink setting. */
static void check_shared_origin_occluded(const fr_scene *s, const fr_mft_batch *b, const fr_mft_sets *T) {
  fr_mft_batch moved;
  const int f = move_last_frustum(b, &moved);
  for (int i = 0; i < 3; i++) {
    if (!fr_isa_supported(isas[i])) continue;
    for (int opts = 0; opts < 3; opts++) {
      fr_mft_opts o = fr_mft_opts_default();
      if (opts == 1) o.corner_cost = 0.0f;           /* the cull on every triangle */
      if (opts == 2) o.shrink = FR_MFT_SHRINK_CORNERS; /* corner rays alone */
      uint16_t a[16], g[16];
      isa_fns[i]->occluded(&s->bvh2, &o, b, T, a, NULL, NULL);
      isa_fns[i]->occluded(&s->bvh2, &o, &moved, T, g, NULL, NULL);
      for (int e = 0; e < 16; e++) assert_int_equal(g[e], e == f ? 0 : a[e]);
    }
  }
}

static void rays_frusta(void **state) {
  (void)state;
  fr_rng r = fr_rng_seed(29, 5);
  tally tl = {0};
  long made = 0, stopped = 0;
  for (int round = 0; round < FR_TEST_ROUNDS(4); round++) {
    vec3 center = round == 3 ? v3(1e4f, -3e3f, 2e3f) : v3(0, 0, 0);
    float size = round % 2 ? 1.0f : 30.0f;
    scene_data sd = make_scene(&r, 800 + 400 * (size_t)round, center, size);
    fr_scene *s = commit_scene(&sd);
    mesh_ref m = scene_mesh(s);
    for (int n = 0; n < 24; n++) {
      /* a light above the scene, so that the rays fan out within 75 degrees */
      vec3 light = v3_add(center, v3(urand(&r, -0.3f, 0.3f) * size, 4.0f * size, urand(&r, -0.3f, 0.3f) * size));
      static fr_ray rays[256];
      const int bad = n % 16;
      rays_batch(&r, &m, light, 1e-4f * size, rays, bad);
      const size_t count = n % 3 ? 256 : 256 - 5; /* a partial last frustum (11 rays) */
      fr_mft_batch b, bi;
      static fr_mft_sets T, Ti;
      unsigned valid = 0;
      for (int i = 0; i < 3; i++) {
        if (!fr_isa_supported(isas[i])) continue;
        memset(&bi, 0x5A, sizeof bi);
        memset(&Ti, 0x5A, sizeof Ti);
        unsigned v = isa_fns[i]->from_rays(&bi, &Ti, rays, count);
        assert_int_equal(v, bi.valid);
        if (i == 0) {
          valid = v;
          b = bi;
          T = Ti;
        } else { /* every ISA makes the same frusta */
          assert_int_equal(v, valid);
          assert_memory_equal(&bi, &b, sizeof b);
          assert_memory_equal(&Ti, &T, sizeof T);
        }
      }
      /* the broken group, and no other, makes no frustum */
      assert_int_equal(valid, 0xFFFFu & ~(1u << bad));
      made += __builtin_popcount(valid);
      for (unsigned l = valid; l; l &= l - 1) {
        int f = __builtin_ctz(l);
        assert_true(b.tfar[f] == 1.0f);
        for (int k = 0; k < 16; k++) {
          const fr_ray *g = &rays[16 * f + (16 * (size_t)f + (size_t)k < count ? k : (int)(count - 1 - 16 * (size_t)f))];
          float org[3], dir[3];
          fr_mft_ray(&b, &T, f, k, org, dir);
          assert_memory_equal(org, g->org, sizeof org);
          for (int a = 0; a < 3; a++) assert_true(fabsf(dir[a] - g->dir[a] * g->tfar) <= 1e-5f * g->tfar);
          assert_true(b.tnear[f] <= g->tnear / g->tfar);
        }
      }
      check_shadows(s, &b, &T, &tl);
      check_shared_origin_occluded(s, &b, &T);
      /* a budget of 3 nodes stops the batch: what it says occluded is */
      uint16_t full[16], part[16];
      fr_mft_budget all = {0, 0, 0, 0, 0};
      const fr_mft_opts o = fr_mft_opts_default();
      const unsigned fetched = fr_mft_active()->occluded(&s->bvh2, &o, &b, &T, full, &all, NULL);
      assert_false(all.stopped);
      if (all.visited > 3) {
        fr_mft_budget budget = {3, 0, 0, 0, 0};
        fr_mft_active()->occluded(&s->bvh2, &o, &b, &T, part, &budget, NULL);
        assert_true(budget.stopped);
        assert_int_equal(budget.visited, 3);
        for (int f = 0; f < 16; f++) assert_int_equal(part[f] & ~full[f], 0);
        stopped++;
      }
      /* nodes and triangles together: the batch stops only once it has
       * spent both, and a budget the whole batch stays within changes
       * nothing */
      if (all.visited > 3 && fetched > 0) {
        fr_mft_budget both = {3, fetched, 0, 0, 0};
        fr_mft_active()->occluded(&s->bvh2, &o, &b, &T, part, &both, NULL);
        assert_true(both.visited >= 3);
        for (int f = 0; f < 16; f++) assert_int_equal(part[f] & ~full[f], 0);
        fr_mft_budget roomy = {all.visited + 1, fetched + 1, 0, 0, 0};
        fr_mft_active()->occluded(&s->bvh2, &o, &b, &T, part, &roomy, NULL);
        assert_false(roomy.stopped);
        assert_int_equal(roomy.visited, all.visited);
        assert_memory_equal(part, full, sizeof part);
      }
    }
    fr_scene_release(s);
    free_scene(&sd);
  }
  print_message("rays as frusta: %ld frusta, %ld rays, %ld disagreements (all at edges or range ends), %ld stopped by a budget\n",
                made, tl.rays, tl.disagree, stopped);
  assert_true(made > 0 && stopped > 0);
  assert_true(tl.disagree * 1000 < tl.rays);
}

/* Shadow frusta for the 4x4 pixels at (bx, by): from each primary hit to the
 * quad light at corner lc, as the workload engine makes them. */
static void camera_shadow_batch(const fr_scene *s, const fr_camera *cam, int bx, int by, vec3 lc, vec3 centre,
                                float eps, fr_mft_batch *b) {
  memset(b, 0, sizeof *b);
  for (int f = 0; f < 16; f++) {
    int x = bx + (f & 3), y = by + (f >> 2);
    fr_ray r = fr_camera_ray(cam, x, y);
    fr_hit h;
    fr_intersect1(s, &r, &h);
    if (h.prim == FR_INVALID_ID) continue;
    vec3 p = v3_add(v3_load(r.org), v3_scale(v3_load(r.dir), h.t)), st = v3_sub(lc, p);
    b->org[0][f] = p.x; b->org[1][f] = p.y; b->org[2][f] = p.z;
    b->start[0][f] = st.x; b->start[1][f] = st.y; b->start[2][f] = st.z;
    b->tnear[f] = eps / v3_len(v3_sub(centre, p));
    b->tfar[f] = 1.0f - 1e-4f;
    b->set[f] = (uint8_t)fr_mft_light_set(x, y);
    b->valid |= 1u << f;
  }
}

/* The built-in scene: closed boxes and spheres on a floor, axis-aligned faces,
 * the shadows of its quad light seen from its view. */
static void builtin_scene(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  vec3 c = v3_scale(v3_add(v3_load(lo), v3_load(hi)), 0.5f), ext = v3_sub(v3_load(hi), v3_load(lo));
  fr_camera cam;
  assert_int_equal(fr_camera_setup(&cam, v3_add(c, v3(0.3f * ext.x, 0.4f * ext.y, 0.9f * ext.z)), c, v3(0, 1, 0), 45.0f,
                                   96, 96), FR_OK);
  tally tl = {0};
  for (int y = 0; y < 96; y += 32)
    for (int x = 0; x < 96; x += 32) check_camera(s, &cam, x, y, &tl);
  /* shadow frusta from the primary hits of pixel blocks */
  fr_mft_sets T;
  float e1[3] = {0.2f * ext.x, 0, 0}, e2[3] = {0, 0, 0.2f * ext.z};
  fr_mft_sets_light(&T, e1, e2, 5, FR_LIGHT_SETS_SPREAD);
  vec3 lc = v3_add(c, v3(-0.1f * ext.x, 0.8f * ext.y, -0.1f * ext.z));
  vec3 centre = v3_add(lc, v3(0.1f * ext.x, 0, 0.1f * ext.z));
  for (int by = 0; by < 96; by += 4)
    for (int bx = 0; bx < 96; bx += 24) {
      fr_mft_batch b;
      camera_shadow_batch(s, &cam, bx, by, lc, centre, 1e-4f * v3_len(ext), &b);
      check_shadows(s, &b, &T, &tl);
    }
  print_message("built-in scene: %ld rays, %ld disagreements (all at edges or range ends), %ld batches with cached occluders, "
                "%ld through shafts\n", tl.rays, tl.disagree, tl.cache_filled, tl.shafts);
  assert_true(tl.shafts > 0);
  assert_true(tl.disagree * 1000 < tl.rays);
  assert_true(tl.cache_filled > 0);
  fr_scene_release(s);
}

/* A fine closed sphere far from the camera (dragon-like: triangles 1000x
 * smaller than their distance), with soft shadows from its surface: the
 * common-origin test must keep its barycentrics accurate there. */
static void fine_far_sphere(void **state) {
  (void)state;
  enum { RINGS = 300, SEGS = 600 };
  size_t nv = (RINGS + 1) * SEGS, nt = 2 * RINGS * SEGS;
  float *pos = malloc(nv * 3 * sizeof(float));
  uint32_t *idx = malloc(nt * 3 * sizeof(uint32_t));
  const float R = 0.1f;
  vec3 c = v3(0.3f, 0.7f, -0.2f);
  for (int i = 0; i <= RINGS; i++)
    for (int j = 0; j < SEGS; j++) {
      float th = (float)M_PI * (float)i / RINGS, ph = 2.0f * (float)M_PI * (float)j / SEGS;
      float *p = pos + 3 * ((size_t)i * SEGS + (size_t)j);
      p[0] = c.x + R * sinf(th) * cosf(ph); p[1] = c.y + R * cosf(th); p[2] = c.z + R * sinf(th) * sinf(ph);
    }
  size_t t = 0;
  for (int i = 0; i < RINGS; i++)
    for (int j = 0; j < SEGS; j++) {
      uint32_t a = (uint32_t)(i * SEGS + j), b = (uint32_t)(i * SEGS + (j + 1) % SEGS), d = a + SEGS, e = b + SEGS;
      uint32_t q[6] = {a, b, d, b, e, d};
      memcpy(idx + 3 * t, q, sizeof q);
      t += 2;
    }
  scene_data sd = {pos, idx, nv, nt};
  fr_scene *s = commit_scene(&sd);
  fr_camera cam;
  assert_int_equal(fr_camera_setup(&cam, v3_add(c, v3(0.6f, 0.75f, 1.8f)), c, v3(0, 1, 0), 8.0f, 64, 64), FR_OK);
  tally tl = {0};
  for (int y = 0; y < 64; y += 16)
    for (int x = 0; x < 64; x += 16) check_camera(s, &cam, x, y, &tl);
  /* shadows from points on the sphere towards a light above it */
  fr_rng r = fr_rng_seed(5, 5);
  mesh_ref m = scene_mesh(s);
  fr_mft_sets T;
  float e1[3] = {0.05f, 0, 0}, e2[3] = {0, 0, 0.05f};
  fr_mft_sets_light(&T, e1, e2, 9, FR_LIGHT_SETS_CELLS);
  for (int n = 0; n < 40; n++) {
    fr_mft_batch b;
    make_shadow_batch(&r, &m, v3_add(c, v3(0.1f, 0.4f, 0.05f)), 1e-5f, &b);
    check_shadows(s, &b, &T, &tl);
  }
  print_message("fine sphere: %ld rays, %ld disagreements (all at edges or range ends)\n", tl.rays, tl.disagree);
  assert_true(tl.disagree * 1000 < tl.rays);
  fr_scene_release(s);
  free_scene(&sd);
}

/* Every scene of ../shared/scenes from its own view at 64x64: camera frusta
 * against the single-ray kernel, and soft-shadow frusta to its quad light
 * (both ways of dealing out samples) against the single-ray kernel and
 * against 16-wide packets on the same rays. */
static void check_shared_scene(const char *path, tally *tl) {
  fr_scene *s;
  if (fr_scene_load(path, &s) != FR_OK) fail_msg("%s: %s", path, fr_last_error());
  assert_int_equal(fr_scene_commit(s), FR_OK);
  fr_view v;
  if (!fr_view_lookup(s->name, &v)) fail_msg("%s: no view", s->name);
  enum { SZ = FR_TEST_SANITIZED ? 32 : 64 };
  fr_camera cam;
  assert_int_equal(fr_camera_setup(&cam, v.eye, v.at, v.up, v.fov, SZ, SZ), FR_OK);
  for (int y = 0; y < SZ; y += 16)
    for (int x = 0; x < SZ; x += 16) check_camera(s, &cam, x, y, tl);
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  float eps = 1e-4f * v3_len(v3_sub(v3_load(hi), v3_load(lo)));
  float e1[3] = {v.area_e1.x, v.area_e1.y, v.area_e1.z}, e2[3] = {v.area_e2.x, v.area_e2.y, v.area_e2.z};
  vec3 centre = v3_add(v.area_c, v3_scale(v3_add(v.area_e1, v.area_e2), 0.5f));
  for (int kind = 0; kind < 2; kind++) {
    fr_mft_sets T;
    fr_mft_sets_light(&T, e1, e2, 3, kind ? FR_LIGHT_SETS_CELLS : FR_LIGHT_SETS_SPREAD);
    for (int by = kind * 2; by < SZ; by += 8)
      for (int bx = 0; bx < SZ; bx += 4) {
        fr_mft_batch b;
        camera_shadow_batch(s, &cam, bx, by, v.area_c, centre, eps, &b);
        uint16_t pk[16];
        packet16_occluded(s, &b, &T, pk);
        check_shadows_vs(s, &b, &T, tl, pk);
      }
  }
  fr_scene_release(s);
}

static void shared_scene_one(const char *path, void *ctx) {
  tally *tl = ctx;
  /* under the sanitizers: the three scenes with planar occluders, fine
   * shadows and a small tree (kitchen, museum, sibenik), not all fifteen */
  if (FR_TEST_SANITIZED && !strstr(path, "/kitchen.") && !strstr(path, "/museum.") && !strstr(path, "/sibenik."))
    return;
  long before = tl->disagree;
  check_shared_scene(path, tl);
  print_message("%s: %ld disagreements so far (+%ld)\n", path, tl->disagree, tl->disagree - before);
}

static void shared_scenes(void **state) {
  (void)state;
  tally tl = {0};
  int checked = for_each_shared_scene(shared_scene_one, &tl);
  print_message("shared scenes: %ld rays, %ld disagreements (all at edges or range ends), %ld rays in planar occluders "
                "(%ld bits from the occluders alone)\n",
                tl.rays, tl.disagree, tl.plane_rays, tl.planes_only);
  print_message("shared scenes: %ld batches through shafts, %ld planar occluders left out of them\n", tl.shafts,
                tl.planes_left_out);
  assert_true(tl.shafts > 0 && tl.planes_left_out > 0);
  assert_true(tl.planes_only > 0); /* kitchen's table top */
  assert_true(checked >= 14); /* found, if not all checked */
  assert_true(tl.disagree * 1000 < tl.rays);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(random_scenes),
      cmocka_unit_test(rays_frusta),
      cmocka_unit_test(builtin_scene),
      cmocka_unit_test(fine_far_sphere),
      cmocka_unit_test(shared_scenes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
