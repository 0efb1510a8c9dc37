/*
 * Exact answers on hostile geometry: generated scenes at their worst
 * (triangles over five orders of magnitude of size with slivers whose third
 * vertex lies within 1e-6 of the opposite edge, cities of boxes 1e4 and 1e6
 * from the origin, long thin strands, degenerate triangles among ordinary
 * ones), traced with random, aimed, surface-leaving and coherent rays by
 * every tracer (single rays at both BVH widths, the 16-ray packet call,
 * every stream mode, large packets, multi-frusta) at every ISA, and judged
 * ray by ray in double precision by the rule of exact_judge.h: 0 wrong.
 */
#include "api/scene.h"
#include "exact_judge.h"
#include "random_scene.h"
#include "test_util.h"
#include "trace/lpacket/lpacket.h"
#include "trace/mft/mft.h"

static const fr_isa isas[] = {FR_ISA_SCALAR, FR_ISA_AVX2, FR_ISA_AVX512};
static const fr_lp_fns *lp_fns[] = {&fr_lp_scalar, &fr_lp_avx2, &fr_lp_avx512};
static const fr_mft_fns *mft_fns[] = {&fr_mft_scalar, &fr_mft_avx2, &fr_mft_avx512};

/* ---- scenes ---------------------------------------------------------------- */

static scene_data scene_alloc(size_t nt) {
  scene_data s = {malloc(nt * 9 * sizeof(float)), malloc(nt * 3 * sizeof(uint32_t)), 0, 0};
  return s;
}

static vec3 random_unit(fr_rng *r) {
  for (;;) {
    vec3 v = v3(urand(r, -1, 1), urand(r, -1, 1), urand(r, -1, 1));
    float l = v3_len(v);
    if (l > 0.1f && l <= 1.0f) return v3_scale(v, 1.0f / l);
  }
}

/* Triangles of sizes from 1e-3 to 1e2 in a box of 100: ordinary ones,
 * slivers (the third vertex within 1e-6 of the line through the other two,
 * between them or just beyond), needles (two vertices 1e-4 apart) and
 * thin ones (the third vertex 3e-3 to 3e-2 off the line). */
static scene_data soup(fr_rng *r, size_t n) {
  scene_data s = scene_alloc(n);
  for (size_t i = 0; i < n; i++) {
    float size = powf(10.0f, urand(r, -3.0f, 2.0f));
    vec3 a = v3(urand(r, -50, 50), urand(r, -50, 50), urand(r, -50, 50));
    vec3 e = v3_scale(random_unit(r), size), b = v3_add(a, e), c;
    if (i % 4 == 0) {
      c = v3_add(a, v3_scale(random_unit(r), size));
    } else if (i % 4 == 1 || i % 4 == 3) {
      const float off = i % 4 == 1 ? urand(r, -1e-6f, 1e-6f) : powf(10.0f, urand(r, -2.5f, -1.5f));
      vec3 perp = v3_norm(v3_cross(e, random_unit(r)));
      c = v3_add(v3_add(a, v3_scale(e, urand(r, -0.2f, 1.2f))), v3_scale(perp, size * off));
    } else {
      c = v3_add(b, v3_scale(random_unit(r), size * 1e-4f));
    }
    add_tri(&s, a, b, c);
  }
  return s;
}

/* A grid of closed boxes (8 shared vertices, 12 triangles each) whose
 * corner lies at `offset` from the origin. */
static scene_data city(fr_rng *r, int side, float offset) {
  scene_data s = scene_alloc((size_t)side * side * 12);
  static const int quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (int i = 0; i < side; i++)
    for (int j = 0; j < side; j++) {
      vec3 lo = v3(offset + 12.0f * (float)i + urand(r, 0, 2), offset + urand(r, -1, 1), offset + 12.0f * (float)j + urand(r, 0, 2));
      vec3 hi = v3_add(lo, v3(urand(r, 1, 10), urand(r, 1, 40), urand(r, 1, 10)));
      uint32_t base = (uint32_t)s.nv;
      for (int k = 0; k < 8; k++) {
        vec3 p = v3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
        s.pos[3 * s.nv] = p.x; s.pos[3 * s.nv + 1] = p.y; s.pos[3 * s.nv + 2] = p.z;
        s.nv++;
      }
      for (int f = 0; f < 6; f++) {
        const int *q = quads[f];
        uint32_t t0[3] = {base + q[0], base + q[1], base + q[2]}, t1[3] = {base + q[0], base + q[2], base + q[3]};
        memcpy(s.idx + 3 * s.nt++, t0, sizeof t0);
        memcpy(s.idx + 3 * s.nt++, t1, sizeof t1);
      }
    }
  return s;
}

/* Hair: ribbons of `segs` segments 0.05 long and 2 half_width wide (two
 * long thin triangles sharing a diagonal per segment, segments sharing
 * edges). */
static scene_data strands(fr_rng *r, int count, int segs, float half_width) {
  scene_data s = scene_alloc((size_t)count * segs * 2);
  for (int h = 0; h < count; h++) {
    vec3 p = v3(urand(r, -1, 1), urand(r, -1, 1), urand(r, -1, 1)), dir = random_unit(r);
    vec3 side = v3_scale(v3_norm(v3_cross(dir, random_unit(r))), half_width);
    uint32_t prev = (uint32_t)s.nv;
    vec3 l = v3_sub(p, side), rr = v3_add(p, side);
    s.pos[3 * s.nv] = l.x; s.pos[3 * s.nv + 1] = l.y; s.pos[3 * s.nv + 2] = l.z; s.nv++;
    s.pos[3 * s.nv] = rr.x; s.pos[3 * s.nv + 1] = rr.y; s.pos[3 * s.nv + 2] = rr.z; s.nv++;
    for (int k = 0; k < segs; k++) {
      dir = v3_norm(v3_add(dir, v3_scale(random_unit(r), 0.3f)));
      p = v3_add(p, v3_scale(dir, 0.05f));
      side = v3_scale(v3_norm(v3_cross(dir, v3_add(side, v3_scale(random_unit(r), 0.1f * half_width)))), half_width);
      l = v3_sub(p, side);
      rr = v3_add(p, side);
      uint32_t cur = (uint32_t)s.nv;
      s.pos[3 * s.nv] = l.x; s.pos[3 * s.nv + 1] = l.y; s.pos[3 * s.nv + 2] = l.z; s.nv++;
      s.pos[3 * s.nv] = rr.x; s.pos[3 * s.nv + 1] = rr.y; s.pos[3 * s.nv + 2] = rr.z; s.nv++;
      uint32_t t0[3] = {prev, prev + 1, cur + 1}, t1[3] = {prev, cur + 1, cur};
      memcpy(s.idx + 3 * s.nt++, t0, sizeof t0);
      memcpy(s.idx + 3 * s.nt++, t1, sizeof t1);
      prev = cur;
    }
  }
  return s;
}

/* Ordinary triangles with exactly degenerate ones (a repeated vertex,
 * three on a line), nearly degenerate ones (1e-7 off the line) and tiny
 * ones (1e-6 across) among them, in a box of 20. */
static scene_data degenerate_mix(fr_rng *r, size_t n) {
  scene_data s = scene_alloc(n);
  for (size_t i = 0; i < n; i++) {
    vec3 a = v3(urand(r, -10, 10), urand(r, -10, 10), urand(r, -10, 10));
    vec3 b = v3_add(a, v3_scale(random_unit(r), urand(r, 0.1f, 3.0f))), c;
    switch (i % 5) {
    case 0: c = b; break;
    case 1: c = v3_add(a, v3_scale(v3_sub(b, a), 2.0f)); break;
    case 2: c = v3_add(v3_add(a, v3_scale(v3_sub(b, a), 0.5f)), v3_scale(random_unit(r), 1e-7f)); break;
    case 3: b = v3_add(a, v3_scale(random_unit(r), 1e-6f)); c = v3_add(a, v3_scale(random_unit(r), 1e-6f)); break;
    default: c = v3_add(a, v3_scale(random_unit(r), urand(r, 0.1f, 3.0f))); break;
    }
    add_tri(&s, a, b, c);
  }
  return s;
}

/* ---- rays ------------------------------------------------------------------- */

typedef struct bounds { vec3 lo, hi; } bounds;

static vec3 in_box(fr_rng *r, bounds b) {
  return v3(urand(r, b.lo.x, b.hi.x), urand(r, b.lo.y, b.hi.y), urand(r, b.lo.z, b.hi.z));
}

static vec3 on_triangle(fr_rng *r, const scene_data *sd, uint32_t t) {
  vec3 a = v3_load(sd->pos + 3 * sd->idx[3 * t]), b = v3_load(sd->pos + 3 * sd->idx[3 * t + 1]);
  vec3 c = v3_load(sd->pos + 3 * sd->idx[3 * t + 2]);
  float u = fr_rng_float(r), v = fr_rng_float(r);
  if (u + v > 1.0f) { u = 1.0f - u; v = 1.0f - v; }
  return v3_add(a, v3_add(v3_scale(v3_sub(b, a), u), v3_scale(v3_sub(c, a), v)));
}

/* Groups of 16: from a random point to random points; leaving a surface
 * (from a point of a triangle, tnear 0, small or a few percent of the
 * scene); aimed at surface points from around the scene (half with tfar
 * just short of the point); and coherent groups from one point to a patch
 * of surface, as camera and shadow rays are. */
static void make_rays(fr_rng *r, const scene_data *sd, bounds b, fr_ray *rays, size_t n) {
  const float extent = v3_len(v3_sub(b.hi, b.lo));
  const vec3 mid = v3_scale(v3_add(b.lo, b.hi), 0.5f);
  bounds wide = {v3_sub(mid, v3_sub(b.hi, mid)), v3_add(mid, v3_sub(b.hi, mid))};
  wide.lo = v3_sub(wide.lo, v3_scale(v3_sub(b.hi, b.lo), 0.5f));
  wide.hi = v3_add(wide.hi, v3_scale(v3_sub(b.hi, b.lo), 0.5f));
  for (size_t g = 0; g < n / 16; g++) {
    const int kind = (int)(g % 4);
    const vec3 shared = in_box(r, wide);
    const uint32_t patch = fr_rng_u32(r) % (uint32_t)sd->nt;
    for (int i = 0; i < 16; i++) {
      fr_ray *ray = &rays[16 * g + (size_t)i];
      vec3 o, d;
      float tnear = 0.0f, tfar = INFINITY;
      if (kind == 0) {
        o = in_box(r, b);
        d = v3_sub(in_box(r, b), o);
        if (fr_rng_u32(r) % 4 == 0) tfar = urand(r, 0.1f, 1.0f);
      } else if (kind == 1) {
        o = on_triangle(r, sd, fr_rng_u32(r) % (uint32_t)sd->nt);
        d = random_unit(r);
        const int near_kind = (int)(fr_rng_u32(r) % 3);
        tnear = near_kind == 0 ? 0.0f : near_kind == 1 ? 1e-5f * extent : urand(r, 0.0f, 0.05f) * extent;
      } else if (kind == 2) {
        o = in_box(r, wide);
        vec3 p = on_triangle(r, sd, fr_rng_u32(r) % (uint32_t)sd->nt);
        d = v3_sub(p, o);
        if (fr_rng_u32(r) & 1) tfar = 1.0f - 1e-4f;
      } else {
        o = shared;
        d = v3_sub(on_triangle(r, sd, (patch + (uint32_t)i) % (uint32_t)sd->nt), o);
      }
      if (!(v3_len(d) > 0.0f)) d = v3(0, 1, 0);
      if (fr_rng_u32(r) & 1) d = v3_norm(d);
      *ray = (fr_ray){{o.x, o.y, o.z}, tnear, {d.x, d.y, d.z}, tfar};
    }
  }
}

/* ---- tracers ------------------------------------------------------------------ */

typedef struct tally {
  char name[64];
  long rays, wrong;
} tally;

typedef struct exam {
  const fr_scene *scene;
  const jd_mesh *m;
  const fr_ray *rays;
  const jd_ray *judged;
  size_t n;
  const char *scene_name;
  tally *tallies;
  int ntallies;
  fr_hit *hits;
  uint8_t *occ;
} exam;

static tally *tally_of(exam *e, const char *name) {
  for (int i = 0; i < e->ntallies; i++)
    if (!strcmp(e->tallies[i].name, name)) return &e->tallies[i];
  tally *t = &e->tallies[e->ntallies];
  snprintf(t->name, sizeof t->name, "%s", name);
  t->rays = t->wrong = 0;
  e->ntallies++;
  return t;
}

static void report(exam *e, tally *t, size_t i, const char *why, const fr_ray *ray, const fr_hit *h, int occ) {
  t->wrong++;
  if (t->wrong > 3) return;
  uint32_t bp;
  double margin, bt = brute_force(fr_scene_vertices(e->scene), fr_scene_indices(e->scene), fr_scene_triangle_count(e->scene),
                                  ray, &bp, &margin, 1);
  print_message("%s %s ray %zu: %s (prim %u t %.9g occ %d; double t %.9g prim %u; org %a %a %a dir %a %a %a range %a %a)\n",
                e->scene_name, t->name, i, why, h ? h->prim : 0, h ? h->t : 0.0, occ, bt, bp, ray->org[0], ray->org[1],
                ray->org[2], ray->dir[0], ray->dir[1], ray->dir[2], ray->tnear, ray->tfar);
}

static void judge_all(exam *e, const char *name, const fr_ray *rays, const jd_ray *judged, size_t n, const fr_hit *hits,
                      const uint8_t *occ) {
  tally *t = tally_of(e, name);
  for (size_t i = 0; i < n; i++) {
    t->rays++;
    const char *why = hits ? jd_check_hit(e->m, &judged[i], &rays[i], &hits[i]) : jd_check_occluded(&judged[i], occ[i]);
    if (why) report(e, t, i, why, &rays[i], hits ? &hits[i] : NULL, occ ? occ[i] : -1);
  }
}

static const char *mode_names[] = {"auto", "single", "packet8", "packet16", "hybrid16", "raystream"};

/* The API's calls: single rays at both widths, 16-ray packets, streams in every mode. */
static void exam_api(exam *e, int isa) {
  fr_scene *s = (fr_scene *)e->scene;
  char name[64];
  for (int w = 4; w <= 8; w += 4) {
    assert_int_equal(fr_scene_set_bvh_width(s, w), FR_OK);
    for (size_t i = 0; i < e->n; i++) {
      fr_intersect1(s, &e->rays[i], &e->hits[i]);
      e->occ[i] = (uint8_t)fr_occluded1(s, &e->rays[i]);
    }
    snprintf(name, sizeof name, "single bvh%d %s", w, fr_isa_name(isas[isa]));
    judge_all(e, name, e->rays, e->judged, e->n, e->hits, NULL);
    judge_all(e, name, e->rays, e->judged, e->n, NULL, e->occ);
  }
  for (size_t g = 0; g + 16 <= e->n; g += 16) {
    fr_ray16 p;
    fr_hit16 h;
    for (int i = 0; i < 16; i++) {
      const fr_ray *ray = &e->rays[g + (size_t)i];
      p.org_x[i] = ray->org[0]; p.org_y[i] = ray->org[1]; p.org_z[i] = ray->org[2]; p.tnear[i] = ray->tnear;
      p.dir_x[i] = ray->dir[0]; p.dir_y[i] = ray->dir[1]; p.dir_z[i] = ray->dir[2]; p.tfar[i] = ray->tfar;
    }
    fr_intersect16(s, 0xFFFFu, &p, &h);
    const unsigned occ = fr_occluded16(s, 0xFFFFu, &p);
    for (int i = 0; i < 16; i++) {
      e->hits[g + (size_t)i] = (fr_hit){h.t[i], h.u[i], h.v[i], h.prim[i], {0, 0, 0}};
      e->occ[g + (size_t)i] = (uint8_t)((occ >> i) & 1);
    }
  }
  snprintf(name, sizeof name, "intersect16 %s", fr_isa_name(isas[isa]));
  judge_all(e, name, e->rays, e->judged, e->n, e->hits, NULL);
  judge_all(e, name, e->rays, e->judged, e->n, NULL, e->occ);
  for (int mode = FR_TRACE_AUTO; mode <= FR_TRACE_RAYSTREAM; mode++) {
    assert_int_equal(fr_scene_set_trace_mode(s, (fr_trace_mode)mode), FR_OK);
    fr_intersect_stream(s, e->rays, e->hits, e->n);
    fr_occluded_stream(s, e->rays, e->occ, e->n);
    snprintf(name, sizeof name, "stream %s %s", mode_names[mode], fr_isa_name(isas[isa]));
    judge_all(e, name, e->rays, e->judged, e->n, e->hits, NULL);
    judge_all(e, name, e->rays, e->judged, e->n, NULL, e->occ);
  }
  assert_int_equal(fr_scene_set_trace_mode(s, FR_TRACE_AUTO), FR_OK);
}

/* Large packets of 256 consecutive rays, every traversal and cull. */
static void exam_lpacket(exam *e, int isa) {
  static fr_lpacket lp;
  char name[64];
  fr_lp_scene g = {&e->scene->bvh2, NULL, 0};
  for (int tr = 0; tr < FR_LP_TRAVERSAL_COUNT; tr++)
    for (int c = 0; c < FR_CULL_COUNT; c++) {
      fr_lp_opts o = {(fr_lp_traversal)tr, (fr_cull)c};
      for (size_t a = 0; a < e->n; a += 256) {
        const int m = (int)(e->n - a < 256 ? e->n - a : 256);
        fr_lpacket_load(&lp, e->rays + a, m);
        lp_fns[isa]->intersect(&g, &o, &lp);
        fr_lpacket_hits(&lp, &g, e->hits + a);
        fr_lpacket_load(&lp, e->rays + a, m);
        lp_fns[isa]->occluded(&g, &o, &lp);
        for (int k = 0; k < m; k++) e->occ[a + (size_t)k] = (uint8_t)((lp.occ[k / 16] >> (k % 16)) & 1);
      }
      snprintf(name, sizeof name, "lpacket %s/%s %s", fr_lp_traversal_name(o.traversal), fr_cull_name(o.cull),
               fr_isa_name(isas[isa]));
      judge_all(e, name, e->rays, e->judged, e->n, e->hits, NULL);
      judge_all(e, name, e->rays, e->judged, e->n, NULL, e->occ);
    }
}

/* Multi-frusta around batches of rays from one point to surface points
 * (shadow rays from a point light), judged on the rays the frusta trace. */
static void exam_mft(exam *e, int isa, fr_rng *r, const scene_data *sd, bounds b, int batches) {
  static fr_ray rays[256], traced[256];
  static fr_hit hits[256];
  static uint8_t occ[256];
  static jd_ray judged[256];
  static fr_mft_sets T;
  char name[64];
  snprintf(name, sizeof name, "mft %s", fr_isa_name(isas[isa]));
  const fr_mft_opts o = fr_mft_opts_default();
  for (int k = 0; k < batches; k++) {
    vec3 light = in_box(r, b);
    light.y = b.hi.y + 0.1f * (b.hi.y - b.lo.y);
    for (int i = 0; i < 256; i++) {
      vec3 d = v3_sub(on_triangle(r, sd, fr_rng_u32(r) % (uint32_t)sd->nt), light);
      float dist = v3_len(d);
      d = v3_scale(d, 1.0f / dist);
      rays[i] = (fr_ray){{light.x, light.y, light.z}, 0.0f, {d.x, d.y, d.z}, dist * (1.0f - 1e-4f)};
    }
    fr_mft_batch batch;
    fr_mft_hits h;
    const unsigned valid = mft_fns[isa]->from_rays(&batch, &T, rays, 256);
    mft_fns[isa]->intersect(&e->scene->bvh2, &o, &batch, &T, &h);
    uint16_t occb[16];
    mft_fns[isa]->occluded(&e->scene->bvh2, &o, &batch, &T, occb, NULL, NULL);
    size_t n = 0;
    for (int f = 0; f < 16; f++) {
      if (!((valid >> f) & 1)) continue;
      for (int q = 0; q < 16; q++, n++) {
        fr_ray *t = &traced[n];
        fr_mft_ray(&batch, &T, f, q, t->org, t->dir);
        t->tnear = batch.tnear[f];
        t->tfar = batch.tfar[f];
        judged[n] = jd_judge(e->m, t);
        hits[n] = (fr_hit){h.prim[f][q] == FR_INVALID_ID ? INFINITY : h.t[f][q], h.u[f][q], h.v[f][q], h.prim[f][q], {0, 0, 0}};
        occ[n] = (uint8_t)((occb[f] >> q) & 1);
      }
    }
    judge_all(e, name, traced, judged, n, hits, NULL);
    judge_all(e, name, traced, judged, n, NULL, occ);
  }
}

static long examine(const char *scene_name, scene_data *sd, uint64_t seed, size_t nrays) {
  fr_rng r = fr_rng_seed(seed, 7);
  fr_scene *s = commit_scene(sd);
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  bounds b = {v3_load(lo), v3_load(hi)};
  jd_mesh m = jd_mesh_make(sd->pos, sd->idx, sd->nt);
  fr_ray *rays = malloc(nrays * sizeof *rays);
  jd_ray *judged = malloc(nrays * sizeof *judged);
  make_rays(&r, sd, b, rays, nrays);
  for (size_t i = 0; i < nrays; i++) judged[i] = jd_judge(&m, &rays[i]);
  static tally tallies[256];
  const fr_isa before = fr_get_isa();
  exam e = {s, &m, rays, judged, nrays, scene_name, tallies, 0, malloc(nrays * sizeof(fr_hit)), malloc(nrays)};
  for (int isa = 0; isa < 3; isa++) {
    if (!fr_isa_supported(isas[isa])) continue;
    assert_int_equal(fr_set_isa(isas[isa]), FR_OK);
    exam_api(&e, isa);
    exam_lpacket(&e, isa);
    fr_rng mr = fr_rng_seed(seed, 11);
    exam_mft(&e, isa, &mr, sd, b, FR_TEST_ROUNDS(8));
  }
  fr_set_isa(before);
  long wrong = 0;
  int clear = 0;
  for (size_t i = 0; i < nrays; i++) clear += judged[i].clear;
  for (int i = 0; i < e.ntallies; i++) {
    wrong += tallies[i].wrong;
    if (tallies[i].wrong) print_message("%s: %s: %ld of %ld answers wrong\n", scene_name, tallies[i].name, tallies[i].wrong, tallies[i].rays);
  }
  print_message("%s: %zu triangles, %zu rays (%d with a clear hit), %d tracers: %ld answers wrong\n", scene_name, sd->nt,
                nrays, clear, e.ntallies, wrong);
  free(e.hits);
  free(e.occ);
  free(rays);
  free(judged);
  free(m.tri);
  fr_scene_release(s);
  free_scene(sd);
  return wrong;
}

static size_t rays_per_scene(void) { return (size_t)FR_TEST_ROUNDS(8) * 1024; }

static void test_soup(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(1, 1);
  scene_data sd = soup(&r, (size_t)FR_TEST_ROUNDS(4) * 5000);
  assert_int_equal(examine("soup", &sd, 1, rays_per_scene()), 0);
}

static void test_city_far(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(2, 1);
  scene_data sd = city(&r, 20, 1e4f);
  assert_int_equal(examine("city at 1e4", &sd, 2, rays_per_scene()), 0);
  sd = city(&r, 20, 1e6f);
  assert_int_equal(examine("city at 1e6", &sd, 3, rays_per_scene()), 0);
}

static void test_strands(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(4, 1);
  scene_data sd = strands(&r, FR_TEST_ROUNDS(4) * 100, 40, 2e-3f);
  assert_int_equal(examine("strands", &sd, 4, rays_per_scene()), 0);
  sd = strands(&r, FR_TEST_ROUNDS(4) * 100, 40, 1e-4f);
  assert_int_equal(examine("hair strands", &sd, 6, rays_per_scene()), 0);
}

static void test_degenerate(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(5, 1);
  scene_data sd = degenerate_mix(&r, (size_t)FR_TEST_ROUNDS(4) * 1000);
  assert_int_equal(examine("degenerate mix", &sd, 5, rays_per_scene()), 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_soup), cmocka_unit_test(test_city_far),
                                     cmocka_unit_test(test_strands), cmocka_unit_test(test_degenerate)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
