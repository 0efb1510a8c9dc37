/*
 * What multi-frusta tracing builds on, beside the kernels (test_mft.c): the
 * interleaved light sample sets, the SAH-cut leaves of the binary trees,
 * tile shafts (every leaf a segment of the shaft meets is listed, in double
 * precision), and the soft-shadow tile driver's fall-back to ray streams.
 */
#include <string.h>
#include "api/scene.h"
#include "random_scene.h"
#include "render/mft_rays.h"
#include "render/softshadow.h"
#include "render/views.h"
#include "render/workload.h"
#include "test_util.h"
#include "trace/kernels.h"
#include "trace/mft/mft.h"

/* The binary trees' leaves are cut by SAH (accel/bvh2.c): a room's
 * ceiling and wall, four large triangles, make two flat leaves rather than
 * one leaf as large as the room, which every shadow frustum in it would
 * enter; a tetrahedron's four faces, whose boxes overlap, stay one leaf. */
static void bvh2_leaves_by_sah(void **state) {
  (void)state;
  scene_data sd = {malloc(4 * 9 * sizeof(float)), malloc(4 * 3 * sizeof(uint32_t)), 0, 0};
  add_tri(&sd, v3(0, 10, 0), v3(10, 10, 0), v3(10, 10, 10)); /* ceiling */
  add_tri(&sd, v3(0, 10, 0), v3(10, 10, 10), v3(0, 10, 10));
  add_tri(&sd, v3(0, 0, 0), v3(0, 10, 0), v3(0, 10, 10)); /* wall */
  add_tri(&sd, v3(0, 0, 0), v3(0, 10, 10), v3(0, 0, 10));
  fr_scene *s = commit_scene(&sd);
  const fr_bvh2 *b = &s->bvh2;
  assert_false(b->root & FR_BVH2_LEAF);
  const fr_bvh2_node *n = &b->nodes[b->root];
  int flat_y = 0, flat_x = 0;
  for (int k = 0; k < 2; k++) {
    assert_true(n->child[k] & FR_BVH2_LEAF);
    assert_int_equal(FR_BVH2_LEAF_COUNT(n->child[k]), 2);
    flat_y += n->lo_y[k] == 10.0f && n->hi_y[k] == 10.0f;
    flat_x += n->lo_x[k] == 0.0f && n->hi_x[k] == 0.0f;
  }
  assert_int_equal(flat_y, 1);
  assert_int_equal(flat_x, 1);
  fr_scene_release(s);
  sd.nv = sd.nt = 0;
  const vec3 o = v3(0, 0, 0), x = v3(1, 0, 0), y = v3(0, 1, 0), z = v3(0, 0, 1);
  add_tri(&sd, o, y, x);
  add_tri(&sd, o, x, z);
  add_tri(&sd, o, z, y);
  add_tri(&sd, x, y, z);
  s = commit_scene(&sd);
  assert_true(s->bvh2.root & FR_BVH2_LEAF);
  assert_int_equal(FR_BVH2_LEAF_COUNT(s->bvh2.root), 4);
  fr_scene_release(s);
  free_scene(&sd);
  /* triangles whose boxes' areas would overflow float: refused at commit */
  scene_data big = {malloc(12 * 9 * sizeof(float)), malloc(12 * 3 * sizeof(uint32_t)), 0, 0};
  for (int i = 0; i < 12; i++) {
    const float f = (float)(i + 1) * 1e28f;
    add_tri(&big, v3(-f, -f, f), v3(f, -f, -f), v3(f, f, (float)i));
  }
  s = commit_scene_with(&big, 0);
  assert_int_equal(fr_scene_commit(s), FR_ERR_UNSUPPORTED);
  fr_scene_release(s);
  free_scene(&big);
}


/* The sample sets: each a (0,4,2)-net (one sample per 4x4 stratum and per
 * 1/16 row and column), the 16 together one per 16x16 stratum. */
static void light_sets_are_nets(void **state) {
  (void)state;
  fr_mft_sets T;
  float e1[3] = {1, 0, 0}, e2[3] = {0, 1, 0};
  for (uint64_t seed = 0; seed < 4; seed++) {
    fr_mft_sets_light(&T, e1, e2, seed, FR_LIGHT_SETS_SPREAD);
    int all[16][16] = {{0}};
    for (int j = 0; j < 16; j++) {
      int cell[4][4] = {{0}}, row[16] = {0}, col[16] = {0};
      for (int k = 0; k < 16; k++) {
        float a = T.set[j].a[k], b = T.set[j].b[k];
        assert_true(a >= 0.0f && a < 1.0f && b >= 0.0f && b < 1.0f);
        cell[(int)(a * 4)][(int)(b * 4)]++;
        col[(int)(a * 16)]++;
        row[(int)(b * 16)]++;
        all[(int)(a * 16)][(int)(b * 16)]++;
        assert_true(T.set[j].dx[k] == a && T.set[j].dy[k] == b);
      }
      for (int i = 0; i < 16; i++) {
        assert_int_equal(cell[i / 4][i % 4], 1);
        assert_int_equal(row[i], 1);
        assert_int_equal(col[i], 1);
      }
    }
    for (int i = 0; i < 16; i++)
      for (int k = 0; k < 16; k++) assert_int_equal(all[i][k], 1);
    /* cells: the same 256 points, set j inside cell j, one per 1/16 row and column of it */
    fr_mft_sets C;
    fr_mft_sets_light(&C, e1, e2, seed, FR_LIGHT_SETS_CELLS);
    int again[16][16] = {{0}};
    for (int j = 0; j < 16; j++) {
      int row[4] = {0}, col[4] = {0};
      for (int k = 0; k < 16; k++) {
        float a = C.set[j].a[k], b = C.set[j].b[k];
        assert_int_equal((int)(b * 4) * 4 + (int)(a * 4), j);
        again[(int)(a * 16)][(int)(b * 16)]++;
        col[(int)(a * 16) & 3]++;
        row[(int)(b * 16) & 3]++;
      }
      for (int i = 0; i < 4; i++) { assert_int_equal(row[i], 4); assert_int_equal(col[i], 4); }
    }
    assert_memory_equal(again, all, sizeof all);
  }
}

/* Soft shadows of a tile go as ray streams where a batch's frusta fetch
 * many triangles each (render/workload.c), and the batch that tells stops
 * short, its rays still open joining the streams. On the kitchen at
 * 128x128 every path runs (frusta, streams, a stopped batch, tile shafts):
 * the visibility must match the stream tracer's, pixel by pixel, up to rays
 * grazing an edge, and be the same without tile shafts. */
typedef struct ray_counter { fr_tracer inner; size_t rays, batches, stream_rays, stopped, shaft_batches; } ray_counter;

static void counted_occluded(void *ctx, const fr_ray *rays, uint8_t *occ, size_t n, int coherent) {
  ray_counter *c = ctx;
  c->rays += n;
  if (coherent == FR_RAYS_DIVERGENT) c->stream_rays += n;
  c->inner.occluded(c->inner.ctx, rays, occ, n, coherent);
}

static void counted_intersect(void *ctx, const fr_ray *rays, fr_hit *hits, size_t n, int coherent) {
  ray_counter *c = ctx;
  c->inner.intersect(c->inner.ctx, rays, hits, n, coherent);
}

static unsigned counted_intersect_frusta(void *ctx, const fr_mft_batch *b, const fr_mft_sets *t, fr_mft_hits *h) {
  ray_counter *c = ctx;
  return c->inner.intersect_frusta(c->inner.ctx, b, t, h);
}

static unsigned counted_occluded_frusta(void *ctx, const fr_mft_batch *b, const fr_mft_sets *t, uint16_t occ[16],
                                        fr_mft_budget *budget, fr_mft_occluders *cache) {
  ray_counter *c = ctx;
  c->batches++;
  c->shaft_batches += cache && cache->shaft;
  const unsigned fetched = c->inner.occluded_frusta(c->inner.ctx, b, t, occ, budget, cache);
  c->stopped += budget && budget->stopped;
  return fetched;
}

static const fr_bvh2 *counted_shaft_tree(void *ctx) {
  ray_counter *c = ctx;
  return c->inner.shaft_tree(c->inner.ctx);
}

/* Kitchen committed, and *w a one-thread workload of its view at size x
 * size pixels; returns the scene (the caller releases it). */
static fr_scene *kitchen_workload(fr_workload *w, int size) {
  char path[1024];
  shared_scene_path(path, sizeof path, "kitchen/kitchen.ply.zst");
  fr_scene *s;
  if (fr_scene_load(path, &s) != FR_OK) fail_msg("%s: %s", path, fr_last_error());
  assert_int_equal(fr_scene_commit(s), FR_OK);
  memset(w, 0, sizeof *w);
  w->scene = s;
  assert_true(fr_view_lookup(s->name, &w->view));
  assert_int_equal(fr_camera_setup(&w->cam, w->view.eye, w->view.at, w->view.up, w->view.fov, size, size), FR_OK);
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  w->eps = 1e-4f * v3_len(v3_sub(v3_load(hi), v3_load(lo)));
  w->threads = 1;
  return s;
}

static void soft_fallback(void **state) {
  (void)state;
  enum { SZ = 128 };
  fr_workload w;
  fr_scene *s = kitchen_workload(&w, SZ);
  fr_softshadow_opts so = {16, 0, FR_LIGHT_SETS_SPREAD};
  static float img[SZ * SZ * 3], vis_mft[SZ * SZ], vis_rays[SZ * SZ];
  fr_mft_tracer mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  ray_counter c = {fr_tracer_mft(&mctx), 0, 0, 0, 0, 0};
  fr_tracer counted = {&c, counted_intersect, counted_occluded, counted_intersect_frusta, counted_occluded_frusta, 0,
                       counted_shaft_tree};
  fr_workload_result r;
  /* without tile shafts first (every batch walks from the root, and no
   * shaft decides a fall-back), then with: the same visibility */
  static float vis_walk[SZ * SZ];
  w.mft_no_shaft = 1;
  assert_int_equal(fr_render_softshadow(&w, &counted, &so, img, vis_walk, &r), FR_OK);
  w.mft_no_shaft = 0;
  assert_int_equal(c.shaft_batches, 0);
  c.batches = c.stopped = c.rays = c.stream_rays = 0;
  assert_int_equal(fr_render_softshadow(&w, &counted, &so, img, vis_mft, &r), FR_OK);
  assert_true(c.shaft_batches > 0);
  assert_memory_equal(vis_walk, vis_mft, sizeof vis_mft);
  fr_tracer rays = fr_tracer_frusta(s);
  assert_int_equal(fr_render_softshadow(&w, &rays, &so, img, vis_rays, &r), FR_OK);
  print_message("kitchen soft shadows: %zu frusta batches (%zu stopped short, %zu through tile shafts), %zu rays as "
                "rays, %zu of them in ray streams\n", c.batches, c.stopped, c.shaft_batches, c.rays, c.stream_rays);
  /* every path ran; fallen-back tiles take streams only */
  assert_true(c.batches > 0 && c.rays > 0 && c.rays == c.stream_rays && c.stopped > 0);
  double sum = 0.0;
  for (int i = 0; i < SZ * SZ; i++) {
    float d = fabsf(vis_mft[i] - vis_rays[i]);
    assert_true(d <= 2.0f / 16.0f + 1e-6f);
    sum += d;
  }
  assert_true(sum / (SZ * SZ) < 0.002);
  fr_scene_release(s);
}

/* The shadow workload through the multi-frusta tracer: tiles over few
 * triangles send their point-light shadow rays as frusta from the light,
 * the others as rays from the points (tile.c, POINT_FRUSTA_MAX_TRIS). Both
 * kinds of tile must occur, and the pixels' verdicts must be the rays':
 * all but at most 1 in 2000 (none on this view), which the two ways may
 * judge apart where an occluder lies within rounding of a segment's end. */
static void point_shadow_tiles(void **state) {
  (void)state;
  enum { SZ = 256 };
  fr_workload w;
  fr_scene *s = kitchen_workload(&w, SZ);
  w.kind = FR_WL_SHADOW;
  static float vis_mft[SZ * SZ], vis_rays[SZ * SZ], depth[SZ * SZ], normal[3 * SZ * SZ], albedo[3 * SZ * SZ];
  w.gbuf_depth = depth;
  w.gbuf_normal = normal;
  w.gbuf_albedo = albedo;
  fr_mft_tracer mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  ray_counter c = {fr_tracer_mft(&mctx), 0, 0, 0, 0, 0};
  fr_tracer counted = {&c, counted_intersect, counted_occluded, counted_intersect_frusta, counted_occluded_frusta, 0,
                       counted_shaft_tree};
  w.gbuf_vis = vis_mft;
  fr_workload_run(&w, &counted);
  fr_tracer rays = fr_tracer_frusta(s);
  w.gbuf_vis = vis_rays;
  fr_workload_run(&w, &rays);
  size_t differ = 0, lit = 0;
  for (int i = 0; i < SZ * SZ; i++) {
    differ += vis_mft[i] != vis_rays[i];
    lit += vis_rays[i] == 1.0f;
  }
  print_message("kitchen shadow workload: %zu frusta batches (%zu over their budget), %zu rays as rays; %zu of %d "
                "pixels lit, %zu differ\n", c.batches, c.stopped, c.rays, lit, SZ * SZ, differ);
  assert_true(c.batches > 0 && c.rays > 0);
  assert_true(lit > SZ * SZ / 8 && lit < SZ * SZ * 7 / 8);
  assert_true(differ <= SZ * SZ / 2000);
  fr_scene_release(s);
}

/* Whether segment p + t (q - p), t in [0, 1], meets box [lo, hi], in
 * double precision. */
static int segment_meets(const double p[3], const double q[3], const float lo[3], const float hi[3]) {
  double t0 = 0.0, t1 = 1.0;
  for (int a = 0; a < 3; a++) {
    const double d = q[a] - p[a];
    if (d == 0.0) {
      if (p[a] < lo[a] || p[a] > hi[a]) return 0;
      continue;
    }
    double u = (lo[a] - p[a]) / d, v = (hi[a] - p[a]) / d;
    if (u > v) { double w = u; u = v; v = w; }
    t0 = u > t0 ? u : t0;
    t1 = v < t1 ? v : t1;
  }
  return t0 <= t1;
}

/* Every leaf a segment from P to Q meets, walking the whole tree, must be
 * in the shaft's list: random boxes of origins (points, flat, wide) on
 * random scenes and the built-in one, a quad light's box, and segments
 * from their corners, faces and insides. */
static void check_shaft_covers(const fr_bvh2 *b, fr_rng *r, const float plo[3], const float phi[3], const float qlo[3],
                               const float qhi[3], long *built, long *segments) {
  fr_mft_shaft sh;
  if (!fr_mft_shaft_build(b, plo, phi, qlo, qhi, &sh)) return;
  (*built)++;
  for (int n = 0; n < 200; n++) {
    double p[3], q[3];
    for (int a = 0; a < 3; a++) {
      /* a third of the coordinates on the box's faces */
      const unsigned k = fr_rng_u32(r) % 3;
      const double up = k == 0 ? 0.0 : k == 1 ? 1.0 : fr_rng_float(r), uq = fr_rng_u32(r) % 3 ? fr_rng_float(r) : (double)(n & 1);
      p[a] = plo[a] + up * ((double)phi[a] - plo[a]);
      q[a] = qlo[a] + uq * ((double)qhi[a] - qlo[a]);
    }
    uint32_t stack[256];
    int sp = 0;
    stack[sp++] = b->root;
    while (sp) {
      const uint32_t node = stack[--sp];
      const fr_bvh2_node *nd = &b->nodes[node];
      for (int k = 0; k < 2; k++) {
        const float lo[3] = {nd->lo_x[k], nd->lo_y[k], nd->lo_z[k]}, hi[3] = {nd->hi_x[k], nd->hi_y[k], nd->hi_z[k]};
        if (!segment_meets(p, q, lo, hi)) continue;
        const uint32_t c = nd->child[k];
        if (!(c & FR_BVH2_LEAF)) {
          assert_true(sp < 256);
          stack[sp++] = c;
          continue;
        }
        if (!FR_BVH2_LEAF_COUNT(c)) continue;
        int listed = 0;
        for (unsigned i = 0; i < sh.n; i++) listed |= sh.leaf[i] == (node << 1 | (uint32_t)k);
        if (!listed) fail_msg("leaf %u/%d met by a segment is not in the shaft", node, k);
      }
    }
    (*segments)++;
  }
}

static void shaft_covers(void **state) {
  (void)state;
  fr_rng r = fr_rng_seed(17, 4);
  long built = 0, segments = 0;
  for (int round = 0; round < 7; round++) {
    fr_scene *s;
    scene_data sd = {0};
    float size = 1.0f;
    vec3 center = v3(0, 0, 0);
    if (round == 6) {
      assert_int_equal(fr_scene_builtin(&s), FR_OK);
      assert_int_equal(fr_scene_commit(s), FR_OK);
      float lo[3], hi[3];
      fr_scene_bounds(s, lo, hi);
      center = v3_scale(v3_add(v3_load(lo), v3_load(hi)), 0.5f);
      size = 0.5f * v3_len(v3_sub(v3_load(hi), v3_load(lo)));
    } else {
      center = round % 3 == 2 ? v3(1e4f, -3e3f, 2e3f) : v3(0, 0, 0);
      size = round % 2 ? 1.0f : 30.0f;
      sd = make_scene(&r, 400 + 200 * (size_t)round, center, size);
      s = commit_scene(&sd);
    }
    mesh_ref m = scene_mesh(s);
    for (int n = 0; n < 300; n++) {
      /* origins around a surface point: a point, a flat box, a box */
      const vec3 c = random_surface_point(&r, &m);
      const float ext[3] = {0.0f, n % 3 ? 0.02f * size * fr_rng_float(&r) : 0.0f, n % 3 == 2 ? 0.05f * size : 0.0f};
      float plo[3], phi[3], qlo[3], qhi[3];
      const float cc[3] = {c.x, c.y, c.z};
      for (int a = 0; a < 3; a++) {
        plo[a] = cc[a] - ext[(a + n) % 3];
        phi[a] = cc[a] + ext[(a + n) % 3];
      }
      /* a quad light above the scene, flat in y */
      const float lx = center.x + urand(&r, -size, size), lz = center.z + urand(&r, -size, size), ly = center.y + 2.0f * size;
      qlo[0] = lx; qhi[0] = lx + 0.3f * size;
      qlo[1] = qhi[1] = ly;
      qlo[2] = lz; qhi[2] = lz + 0.2f * size;
      check_shaft_covers(&s->bvh2_mft, &r, plo, phi, qlo, qhi, &built, &segments);
    }
    fr_scene_release(s);
    if (round < 6) free_scene(&sd);
  }
  print_message("shafts: %ld built, %ld segments, every leaf they meet listed\n", built, segments);
  assert_true(built > 100);
}


int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(light_sets_are_nets),
      cmocka_unit_test(bvh2_leaves_by_sah),
      cmocka_unit_test(shaft_covers),
      cmocka_unit_test(soft_fallback),
      cmocka_unit_test(point_shadow_tiles),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
