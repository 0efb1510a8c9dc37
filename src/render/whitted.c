#include "whitted.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "base/alloc.h"
#include "base/error.h"
#include "render/views.h"
#include "base/timer.h"
#include "base/vec3.h"
#include "render/shadow_frusta.h"
#include "render/whitted_shade.h"
#include "render/workload.h"
#include "trace/kernels.h"

#define WT FR_WHITTED_TILE /* tile side: the largest packet */
#define WT_PIX (WT * WT)

/* ---- materials --------------------------------------------------------------- */

/* every name of list must be a material of s ("all" aside) */
static fr_error check_list(const fr_scene *s, const char *list, const char *what) {
  for (const char *p = list; p && *p;) {
    const char *e = strchr(p, ',');
    size_t len = e ? (size_t)(e - p) : strlen(p);
    int found = len == 3 && !memcmp(p, "all", 3) && !strcmp(what, "mirror");
    for (size_t i = 0; i < fr_scene_material_count(s) && !found; i++) {
      const char *nm = fr_scene_material(s, i)->name;
      found = strlen(nm) == len && !memcmp(nm, p, len);
    }
    if (!found) return fr_fail(FR_ERR_ARG, "--%s: the scene has no material '%.*s'", what, (int)len, p);
    p = e ? e + 1 : NULL;
  }
  return FR_OK;
}

fr_error fr_whitted_mats_build(const fr_scene *s, const char *mirror, const char *glass, fr_whitted_mats *out) {
  memset(out, 0, sizeof *out);
  fr_error err;
  if ((err = check_list(s, mirror, "mirror")) || (err = check_list(s, glass, "glass"))) return err;
  const int defaults = !mirror && !glass;
  if (defaults) fr_view_surfaces(s->name, &mirror, &glass);
  const int by_mtl = defaults && !mirror && !glass;
  const int all = fr_names_contain(mirror, "all");
  size_t nm = fr_scene_material_count(s);
  out->mat = calloc(nm + 1, sizeof *out->mat);
  if (!out->mat) return fr_fail(FR_ERR_NOMEM, "out of memory for %zu materials", nm + 1);
  out->count = nm + 1;
  for (size_t i = 0; i <= nm; i++) {
    fr_whitted_mat *w = &out->mat[i];
    const fr_material *m = i < nm ? fr_scene_material(s, i) : NULL;
    for (int c = 0; c < 3; c++) {
      w->kd[c] = m ? m->diffuse[c] : 0.7f;
      w->ks[c] = m ? m->specular[c] : 0.0f;
      w->kt[c] = m ? m->transmission[c] : 0.0f;
    }
    w->ns = m ? m->shininess : 0.0f;
    w->ior = m && m->ior > 0.0f ? m->ior : 1.5f;
    float ks = fmaxf(w->ks[0], fmaxf(w->ks[1], w->ks[2])), kt = fmaxf(w->kt[0], fmaxf(w->kt[1], w->kt[2]));
    int is_glass = m && (by_mtl ? kt > 0.0f : fr_names_contain(glass, m->name));
    int is_mirror = all || (m && (by_mtl ? m->illum == 3 && ks > 0.0f : fr_names_contain(mirror, m->name)));
    if (is_glass) {
      w->kind = FR_SURF_GLASS;
      /* glass named on the command line without a transmission of its own: clear */
      if (kt == 0.0f) w->kt[0] = w->kt[1] = w->kt[2] = 0.9f;
    } else if (is_mirror) {
      w->kind = FR_SURF_MIRROR;
      if (all || ks == 0.0f) {
        /* "all": every surface reflects half the light and keeps half its colour */
        for (int c = 0; c < 3; c++) { w->ks[c] = 0.5f; w->kd[c] *= 0.5f; }
      }
    }
  }
  out->soa = malloc(FR_WM_FIELDS * out->count * sizeof *out->soa);
  if (!out->soa) { fr_whitted_mats_free(out); return fr_fail(FR_ERR_NOMEM, "out of memory for %zu materials", nm + 1); }
  fr_whitted_mats_soa(out);
  if ((err = fr_surfaces_build(s, (int32_t)out->count - 1, &out->tri, &out->ntris))) { fr_whitted_mats_free(out); return err; }
  return FR_OK;
}

void fr_whitted_mats_soa(fr_whitted_mats *m) {
  for (size_t i = 0; i < m->count; i++) {
    const fr_whitted_mat *w = &m->mat[i];
    float *f = m->soa + i;
    const size_t c = m->count;
    float kd = fr_maxf(w->kd[0], fr_maxf(w->kd[1], w->kd[2])), ks = fr_maxf(w->ks[0], fr_maxf(w->ks[1], w->ks[2]));
    for (int a = 0; a < 3; a++) {
      f[(FR_WM_KD + a) * c] = w->kd[a];
      f[(FR_WM_KS + a) * c] = w->ks[a];
      f[(FR_WM_KT + a) * c] = w->kt[a];
    }
    f[FR_WM_NS * c] = w->ns;
    f[FR_WM_IOR * c] = w->ior;
    f[FR_WM_GLASS * c] = w->kind == FR_SURF_GLASS;
    f[FR_WM_BOUNCES * c] = w->kind != FR_SURF_DIFFUSE;
    /* the point light adds where the surface has a colour or a highlight */
    f[FR_WM_LIGHTS * c] = kd > 0.0f || (w->kind == FR_SURF_DIFFUSE && ks > 0.0f);
    f[FR_WM_PHONG * c] = w->kind == FR_SURF_DIFFUSE && w->ns > 0.0f && ks > 0.0f;
  }
}

void fr_whitted_mats_free(fr_whitted_mats *m) {
  free(m->mat);
  free(m->soa);
  free(m->tri);
  memset(m, 0, sizeof *m);
}

static const fr_whitted_mat *mat_of(const fr_scene *s, const fr_whitted_mats *m, uint32_t prim) {
  return &m->mat[fr_surface_material(s, prim, (int32_t)m->count - 1)];
}

void fr_whitted_mats_census(const fr_scene *s, const fr_whitted_mats *m, size_t *mirror_prims, size_t *glass_prims) {
  *mirror_prims = *glass_prims = 0;
  size_t n = fr_scene_triangle_count(s) + fr_scene_sphere_count(s);
  for (size_t t = 0; t < n; t++) {
    fr_whitted_kind k = mat_of(s, m, (uint32_t)t)->kind;
    *mirror_prims += k == FR_SURF_MIRROR;
    *glass_prims += k == FR_SURF_GLASS;
  }
}

void fr_whitted_shade16(const fr_wshade_in *in, fr_wshade_out *out) {
  switch (fr_kernels_active()->isa) {
  case FR_ISA_AVX512: fr_whitted_shade16_avx512(in, out); break;
  case FR_ISA_AVX2: fr_whitted_shade16_avx2(in, out); break;
  default: fr_whitted_shade16_scalar(in, out); break;
  }
}

void fr_whitted_emit16(const fr_wshade_out *out, const float light[3], float eps, fr_wsink *shadow, fr_wsink *next) {
  switch (fr_kernels_active()->isa) {
  case FR_ISA_AVX512: fr_whitted_emit16_avx512(out, light, eps, shadow, next); break;
  case FR_ISA_AVX2: fr_whitted_emit16_avx2(out, light, eps, shadow, next); break;
  default: fr_whitted_emit16_scalar(out, light, eps, shadow, next); break;
  }
}

/* ---- the tile engine ------------------------------------------------------------ */

/* A generation of rays: the rays, in the layout the tracers take, and beside
 * them what each carries. */
typedef struct wgen {
  fr_ray *r;
  fr_wpath *p;
} wgen;

typedef struct fr_whitted_scratch {
  size_t cap;
  wgen cur, next, shadow;
  fr_hit *hits;
  uint8_t *occ;
  fr_surface *surf;       /* a generation's geometric normals (not unit) and materials */
  vec3 colour[WT_PIX];
  double stage[FR_STAGES];    /* seconds, over this thread's tiles */
} fr_whitted_scratch;

/* realloc that keeps the old block on failure */
static int grow(void **p, size_t bytes) {
  void *q = realloc(*p, bytes);
  if (!q) return 0;
  *p = q;
  return 1;
}

static int grow_gen(wgen *g, size_t cap) {
  return grow((void **)&g->r, cap * sizeof *g->r) && grow((void **)&g->p, cap * sizeof *g->p);
}

static int reserve(fr_whitted_scratch *S, size_t n) {
  if (n <= S->cap) return 1;
  size_t cap = S->cap ? S->cap : 4096;
  while (cap < n) cap *= 2;
  if (!grow_gen(&S->cur, cap) || !grow_gen(&S->next, cap) || !grow_gen(&S->shadow, cap) ||
      !grow((void **)&S->hits, cap * sizeof *S->hits) || !grow((void **)&S->occ, cap) ||
      !grow((void **)&S->surf, cap * sizeof *S->surf))
    return 0;
  S->cap = cap;
  return 1;
}

fr_whitted_scratch *fr_whitted_scratch_new(void) { return calloc(1, sizeof(fr_whitted_scratch)); }

void fr_whitted_scratch_stages(const fr_whitted_scratch *S, double stage[FR_STAGES]) {
  if (S)
    for (int i = 0; i < FR_STAGES; i++) stage[i] += S->stage[i];
}

void fr_whitted_scratch_free(fr_whitted_scratch *S) {
  if (!S) return;
  wgen *g[3] = {&S->cur, &S->next, &S->shadow};
  for (int i = 0; i < 3; i++) { free(g[i]->r); free(g[i]->p); }
  free(S->hits); free(S->occ); free(S->surf);
  free(S);
}

/* Hands rays [0, n) of a generation to the tracer, one call per packet (run
 * of equal keys). */
static void trace_runs(const fr_tracer *t, wgen g, fr_hit *hits, uint8_t *occ, size_t n) {
  for (size_t a = 0; a < n;) {
    size_t b = a + 1;
    while (b < n && g.p[b].key == g.p[a].key) b++;
    if (occ) t->occluded(t->ctx, g.r + a, occ + a, b - a, 1);
    else t->intersect(t->ctx, g.r + a, hits + a, b - a, 1);
    a = b;
  }
}

/* The pixel of ray i of a 16x16 quarter's frusta (ray k = i % 16 of 4x4
 * frustum f = i / 16), from the quarter's corner in a tile row of WT:
 * row 4 (f / 4) + k / 4, column 4 (f % 4) + k % 4. */
static inline unsigned frustum_pix(unsigned i) {
  return (((i >> 4) & 12u) + ((i >> 2) & 3u)) * WT + ((i >> 2) & 12u) + (i & 3u);
}

/* What each hit needs from memory, its material and normal, in a loop
 * short enough that the cache misses of many hits overlap; the arithmetic
 * follows 16 hits at a time. */
static void fetch_surfaces(const fr_workload *w, fr_whitted_scratch *S, size_t n) {
  for (size_t i = 0; i < n; i++) {
    const fr_hit *h = &S->hits[i];
    fr_surface *sf = &S->surf[i];
    if (h->prim < w->mats->ntris) {
      *sf = w->mats->tri[h->prim];
      /* smooth shading: the interpolated normal, on the geometric normal's
       * side and the same side of the ray (else the geometric one) */
      float sn[3];
      if (fr_scene_shading_normal(w->scene, h->prim, h->u, h->v, sn)) {
        const float *d = S->cur.r[i].dir, *g = sf->ng;
        const float sg = sn[0] * g[0] + sn[1] * g[1] + sn[2] * g[2], s = sg < 0.0f ? -1.0f : 1.0f;
        const float dn = s * (sn[0] * d[0] + sn[1] * d[1] + sn[2] * d[2]), dg = g[0] * d[0] + g[1] * d[1] + g[2] * d[2];
        if ((dn < 0.0f) == (dg < 0.0f)) sf->ng[0] = s * sn[0], sf->ng[1] = s * sn[1], sf->ng[2] = s * sn[2];
      }
      continue;
    }
    *sf = (fr_surface){{0.0f, 0.0f, 0.0f}, 0};
    if (h->prim == FR_INVALID_ID) continue;
    const float *o = S->cur.r[i].org, *d = S->cur.r[i].dir; /* a sphere: the normal is p - c */
    float pp[3] = {o[0] + d[0] * h->t, o[1] + d[1] * h->t, o[2] + d[2] * h->t};
    fr_scene_geometric_normal(w->scene, h->prim, pp, sf->ng);
    sf->mat = fr_surface_material(w->scene, h->prim, (int32_t)w->mats->count - 1);
  }
}

/* The next generation's nn rays into S->cur, grouped by key (a counting
 * sort, stable): the reflection and the refraction packets of each of the
 * per x per blocks. */
static void group_by_key(fr_whitted_scratch *S, size_t nn, int per) {
  size_t count[2 * WT_PIX + 1];
  memset(count, 0, (2 * (size_t)(per * per) + 1) * sizeof count[0]);
  for (size_t i = 0; i < nn; i++) count[S->next.p[i].key + 1]++;
  for (int k = 1; k <= 2 * per * per; k++) count[k] += count[k - 1];
  for (size_t i = 0; i < nn; i++) {
    size_t j = count[S->next.p[i].key]++;
    S->cur.r[j] = S->next.r[i];
    S->cur.p[j] = S->next.p[i];
  }
}

uint64_t fr_whitted_tile(const fr_workload *w, const fr_tracer *t, fr_whitted_scratch *S, int tx, int ty) {
  const int W = w->cam.width, H = w->cam.height;
  const int side = t->packet_side > 0 && t->packet_side <= WT ? t->packet_side : WT, per = WT / side;
  const int max_depth = w->max_depth > 0 ? w->max_depth : 4;
  if (!reserve(S, 2 * WT_PIX)) return 0;
  /* a few clock reads per generation: stage times for bench (fr_workload_result) */
  const double t_tile = fr_seconds();
  double traced_s = 0.0;
  size_t n = 0, traced = 0;
  if (t->intersect_frusta && w->camera_set && side == WT) {
    /* a multi-frusta tracer traces the camera rays of every full 16x16
     * quarter of the tile as 16 frusta; the tile is one packet (key 0) */
    for (int q = 0; q < 4; q++) {
      int qx = tx + 16 * (q % 2), qy = ty + 16 * (q / 2);
      if (qx + 16 > W || qy + 16 > H) continue;
      fr_camera_frusta(w, t, qx, qy, S->cur.r + n, S->hits + n);
      const int corner = (qy - ty) * WT + (qx - tx);
      for (int i = 0; i < 256; i++, n++)
        S->cur.p[n] = (fr_wpath){{1.0f, 1.0f, 1.0f}, (uint16_t)(corner + (int)frustum_pix((unsigned)i)), 0};
    }
    traced = n;
  }
  for (int b = 0; b < per * per && traced < WT_PIX; b++) /* (all four quarters as frusta: nothing left) */
    for (int y = 0; y < side; y++)
      for (int x = 0; x < side; x++) {
        int X = tx + (b % per) * side + x, Y = ty + (b / per) * side + y;
        if (X >= W || Y >= H) continue;
        if (traced && X + 16 - X % 16 <= W && Y + 16 - Y % 16 <= H) continue; /* in a traced quarter */
        S->cur.r[n] = fr_camera_ray(&w->cam, X, Y);
        S->cur.p[n++] = (fr_wpath){{1.0f, 1.0f, 1.0f}, (uint16_t)((Y - ty) * WT + (X - tx)), (uint16_t)(2 * b)};
      }
  for (int i = 0; i < WT_PIX; i++) S->colour[i] = v3(0, 0, 0);
  uint64_t rays = 0;
  for (int depth = 0; n > 0; depth++) {
    const double t_gen = fr_seconds();
    trace_runs(t, (wgen){S->cur.r + traced, S->cur.p + traced}, S->hits + traced, NULL, n - traced);
    const double t_traced = fr_seconds();
    /* the camera stage runs from the tile's start: making the rays is part of it */
    const double dt = depth == 0 ? t_traced - t_tile : t_traced - t_gen;
    S->stage[depth == 0 ? FR_STAGE_CAMERA : FR_STAGE_SECONDARY] += dt;
    traced_s += dt;
    traced = 0;
    rays += n;
    /* room for two new rays per ray, and a whole group of 16 past them */
    if (!reserve(S, 2 * n + 2 * FR_WS_LANES)) return rays;
    fr_wsink shadow = {S->shadow.r, S->shadow.p, 0}, next = {S->next.r, S->next.p, 0};
    fetch_surfaces(w, S, n);
    fr_wshade_in in = {.mats = w->mats->soa, .mat_count = w->mats->count, .bounce = depth < max_depth};
    memcpy(in.light, &w->view.light, sizeof in.light);
    for (size_t i0 = 0; i0 < n; i0 += FR_WS_LANES) {
      const size_t lanes = n - i0 < FR_WS_LANES ? n - i0 : FR_WS_LANES;
      in.ray = S->cur.r + i0;
      in.path = S->cur.p + i0;
      in.hit = S->hits + i0;
      in.surf = S->surf + i0;
      in.valid = (unsigned)((1u << lanes) - 1u);
      in.hits = 0;
      for (size_t l = 0; l < lanes; l++) in.hits |= (unsigned)(S->hits[i0 + l].prim != FR_INVALID_ID) << l;
      fr_wshade_out out;
      fr_whitted_shade16(&in, &out);
      for (size_t l = 0; l < lanes; l++) {
        vec3 *c = &S->colour[S->cur.p[i0 + l].pix];
        *c = v3_add(*c, v3(out.add[0][l], out.add[1][l], out.add[2][l]));
      }
      /* Shadow rays are traced from the light to just short of the
       * surface, so that a block's shadow rays share an origin and a large
       * packet's frustum one apex. The light's own end skips 1e-4 of the
       * way, for a light on a surface. */
      fr_whitted_emit16(&out, in.light, w->eps, &shadow, &next);
    }
    const size_t ns = shadow.n, nn = next.n;
    /* shadow rays, packet by packet (they follow their block's order) */
    const double t_shadow = fr_seconds();
    if (t->occluded_frusta && depth == 0) {
      const fr_shadow_rays src = {S->shadow.r, NULL, NULL, 0.0f};
      fr_shadow_frusta_occluded(t, &src, S->occ, ns, !w->mft_no_fallback);
    } else {
      trace_runs(t, S->shadow, NULL, S->occ, ns);
    }
    const double ds = fr_seconds() - t_shadow;
    S->stage[FR_STAGE_SHADOW] += ds;
    traced_s += ds;
    rays += ns;
    for (size_t i = 0; i < ns; i++) {
      const fr_wpath *g = &S->shadow.p[i];
      if (!S->occ[i]) S->colour[g->pix] = v3_add(S->colour[g->pix], v3_load(g->w));
    }
    group_by_key(S, nn, per);
    n = nn;
  }
  S->stage[FR_STAGE_SHADE] += fr_seconds() - t_tile - traced_s;
  if (w->image)
    for (int i = 0; i < WT_PIX; i++) {
      int X = tx + i % WT, Y = ty + i / WT;
      if (X >= W || Y >= H) continue;
      float *px = w->image + 3 * ((size_t)Y * (size_t)W + (size_t)X);
      px[0] = S->colour[i].x; px[1] = S->colour[i].y; px[2] = S->colour[i].z;
    }
  return rays;
}
