/*
 * The Whitted renderer on kitchen and museum (their MTL mirrors and glass):
 * every packet the engine hands to the large-packet tracer (camera,
 * shadow, reflection and refraction packets) is traced again ray by ray by
 * the single-ray kernel, and the answers must agree (a disagreement must be
 * a ray within rounding of an edge or of tnear/tfar), for every packet size
 * and traversal, culls on and off, and for the multi-frusta tracer, whose
 * camera rays come as frusta. The rays really are Whitted's: there are
 * secondary rays of every kind. The shading kernel, at every ISA level,
 * against per-ray scalar formulas, bit for bit.
 */
#include <string.h>
#include "api/scene.h"
#include "render/camera.h"
#include "render/views.h"
#include "render/whitted.h"
#include "render/whitted_shade.h"
#include "base/rng.h"
#include "base/vec3.h"
#include "trace/kernels.h"
#include "render/workload.h"
#include "test_util.h"

typedef struct checker {
  fr_tracer inner;
  const fr_scene *s;
  long rays, occluded_rays, disagree, frusta_rays, shadow_frusta_rays;
} checker;

/* the tracer may overwrite its rays: keep a copy to re-trace */
static fr_ray *copy_rays(const fr_ray *rays, size_t n) {
  fr_ray *copy = malloc(n * sizeof *copy);
  assert_non_null(copy);
  memcpy(copy, rays, n * sizeof *copy);
  return copy;
}

/* One closest hit against fr_intersect1's on the same ray. */
static void check_hit(checker *c, const mesh_ref *m, const fr_ray *ray, const fr_hit *got, size_t i, size_t n) {
  fr_hit h;
  fr_intersect1(c->s, ray, &h);
  if (h.prim == got->prim && (h.prim == FR_INVALID_ID || fabsf(h.t - got->t) <= 1e-4f * fmaxf(1.0f, h.t))) return;
  if (h.prim != FR_INVALID_ID && got->prim != FR_INVALID_ID && fabsf(h.t - got->t) <= 1e-4f * fmaxf(1.0f, h.t)) return;
  c->disagree++;
  if (!ambiguous(m, ray))
    fail_msg("ray %zu of a packet of %zu: packet prim %u t %g, single prim %u t %g", i, n, got->prim, got->t, h.prim, h.t);
}

static void check_intersect(void *ctx, const fr_ray *rays, fr_hit *hits, size_t n, int coherent) {
  checker *c = ctx;
  fr_ray *copy = copy_rays(rays, n);
  c->inner.intersect(c->inner.ctx, rays, hits, n, coherent);
  mesh_ref m = scene_mesh(c->s);
  for (size_t i = 0; i < n; i++, c->rays++) check_hit(c, &m, &copy[i], &hits[i], i, n);
  free(copy);
}

/* camera frusta: each ray as fr_mft_ray makes it, in its units */
static unsigned check_intersect_frusta(void *ctx, const fr_mft_batch *b, const fr_mft_sets *t, fr_mft_hits *hits) {
  checker *c = ctx;
  unsigned fetched = c->inner.intersect_frusta(c->inner.ctx, b, t, hits);
  mesh_ref m = scene_mesh(c->s);
  for (int f = 0; f < FR_MFT_FRUSTA; f++) {
    if (!((b->valid >> f) & 1)) continue;
    for (int k = 0; k < FR_MFT_RAYS; k++, c->frusta_rays++) {
      fr_ray r = {{0, 0, 0}, b->tnear[f], {0, 0, 0}, b->tfar[f]};
      fr_mft_ray(b, t, f, k, r.org, r.dir);
      fr_hit got = {hits->t[f][k], hits->u[f][k], hits->v[f][k], hits->prim[f][k], {0, 0, 0}};
      if (got.prim == FR_INVALID_ID) got.t = INFINITY;
      check_hit(c, &m, &r, &got, (size_t)k, FR_MFT_RAYS);
    }
  }
  return fetched;
}

/* shadow frusta from the light: each ray as fr_mft_ray makes it; a batch
 * stopped by its node budget answers only for the rays it found occluded */
static unsigned check_occluded_frusta(void *ctx, const fr_mft_batch *b, const fr_mft_sets *t, uint16_t occ[16],
                                      fr_mft_budget *budget, fr_mft_occluders *cache) {
  checker *c = ctx;
  unsigned fetched = c->inner.occluded_frusta(c->inner.ctx, b, t, occ, budget, cache);
  const int stopped = budget && budget->stopped;
  mesh_ref m = scene_mesh(c->s);
  for (int f = 0; f < FR_MFT_FRUSTA; f++) {
    if (!((b->valid >> f) & 1)) continue;
    for (int k = 0; k < FR_MFT_RAYS; k++) {
      fr_ray r = {{0, 0, 0}, b->tnear[f], {0, 0, 0}, b->tfar[f]};
      fr_mft_ray(b, t, f, k, r.org, r.dir);
      int got = (occ[f] >> k) & 1, single = fr_occluded1(c->s, &r);
      c->shadow_frusta_rays++;
      if (got == single || (stopped && !got)) continue;
      c->disagree++;
      if (!ambiguous(&m, &r)) fail_msg("shadow frustum %d ray %d: frusta %d, single %d", f, k, got, single);
    }
  }
  return fetched;
}

static void check_occluded(void *ctx, const fr_ray *rays, uint8_t *occ, size_t n, int coherent) {
  checker *c = ctx;
  fr_ray *copy = copy_rays(rays, n);
  c->inner.occluded(c->inner.ctx, rays, occ, n, coherent);
  mesh_ref m = scene_mesh(c->s);
  for (size_t i = 0; i < n; i++) {
    c->occluded_rays++;
    if (fr_occluded1(c->s, &copy[i]) == occ[i]) continue;
    c->disagree++;
    if (!ambiguous(&m, &copy[i])) fail_msg("shadow ray %zu of %zu: packet %d, single %d", i, n, occ[i], !occ[i]);
  }
  free(copy);
}

/* The Whitted workload on scene s with the view of name, at width x height. */
static void whitted_setup(fr_workload *w, fr_scene *s, const char *name, const fr_whitted_mats *mats, int width,
                          int height) {
  memset(w, 0, sizeof *w);
  w->kind = FR_WL_WHITTED;
  w->scene = s;
  assert_true(fr_view_lookup(name, &w->view));
  assert_int_equal(fr_camera_setup(&w->cam, w->view.eye, w->view.at, w->view.up, w->view.fov, width, height), FR_OK);
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  w->eps = 1e-4f * sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
  w->threads = 1;
  w->mats = mats;
  w->max_depth = 4;
}

/* The multi-frusta tracer: camera rays as frusta where a 16x16 block fits
 * (200x150 leaves partial blocks on two sides, traced as rays), the first
 * shadow rays as frusta from the light (with their node budget, and with
 * none: every batch), the rest as streams; everything checked ray by ray. */
static void check_whitted_mft(fr_scene *s, const char *name, const fr_whitted_mats *mats) {
  for (int no_budget = 0; no_budget < 2; no_budget++) {
    fr_workload w;
    whitted_setup(&w, s, name, mats, 200, 150);
    w.mft_no_fallback = no_budget;
    fr_mft_tracer mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
    checker c = {fr_tracer_mft(&mctx), s, 0, 0, 0, 0, 0};
    fr_tracer t = {&c, check_intersect, check_occluded, check_intersect_frusta, check_occluded_frusta, 0, NULL};
    fr_workload_result r = fr_workload_run(&w, &t);
    /* shadow frusta repeat a partial frustum's last ray, and a batch over budget goes again as rays */
    const long traced = c.rays + c.occluded_rays + c.frusta_rays;
    assert_true((long)r.rays >= traced && (long)r.rays <= traced + c.shadow_frusta_rays);
    assert_true(c.shadow_frusta_rays > 0);
    if (no_budget) assert_true((long)r.rays > traced);
    /* 12 x 9 blocks of 16x16 as frusta; the partial ones' camera rays, and the secondaries, as rays */
    assert_int_equal(c.frusta_rays, 12 * 9 * 256);
    /* the stage times: every stage ran, and (one thread) they add up to the tiles' time, within the run's */
    double staged = 0.0;
    for (int i = 0; i < FR_STAGES; i++) {
      assert_true(r.stage[i] > 0.0);
      staged += r.stage[i];
    }
    assert_true(staged <= r.seconds * 1.0001 + 1e-6 && staged >= 0.5 * r.seconds);
    assert_true(c.rays > 200 * 150 - 12 * 9 * 256 && c.occluded_rays > 0);
    print_message("%s mft%s: %ld camera rays in frusta, %ld closest-hit rays, %ld shadow rays, %ld shadow rays in "
                  "frusta, %ld disagreements (all at edges or range ends)\n", name, no_budget ? " (no budget)" : "",
                  c.frusta_rays, c.rays, c.occluded_rays, c.shadow_frusta_rays, c.disagree);
  }
}

/* Whitted on scene s (view of name) with its materials as mirror and glass
 * say (NULL: the defaults), which must give mirrors and, if want_glass, glass. */
static void check_whitted(fr_scene *s, const char *name, const char *mirror, const char *glass, int want_glass) {
  fr_whitted_mats mats;
  assert_int_equal(fr_whitted_mats_build(s, mirror, glass, &mats), FR_OK);
  size_t nm, ng;
  fr_whitted_mats_census(s, &mats, &nm, &ng);
  assert_true((nm > 0 || !mirror) && (ng > 0 || !want_glass));
  fr_workload w;
  whitted_setup(&w, s, name, &mats, 192, 144);
  static const struct { int side; fr_lp_traversal t; fr_cull c; } configs[] = {
      {2, FR_LP_MASKED, FR_CULL_CORNERS}, {4, FR_LP_PARTITION, FR_CULL_PLANES}, {8, FR_LP_RANGED, FR_CULL_IA},
      {16, FR_LP_RANGED, FR_CULL_OFF},    {16, FR_LP_PARTITION, FR_CULL_CORNERS}, {32, FR_LP_MASKED, FR_CULL_CORNERS}};
  for (size_t k = 0; k < sizeof configs / sizeof configs[0]; k++) {
    fr_lp_tracer lpc = {s, {&s->bvh2, &s->sphere_bvh, fr_scene_sphere_base(s)}, {configs[k].t, configs[k].c}, configs[k].side};
    checker c = {fr_tracer_lp(&lpc), s, 0, 0, 0, 0, 0};
    fr_tracer t = {&c, check_intersect, check_occluded, NULL, NULL, configs[k].side, NULL};
    fr_workload_result r = fr_workload_run(&w, &t);
    assert_int_equal(r.rays, (uint64_t)(c.rays + c.occluded_rays));
    /* secondary rays: more closest-hit rays than pixels, and shadow rays */
    assert_true(c.rays > 192 * 144 && c.occluded_rays > 0);
    print_message("%s %dx%d %s/%s: %ld closest-hit rays, %ld shadow rays, %ld disagreements (all at edges or range ends)\n",
                  name, configs[k].side, configs[k].side, fr_lp_traversal_name(configs[k].t), fr_cull_name(configs[k].c),
                  c.rays, c.occluded_rays, c.disagree);
  }
  if (!fr_scene_sphere_count(s)) check_whitted_mft(s, name, &mats);
  fr_whitted_mats_free(&mats);
}

static void check_scene(const char *name) {
  char rel[256], path[1024];
  snprintf(rel, sizeof rel, "%s/%s.obj.zst", name, name);
  shared_scene_path(path, sizeof path, rel);
  fr_scene *s;
  if (fr_scene_load(path, &s) != FR_OK) fail_msg("%s", fr_last_error());
  assert_int_equal(fr_scene_commit(s), FR_OK);
  check_whitted(s, name, NULL, NULL, 1);
  fr_scene_release(s);
}

static void test_kitchen(void **state) { (void)state; check_scene("kitchen"); }
static void test_museum(void **state) { (void)state; check_scene("museum"); }

/* Analytic spheres: the sphereflake as mirrors, then as glass. */
static void test_sphereflake(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin_sphereflake(3, &s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  check_whitted(s, "sphereflake", "flake", NULL, 0);
  check_whitted(s, "sphereflake", NULL, "flake", 1);
  fr_scene_release(s);
}

/* Material lists: unknown names are errors, "all" mirrors everything. */
static void test_materials(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  fr_whitted_mats m;
  assert_int_equal(fr_whitted_mats_build(s, "no_such_material", NULL, &m), FR_ERR_ARG);
  assert_non_null(strstr(fr_last_error(), "no_such_material"));
  assert_int_equal(fr_whitted_mats_build(s, NULL, "all", &m), FR_ERR_ARG);
  assert_int_equal(fr_whitted_mats_build(s, "all", NULL, &m), FR_OK);
  size_t nm, ng;
  fr_whitted_mats_census(s, &m, &nm, &ng);
  assert_int_equal(nm, fr_scene_triangle_count(s));
  assert_int_equal(ng, 0);
  fr_whitted_mats_free(&m);
  fr_scene_release(s);
}


/* ---- the shading kernel against the formulas, ray by ray ---------------------- */

static float ref_fresnel(float cosi, float eta, float *cost_out) {
  float k = 1.0f - eta * eta * (1.0f - cosi * cosi);
  if (k <= 0.0f) { *cost_out = 0.0f; return 1.0f; } /* total internal reflection */
  float cost = sqrtf(k);
  float rs = (eta * cosi - cost) / (eta * cosi + cost), rp = (eta * cost - cosi) / (eta * cost + cosi);
  *cost_out = cost;
  return 0.5f * (rs * rs + rp * rp);
}
static float ref_max3(vec3 a) { return fr_maxf(a.x, fr_maxf(a.y, a.z)); }

typedef struct ref_lane {
  vec3 add, p, l, lw, rd, rw, td, tw;
  float ldist;
  int shadow, refl, refr;
} ref_lane;

/* One hit, as the renderer shaded it before the kernel (one branch per case). */
static ref_lane ref_shade(const fr_wshade_in *in, const fr_whitted_mats *mats, int lane) {
  ref_lane o;
  memset(&o, 0, sizeof o);
  const fr_ray *g = &in->ray[lane];
  vec3 w = v3_load(in->path[lane].w);
  if (!((in->hits >> lane) & 1)) { o.add = v3_scale(w, FR_WHITTED_BACKGROUND); return o; }
  const fr_whitted_mat *m = &mats->mat[in->surf[lane].mat];
  vec3 d = v3_load(g->dir), p = v3_add(v3_load(g->org), v3_scale(d, in->hit[lane].t));
  vec3 ng = v3_norm(v3_load(in->surf[lane].ng));
  int entering = v3_dot(ng, d) < 0.0f;
  vec3 nf = entering ? ng : v3_scale(ng, -1.0f);
  vec3 kd = v3_load(m->kd), ks = v3_load(m->ks);
  o.add = v3_mul(w, v3_scale(kd, FR_WHITTED_AMBIENT));
  o.p = p;
  vec3 to = v3_sub(v3_load(in->light), p);
  float dist = v3_len(to);
  vec3 l = v3_scale(to, 1.0f / dist);
  float ndl = v3_dot(nf, l);
  if (ndl > 0.0f && dist > 0.0f && (ref_max3(kd) > 0.0f || (m->kind == FR_SURF_DIFFUSE && ref_max3(ks) > 0.0f))) {
    vec3 lit = v3_scale(kd, ndl);
    if (m->kind == FR_SURF_DIFFUSE && m->ns > 0.0f && ref_max3(ks) > 0.0f) {
      vec3 r = v3_sub(v3_scale(nf, 2.0f * ndl), l);
      float rv = -v3_dot(r, d);
      if (rv > 0.0f) lit = v3_add(lit, v3_scale(ks, powf(rv, m->ns)));
    }
    o.shadow = 1; o.l = l; o.ldist = dist; o.lw = v3_mul(w, lit);
  }
  if (!in->bounce || m->kind == FR_SURF_DIFFUSE) return o;
  float cosi = -v3_dot(d, nf);
  vec3 refl = v3_add(d, v3_scale(nf, 2.0f * cosi));
  vec3 wr = v3_mul(w, ks), wt = v3(0, 0, 0), tdir = v3(0, 0, 0);
  if (m->kind == FR_SURF_GLASS) {
    float eta = entering ? 1.0f / m->ior : m->ior, cost;
    float F = ref_fresnel(cosi, eta, &cost);
    wr = v3_scale(w, F);
    wt = v3_scale(v3_mul(w, v3_load(m->kt)), 1.0f - F);
    tdir = v3_add(v3_scale(d, eta), v3_scale(nf, eta * cosi - cost));
  }
  if (ref_max3(wr) > FR_WHITTED_MIN_WEIGHT) { o.refl = 1; o.rd = refl; o.rw = wr; }
  if (ref_max3(wt) > FR_WHITTED_MIN_WEIGHT) { o.refr = 1; o.td = v3_norm(tdir); o.tw = wt; }
  return o;
}

static int same3(vec3 a, const float (*v)[FR_WS_LANES], int l) {
  float b[3] = {v[0][l], v[1][l], v[2][l]};
  return !memcmp(&a, b, sizeof b);
}

static int same_ray(const fr_ray *a, const fr_ray *b) { return !memcmp(a, b, sizeof *a); }
static int same_path(const fr_wpath *a, const fr_wpath *b) {
  return !memcmp(a->w, b->w, sizeof a->w) && a->pix == b->pix && a->key == b->key;
}

/* fr_whitted_emit16 of one level writes, in lane order, the rays the
 * formulas spawn: shadow rays from the light, then reflections, then
 * refractions, each carrying its weight, pixel and packet key. */
static void check_emit(const fr_wshade_in *in, const fr_whitted_mats *mats, const fr_wshade_out *out, int isa) {
  const float eps = 1e-3f;
  fr_ray sr[FR_WS_LANES], nr[2 * FR_WS_LANES];
  fr_wpath sp[FR_WS_LANES], np[2 * FR_WS_LANES];
  fr_wsink shadow = {sr, sp, 0}, next = {nr, np, 0};
  if (isa == FR_ISA_AVX512) fr_whitted_emit16_avx512(out, in->light, eps, &shadow, &next);
  else if (isa == FR_ISA_AVX2) fr_whitted_emit16_avx2(out, in->light, eps, &shadow, &next);
  else fr_whitted_emit16_scalar(out, in->light, eps, &shadow, &next);
  size_t ns = 0, nn = 0;
  for (int kind = 0; kind < 3; kind++)
    for (int l = 0; l < FR_WS_LANES; l++) {
      if (!((in->valid >> l) & 1)) continue;
      ref_lane r = ref_shade(in, mats, l);
      const fr_wpath *g = &in->path[l];
      fr_ray want;
      fr_wpath carry;
      if (kind == 0) {
        if (!r.shadow) continue;
        want = (fr_ray){{in->light[0], in->light[1], in->light[2]}, r.ldist * 1e-4f, {-r.l.x, -r.l.y, -r.l.z},
                        r.ldist - eps};
        carry = (fr_wpath){{r.lw.x, r.lw.y, r.lw.z}, g->pix, (uint16_t)(g->key / 2)};
        assert_true(ns < shadow.n && same_ray(&sr[ns], &want) && same_path(&sp[ns], &carry));
        ns++;
        continue;
      }
      if (kind == 1 ? !r.refl : !r.refr) continue;
      vec3 dir = kind == 1 ? r.rd : r.td, wt = kind == 1 ? r.rw : r.tw;
      want = (fr_ray){{r.p.x, r.p.y, r.p.z}, eps, {dir.x, dir.y, dir.z}, INFINITY};
      carry = (fr_wpath){{wt.x, wt.y, wt.z}, g->pix, (uint16_t)(kind == 1 ? g->key & ~1u : g->key | 1u)};
      assert_true(nn < next.n && same_ray(&nr[nn], &want) && same_path(&np[nn], &carry));
      nn++;
    }
  assert_int_equal(ns, shadow.n);
  assert_int_equal(nn, next.n);
}

/* Random hits (misses, zero normals, grazing and back-facing ones, total
 * internal reflection) on materials of every kind, in partial groups too. */
static void test_shade_kernel(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  fr_whitted_mats mats;
  assert_int_equal(fr_whitted_mats_build(s, NULL, NULL, &mats), FR_OK);
  /* a material table of our own: diffuse, Phong, mirror, two glasses, black */
  static const fr_whitted_mat table[] = {
      {FR_SURF_DIFFUSE, {0.7f, 0.6f, 0.5f}, {0, 0, 0}, 0, {0, 0, 0}, 1.5f},
      {FR_SURF_DIFFUSE, {0.2f, 0.3f, 0.4f}, {0.5f, 0.5f, 0.5f}, 20.0f, {0, 0, 0}, 1.5f},
      {FR_SURF_MIRROR, {0, 0, 0}, {0.9f, 0.8f, 0.9f}, 0, {0, 0, 0}, 1.5f},
      {FR_SURF_GLASS, {0, 0, 0}, {0, 0, 0}, 0, {0.9f, 0.9f, 0.9f}, 1.5f},
      {FR_SURF_GLASS, {0.1f, 0, 0}, {0, 0, 0}, 0, {0.5f, 0.9f, 0.7f}, 2.4f},
      {FR_SURF_DIFFUSE, {0, 0, 0}, {0, 0, 0}, 0, {0, 0, 0}, 1.5f},
  };
  fr_whitted_mats_free(&mats);
  mats.count = sizeof table / sizeof table[0];
  mats.mat = malloc(sizeof table);
  memcpy(mats.mat, table, sizeof table);
  /* the table the renderer builds, from these */
  mats.soa = malloc(FR_WM_FIELDS * mats.count * sizeof(float));
  fr_whitted_mats_soa(&mats);
  fr_rng rng = fr_rng_seed(7, 11);
  long lanes_checked = 0, counts[3] = {0, 0, 0};
  for (int trial = 0; trial < 4000; trial++) {
    fr_ray rays[FR_WS_LANES];
    fr_wpath path[FR_WS_LANES];
    fr_hit hits[FR_WS_LANES];
    fr_surface surf[FR_WS_LANES];
    int n = 1 + (int)(fr_rng_u32(&rng) % FR_WS_LANES);
    /* lanes past n hold NaNs: the kernel must not let them in */
    memset(rays, 0xFF, sizeof rays);
    memset(path, 0xFF, sizeof path);
    memset(surf, 0xFF, sizeof surf);
    fr_wshade_in in = {rays, path, hits, surf, (1u << n) - 1u, 0, mats.soa, mats.count, {0, 0, 0}, trial % 4 != 0};
    for (int a = 0; a < 3; a++) in.light[a] = 4.0f * fr_rng_float(&rng) - 2.0f;
    /* every third group shares one material (the kernel's broadcast path) */
    const int32_t shared_mat = trial % 3 == 0 ? (int32_t)(fr_rng_u32(&rng) % mats.count) : -1;
    for (int l = 0; l < n; l++) {
      vec3 d = v3_norm(v3(2 * fr_rng_float(&rng) - 1, 2 * fr_rng_float(&rng) - 1, 2 * fr_rng_float(&rng) - 1));
      rays[l] = (fr_ray){{fr_rng_float(&rng), fr_rng_float(&rng), fr_rng_float(&rng)}, 0, {d.x, d.y, d.z}, INFINITY};
      path[l] = (fr_wpath){{fr_rng_float(&rng), fr_rng_float(&rng), fr_rng_float(&rng)}, (uint16_t)(l * 37),
                           (uint16_t)(fr_rng_u32(&rng) % 2048)};
      hits[l].t = 3.0f * fr_rng_float(&rng);
      hits[l].prim = fr_rng_u32(&rng) % 5 ? (uint32_t)l : FR_INVALID_ID;
      in.hits |= (unsigned)(hits[l].prim != FR_INVALID_ID) << l;
      surf[l].mat = shared_mat >= 0 ? shared_mat : (int32_t)(fr_rng_u32(&rng) % mats.count);
      for (int a = 0; a < 3; a++) surf[l].ng[a] = 2 * fr_rng_float(&rng) - 1;
      if (fr_rng_u32(&rng) % 50 == 0) surf[l].ng[0] = surf[l].ng[1] = surf[l].ng[2] = 0.0f;
    }
    for (int isa = 0; isa < 3; isa++) {
      if (!fr_isa_supported((fr_isa)isa)) continue;
      fr_wshade_out out;
      memset(&out, 0, sizeof out);
      if (isa == FR_ISA_AVX512) fr_whitted_shade16_avx512(&in, &out);
      else if (isa == FR_ISA_AVX2) fr_whitted_shade16_avx2(&in, &out);
      else fr_whitted_shade16_scalar(&in, &out);
      for (int l = 0; l < n; l++) {
        ref_lane r = ref_shade(&in, &mats, l);
        assert_true(same3(r.add, out.add, l));
        assert_int_equal(r.shadow, (out.shadow >> l) & 1);
        assert_int_equal(r.refl, (out.refl >> l) & 1);
        assert_int_equal(r.refr, (out.refr >> l) & 1);
        if (r.shadow || r.refl || r.refr) assert_true(same3(r.p, out.p, l));
        if (r.shadow) {
          assert_true(same3(r.l, out.l, l) && same3(r.lw, out.lw, l));
          assert_memory_equal(&r.ldist, &out.ldist[l], sizeof(float));
        }
        if (r.refl) assert_true(same3(r.rd, out.rd, l) && same3(r.rw, out.rw, l));
        if (r.refr) assert_true(same3(r.td, out.td, l) && same3(r.tw, out.tw, l));
        counts[0] += r.shadow; counts[1] += r.refl; counts[2] += r.refr;
        lanes_checked++;
      }
      check_emit(&in, &mats, &out, isa);
    }
  }
  /* every kind of output really came up */
  assert_true(counts[0] > 1000 && counts[1] > 1000 && counts[2] > 1000);
  print_message("shading kernel: %ld lanes bit-identical to the formulas, their new rays too (%ld shadow, %ld reflection, %ld refraction rays)\n",
                lanes_checked, counts[0], counts[1], counts[2]);
  fr_whitted_mats_free(&mats);
  fr_scene_release(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_materials),
      cmocka_unit_test(test_shade_kernel),
      cmocka_unit_test(test_kitchen),
      cmocka_unit_test(test_museum),
      cmocka_unit_test(test_sphereflake),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
