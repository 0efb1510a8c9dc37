/*
 * One tile of the primary, shadow, soft16, ao16, diffuse8 and specular8
 * workloads: camera rays (as frusta where the tracer has them), the
 * workload's secondary rays, and the shading of the render modes.
 */
#include "render/tile.h"
#include "base/rng.h"
#include "base/trig.h"
#include "render/mft_rays.h"
#include "render/shadow_frusta.h"

unsigned fr_camera_frusta(const fr_workload *w, const fr_tracer *t, int tx, int ty, fr_ray *rays, fr_hit *hits) {
  fr_mft_batch b;
  static _Thread_local fr_mft_hits h;
  const fr_mft_sets *cam_set = w->camera_set;
  fr_mft_batch_camera(&b, &w->cam, tx, ty);
  const unsigned fetched = t->intersect_frusta(t->ctx, &b, cam_set, &h);
  fr_mft_active()->expand(&b, cam_set, &h, rays, hits);
  return fetched;
}

/* Making a workload's rays is timed with either tracer, so it does only what
 * the rays need. */

/* The camera rays' hit points, the k-th at x[k * stride], y[k * stride]
 * and z[k * stride], its pixel in B->owner[k]; returns how many. */
static int hit_points(fr_tile_buffers *B, int n, float *x, float *y, float *z, int stride) {
  int m = 0;
  for (int i = 0; i < n; i++) {
    const fr_hit *h = &B->prim_hit[i];
    if (h->prim == FR_INVALID_ID) continue;
    const vec3 p = hit_point(&B->prim_ray[i], h);
    const size_t at = (size_t)m * (size_t)stride;
    x[at] = p.x; y[at] = p.y; z[at] = p.z;
    B->owner[m++] = i;
  }
  return m;
}

/* shadow: each hit's ray to the point light, [eps, (1 - 1e-4) |L - p|],
 * made without the normal and random numbers it does not use */
static int point_light_rays(const fr_workload *w, fr_tile_buffers *B, int n) {
  float px[TILE_PIX], py[TILE_PIX], pz[TILE_PIX], inv[TILE_PIX], dist[TILE_PIX];
  const int m = hit_points(B, n, px, py, pz, 1);
  const vec3 L = w->view.light;
  for (int k = 0; k < m; k++) { /* one loop of square roots and divisions, vectorized */
    float dx = L.x - px[k], dy = L.y - py[k], dz = L.z - pz[k];
    dist[k] = sqrtf(dx * dx + dy * dy + dz * dz);
    inv[k] = 1.0f / dist[k];
  }
  for (int k = 0; k < m; k++) {
    fr_ray *r = &B->rays[k];
    r->org[0] = px[k]; r->org[1] = py[k]; r->org[2] = pz[k];
    r->dir[0] = (L.x - px[k]) * inv[k]; r->dir[1] = (L.y - py[k]) * inv[k]; r->dir[2] = (L.z - pz[k]) * inv[k];
    r->tnear = w->eps;
    r->tfar = dist[k] * (1.0f - 1e-4f);
  }
  return m;
}

/* ao16: 16 cosine-weighted directions about each hit's normal, unbounded;
 * each pixel's 16 made in one loop the compiler vectorizes */
static int ao_rays(const fr_workload *w, fr_tile_buffers *B, int n) {
  const int W = w->cam.width;
  int m = 0;
  for (int i = 0; i < n; i++) {
    const fr_hit *h = &B->prim_hit[i];
    if (h->prim == FR_INVALID_ID) continue;
    const vec3 p = hit_point(&B->prim_ray[i], h), nn = facing_normal(w->scene, h, &B->prim_ray[i]);
    vec3 tu, tv;
    v3_onb(nn, &tu, &tv);
    fr_rng rng = fr_rng_seed(w->seed, (uint64_t)B->py[i] * (uint64_t)W + (uint64_t)B->px[i]);
    float u1[16], u2[16], dx[16], dy[16], dz[16];
    for (int k = 0; k < 16; k++) u1[k] = fr_rng_float(&rng), u2[k] = fr_rng_float(&rng);
    for (int k = 0; k < 16; k++) {
      float sn, cs;
      fr_sincos_turns(u2[k], &sn, &cs);
      const float r = sqrtf(u1[k]), one = 1.0f - u1[k], z = sqrtf(one > 0.0f ? one : 0.0f);
      const float x = r * cs, y = r * sn;
      dx[k] = tu.x * x + tv.x * y + nn.x * z;
      dy[k] = tu.y * x + tv.y * y + nn.y * z;
      dz[k] = tu.z * x + tv.z * y + nn.z * z;
    }
    for (int k = 0; k < 16; k++) {
      B->rays[m] = make_ray(p, v3(dx[k], dy[k], dz[k]), w->eps, INFINITY);
      B->owner[m++] = i;
    }
  }
  return m;
}

/* A tile's point-light shadow rays go as multi-frusta from the light where
 * its camera frusta fetched at most POINT_FRUSTA_MAX_TRIS triangles per
 * frustum of 4x4 pixels: segments that end among few triangles pass few on
 * the way, and frusta from the light beat packets from the points there
 * (the interiors). Over fine geometry (dragon, hairball: over 100 per
 * frustum) every batch would spend its node budget before going to rays. */
#define POINT_FRUSTA_MAX_TRIS 8u

/* shadow by frusta: each hit's segment to the light traced from the light's
 * end (render/shadow_frusta.h), the segment of point_light_rays' ray: eps
 * left out at the point, 1e-4 of the length at the light. Returns the
 * segments traced, their pixels in B->owner. */
static int point_light_frusta(const fr_workload *w, const fr_tracer *t, fr_tile_buffers *B, int n) {
  float points[3 * TILE_PIX];
  const int m = hit_points(B, n, points, points + 1, points + 2, 3);
  const float light[3] = {w->view.light.x, w->view.light.y, w->view.light.z};
  const fr_shadow_rays src = {NULL, light, points, w->eps};
  fr_shadow_frusta_occluded(t, &src, B->occ, (size_t)m, !w->mft_no_fallback);
  return m;
}

/* shadow and ao16: the rays traced as one call; lit[i] gets pixel i's
 * unoccluded fraction. fetched: the triangles the tile's camera frusta
 * fetched, or -1 where its camera rays went as rays. Returns the rays
 * traced. */
static uint64_t point_or_ao_rays(const fr_workload *w, const fr_tracer *t, fr_tile_buffers *B, int n, long fetched,
                                 float *lit) {
  const int per = w->kind == FR_WL_SHADOW ? 1 : 16;
  /* point-light shadows whose tile's camera frusta told how fine its geometry is */
  const int judged = w->kind == FR_WL_SHADOW && t->occluded_frusta && fetched >= 0;
  const int frusta = judged && (w->mft_no_fallback || fetched <= (long)(POINT_FRUSTA_MAX_TRIS * FR_MFT_FRUSTA));
  /* over fine geometry the shadow rays part ways at the scale of the triangles */
  const int divergent = judged && !frusta;
  int m;
  if (frusta) {
    m = point_light_frusta(w, t, B, n);
  } else {
    m = w->kind == FR_WL_SHADOW ? point_light_rays(w, B, n) : ao_rays(w, B, n);
    t->occluded(t->ctx, B->rays, B->occ, (size_t)m, divergent ? FR_RAYS_DIVERGENT : 0);
  }
  /* each pixel's rays are consecutive: summed per pixel, not counted ray by
   * ray into its pixel (a chain through memory); a shadow ray is its
   * pixel's verdict (the loop of a sum of `per` compiled for any per took a
   * tenth of a tile's own time) */
  int cnt[TILE_PIX] = {0};
  if (per == 1) {
    for (int k = 0; k < m; k++) cnt[B->owner[k]] = !B->occ[k];
  } else {
    for (int k = 0; k < m; k += 16) {
      int c = 0;
      for (int j = 0; j < 16; j++) c += !B->occ[k + j];
      cnt[B->owner[k]] = c;
    }
  }
  for (int i = 0; i < n; i++) lit[i] = (float)cnt[i] / (float)per;
  return (uint64_t)m;
}

/* diffuse8 and specular8: up to 8 bounces from each hit, the live paths
 * traced together at each bounce; a path ends at its first miss. Returns
 * the rays traced. */
static uint64_t bounce_rays(const fr_workload *w, const fr_tracer *t, fr_tile_buffers *B, int n) {
  const int W = w->cam.width;
  uint64_t rays = 0;
  fr_rng rng[TILE_PIX];
  fr_ray cur[TILE_PIX];
  fr_hit ch[TILE_PIX];
  int alive[TILE_PIX], na = 0;
  for (int i = 0; i < n; i++)
    if (B->prim_hit[i].prim != FR_INVALID_ID) {
      alive[na++] = i;
      cur[i] = B->prim_ray[i];
      ch[i] = B->prim_hit[i];
      rng[i] = fr_rng_seed(w->seed, (uint64_t)B->py[i] * (uint64_t)W + (uint64_t)B->px[i]);
    }
  for (int bounce = 0; bounce < 8 && na > 0; bounce++) {
    for (int a = 0; a < na; a++) {
      int i = alive[a];
      vec3 d = v3_load(cur[i].dir), p = hit_point(&cur[i], &ch[i]), nn = facing_normal(w->scene, &ch[i], &cur[i]);
      vec3 nd = w->kind == FR_WL_DIFFUSE8 ? cosine_dir(nn, fr_rng_float(&rng[i]), fr_rng_float(&rng[i]))
                                          : v3_sub(d, v3_scale(nn, 2.0f * v3_dot(d, nn)));
      cur[i] = make_ray(p, nd, w->eps, INFINITY);
      B->rays[a] = cur[i]; /* the tracer may overwrite its copy */
    }
    rays += (uint64_t)na;
    t->intersect(t->ctx, B->rays, B->hits, (size_t)na, 0);
    int nn2 = 0;
    for (int a = 0; a < na; a++) {
      int i = alive[a];
      if (B->hits[a].prim == FR_INVALID_ID) continue;
      ch[i] = B->hits[a];
      alive[nn2++] = i;
    }
    na = nn2;
  }
  return rays;
}

/* The soft-shadow filter's inputs: per pixel light visibility, primary hit
 * distance (+inf on a miss), unit normal facing the camera and albedo. */
static void write_gbuffer(const fr_workload *w, const fr_tile_buffers *B, int n, const float *lit) {
  const int W = w->cam.width;
  for (int i = 0; i < n; i++) {
    size_t px = (size_t)B->py[i] * (size_t)W + (size_t)B->px[i];
    const fr_hit *h = &B->prim_hit[i];
    vec3 nn = v3(0, 0, 0);
    if (h->prim != FR_INVALID_ID) nn = facing_normal(w->scene, h, &B->prim_ray[i]);
    w->gbuf_vis[px] = h->prim == FR_INVALID_ID ? 0.0f : lit[i];
    w->gbuf_depth[px] = h->prim == FR_INVALID_ID ? INFINITY : h->t;
    w->gbuf_normal[3 * px] = nn.x; w->gbuf_normal[3 * px + 1] = nn.y; w->gbuf_normal[3 * px + 2] = nn.z;
    vec3 al = h->prim == FR_INVALID_ID ? v3(0, 0, 0) : albedo(w->scene, h->prim);
    w->gbuf_albedo[3 * px] = al.x; w->gbuf_albedo[3 * px + 1] = al.y; w->gbuf_albedo[3 * px + 2] = al.z;
  }
}

/* The shaded pixels of the render modes. */
static void shade_pixels(const fr_workload *w, const fr_tile_buffers *B, int n, const float *lit) {
  const int W = w->cam.width;
  for (int i = 0; i < n; i++) {
    float *px = w->image + 3 * ((size_t)B->py[i] * (size_t)W + (size_t)B->px[i]);
    const fr_hit *h = &B->prim_hit[i];
    if (h->prim == FR_INVALID_ID) { px[0] = px[1] = px[2] = 0.05f; continue; }
    vec3 d = v3_load(B->prim_ray[i].dir), c;
    const vec3 nn = shading_normal(w->scene, h, d, facing_normal(w->scene, h, &B->prim_ray[i]));
    float cosv = fabsf(v3_dot(nn, v3_norm(d)));
    if (w->shade == FR_SHADE_NORMALS) {
      c = v3_scale(v3_add(nn, v3(1, 1, 1)), 0.5f);
    } else if (w->shade == FR_SHADE_LIGHT && w->kind == FR_WL_SHADOW) {
      vec3 p = hit_point(&B->prim_ray[i], h), L = v3_norm(v3_sub(w->view.light, p));
      c = v3_scale(albedo(w->scene, h->prim), 0.15f * cosv + 0.85f * lit[i] * fmaxf(0.0f, v3_dot(nn, L)));
    } else if (w->shade == FR_SHADE_LIGHT) {
      c = v3_scale(albedo(w->scene, h->prim), lit[i] * (0.25f + 0.75f * cosv));
    } else {
      c = v3_scale(albedo(w->scene, h->prim), cosv);
    }
    px[0] = c.x; px[1] = c.y; px[2] = c.z;
  }
}

/* One tile: returns rays traced; writes shaded pixels when w->image is set. */
uint64_t fr_tile_run(const fr_workload *w, const fr_tracer *t, fr_tile_buffers *B, int tx, int ty) {
  const int W = w->cam.width, H = w->cam.height;
  int n = 0;
  /* a full tile's camera rays come from the frusta tracer, made on demand */
  const int frusta = t->intersect_frusta && tx + TILE <= W && ty + TILE <= H;
  /* pixels in 4x4 blocks, so groups of 16 rays are coherent */
  for (int by = 0; by < TILE; by += 4)
    for (int bx = 0; bx < TILE; bx += 4)
      for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++) {
          int X = tx + bx + x, Y = ty + by + y;
          if (X >= W || Y >= H) continue;
          B->px[n] = X; B->py[n] = Y;
          if (!frusta) {
            B->prim_ray[n] = fr_camera_ray(&w->cam, X, Y);
            B->rays[n] = B->prim_ray[n];
          }
          n++;
        }
  uint64_t rays = (uint64_t)n;
  long fetched = -1;
  if (frusta)
    fetched = (long)fr_camera_frusta(w, t, tx, ty, B->prim_ray, B->prim_hit);
  else
    t->intersect(t->ctx, B->rays, B->prim_hit, (size_t)n, 1);
  float lit[TILE_PIX];
  for (int i = 0; i < n; i++) lit[i] = 1.0f;

  switch (w->kind) {
  case FR_WL_PRIMARY:
    break;
  case FR_WL_SOFT16:
    for (int i = 0; i < n; i++) lit[i] = 0.0f;
    rays += fr_tile_soft_shadows(w, t, B, n, lit);
    break;
  case FR_WL_SHADOW:
  case FR_WL_AO16:
    rays += point_or_ao_rays(w, t, B, n, fetched, lit);
    break;
  case FR_WL_DIFFUSE8:
  case FR_WL_SPECULAR8:
    rays += bounce_rays(w, t, B, n);
    break;
  default:
    break;
  }

  if (w->gbuf_vis) write_gbuffer(w, B, n, lit);
  if (w->image) shade_pixels(w, B, n, lit);
  return rays;
}
