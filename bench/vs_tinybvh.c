/*
 * frusta's single rays against tinybvh's BVH8_CPU (bench/tinybvh_side.cpp)
 * on identical rays, 2 threads: camera rays of the scene's view
 * (1024x1024 in 4x4 pixel blocks), shadow rays from their hits to the
 * scene's point light, ambient-occlusion rays (one cosine-weighted
 * direction about each hit's normal, any hit, unbounded) and diffuse
 * bounces (the same directions, closest hit). Each tracer gets the rays as
 * origin, unit direction and tfar (tnear 0: secondary rays start eps off
 * the surface); frusta in its single mode through its stream calls, both
 * on every thread in chunks; the best of REPEAT alternating runs. Prints
 * one line per ray kind with both rates and how many answers differ
 * (closest: t by more than 1e-4 relative; any: the verdict).
 * tinybvh's BVH is its high-quality build, or with OPTIMIZE > 0 its quick
 * build refined by that many rounds of its optimizer.
 * For the comparison only (bench/vs_tinybvh.sh builds it).
 *   usage: vs_tinybvh SCENE [REPEAT [OPTIMIZE]]
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "frusta.h"
#include "base/rng.h"
#include "base/timer.h"
#include "render/camera.h"
#include "render/views.h"

void *tbs_build(const float *xyz, const uint32_t *idx, size_t nt, int optimize);
void tbs_release(void *b);
void tbs_intersect(const void *bvh, const float *rays, size_t n, float *t, uint32_t *prim, int threads);
void tbs_occluded(const void *bvh, const float *rays, size_t n, uint8_t *occ, int threads);

enum { W = 1024, H = 1024, THREADS = 2, CHUNK = 4096 };

static void frusta_closest(const fr_scene *s, const fr_ray *r, fr_hit *h, size_t n) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(THREADS)
  for (size_t c = 0; c < n; c += CHUNK) fr_intersect_stream(s, r + c, h + c, n - c < CHUNK ? n - c : CHUNK);
}
static void frusta_any(const fr_scene *s, const fr_ray *r, uint8_t *o, size_t n) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(THREADS)
  for (size_t c = 0; c < n; c += CHUNK) fr_occluded_stream(s, r + c, o + c, n - c < CHUNK ? n - c : CHUNK);
}

static void pack(const fr_ray *r, size_t n, float *out) {
  for (size_t i = 0; i < n; i++) {
    memcpy(out + 7 * i, r[i].org, 3 * sizeof(float));
    memcpy(out + 7 * i + 3, r[i].dir, 3 * sizeof(float));
    out[7 * i + 6] = r[i].tfar;
  }
}

/* Times both tracers on the rays, best of repeat, and compares answers. */
static void measure(const char *scene, const char *build, const char *kind, const fr_scene *s, const void *tb, const fr_ray *rays, size_t n,
                    int any, int repeat) {
  float *packed = malloc(n * 7 * sizeof(float)), *tt = malloc(n * sizeof(float));
  uint32_t *tp = malloc(n * sizeof(uint32_t));
  fr_hit *fh = malloc(n * sizeof(fr_hit));
  uint8_t *fo = malloc(n), *to = malloc(n);
  if (!packed || !tt || !tp || !fh || !fo || !to) { fprintf(stderr, "out of memory\n"); exit(1); }
  pack(rays, n, packed);
  double bf = 1e30, bt = 1e30;
  for (int k = 0; k < repeat; k++) {
    double t0 = fr_seconds();
    if (any) frusta_any(s, rays, fo, n);
    else frusta_closest(s, rays, fh, n);
    double t1 = fr_seconds();
    if (any) tbs_occluded(tb, packed, n, to, THREADS);
    else tbs_intersect(tb, packed, n, tt, tp, THREADS);
    double t2 = fr_seconds();
    if (t1 - t0 < bf) bf = t1 - t0;
    if (t2 - t1 < bt) bt = t2 - t1;
  }
  size_t differ = 0;
  for (size_t i = 0; i < n; i++) {
    if (any) differ += fo[i] != to[i];
    else if (isinf(fh[i].t) != isinf(tt[i])) differ++;
    else if (!isinf(tt[i]) && fabsf(fh[i].t - tt[i]) > 1e-4f * tt[i]) differ++;
  }
  printf("scene=%s build=%s rays=%s n=%zu frusta_single_mrays=%.2f tinybvh_bvh8_mrays=%.2f ratio=%.3f differ=%zu\n", scene,
         build, kind, n, n / bf * 1e-6, n / bt * 1e-6, bt / bf, differ);
  fflush(stdout);
  free(packed), free(tt), free(tp), free(fh), free(fo), free(to);
}

static fr_ray ray_of(vec3 o, vec3 d, float tfar) {
  fr_ray r = {{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, tfar};
  return r;
}

int main(int argc, char **argv) {
  if (argc < 2) { fprintf(stderr, "usage: vs_tinybvh SCENE [REPEAT [OPTIMIZE]]\n"); return 2; }
  const int repeat = argc > 2 ? atoi(argv[2]) : 5, optimize = argc > 3 ? atoi(argv[3]) : 0;
  fr_scene *s;
  if (fr_scene_load(argv[1], &s) || fr_scene_commit(s)) { fprintf(stderr, "%s\n", fr_last_error()); return 1; }
  const char *slash = strrchr(argv[1], '/'), *base = slash ? slash + 1 : argv[1];
  char name[256];
  snprintf(name, sizeof name, "%.*s", (int)strcspn(base, "."), base);
  fr_view v;
  if (!fr_view_lookup(name, &v)) { fprintf(stderr, "%s: no view\n", name); return 1; }
  double t0 = fr_seconds();
  void *tb = tbs_build(fr_scene_vertices(s), fr_scene_indices(s), fr_scene_triangle_count(s), optimize);
  const char *build = optimize > 0 ? "optimized" : "hq";
  printf("scene=%s tris=%zu tinybvh_build=%s tinybvh_build_seconds=%.2f\n", name, fr_scene_triangle_count(s), build,
         fr_seconds() - t0);
  fr_scene_set_trace_mode(s, FR_TRACE_SINGLE);
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  const float eps = 1e-4f * sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                  (hi[2] - lo[2]) * (hi[2] - lo[2]));
  /* camera rays, 4x4 pixel blocks in rows of blocks */
  const size_t np = (size_t)W * H;
  fr_ray *cam = malloc(np * sizeof(fr_ray)), *sec = malloc(3 * np * sizeof(fr_ray));
  fr_hit *hits = malloc(np * sizeof(fr_hit));
  if (!cam || !sec || !hits) return 1;
  fr_camera c;
  if (fr_camera_setup(&c, v.eye, v.at, v.up, v.fov, W, H)) { fprintf(stderr, "%s\n", fr_last_error()); return 1; }
  size_t n = 0;
  for (int by = 0; by < H; by += 4)
    for (int bx = 0; bx < W; bx += 4)
      for (int k = 0; k < 16; k++) cam[n++] = fr_camera_ray(&c, bx + k % 4, by + k / 4);
  measure(name, build, "camera", s, tb, cam, np, 0, repeat);
  frusta_closest(s, cam, hits, np);
  /* from each hit: a shadow ray to the light, an ao ray and a diffuse bounce (one direction for both) */
  fr_rng rng = fr_rng_seed(7, 1);
  size_t ns = 0, nh = 0;
  fr_ray *shadow = sec, *ao = sec + np, *bounce = sec + 2 * np;
  for (size_t i = 0; i < np; i++) {
    if (hits[i].prim == FR_INVALID_ID) continue;
    const vec3 d = v3_load(cam[i].dir), p = v3_add(v3_load(cam[i].org), v3_scale(d, hits[i].t));
    vec3 ng = v3_norm(v3_load(hits[i].ng));
    if (v3_dot(ng, d) > 0.0f) ng = v3_scale(ng, -1.0f);
    const vec3 o = v3_add(p, v3_scale(ng, eps));
    const vec3 to = v3_sub(v.light, o);
    const float dist = v3_len(to);
    if (dist > 0.0f) shadow[ns++] = ray_of(o, v3_scale(to, 1.0f / dist), dist * (1.0f - 1e-4f));
    vec3 t, b;
    v3_onb(ng, &t, &b);
    const float u1 = fr_rng_float(&rng), u2 = fr_rng_float(&rng), r = sqrtf(u1), phi = 6.2831853f * u2;
    const vec3 w = v3_norm(v3_add(v3_add(v3_scale(t, r * cosf(phi)), v3_scale(b, r * sinf(phi))),
                                  v3_scale(ng, sqrtf(fmaxf(0.0f, 1.0f - u1)))));
    ao[nh] = bounce[nh] = ray_of(o, w, INFINITY);
    nh++;
  }
  measure(name, build, "shadow", s, tb, shadow, ns, 1, repeat);
  measure(name, build, "ao", s, tb, ao, nh, 1, repeat);
  measure(name, build, "diffuse", s, tb, bounce, nh, 0, repeat);
  tbs_release(tb);
  free(cam), free(sec), free(hits);
  fr_scene_release(s);
  return 0;
}
