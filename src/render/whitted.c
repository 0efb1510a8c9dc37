#include "whitted.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "base/error.h"
#include "base/vec3.h"
#include "render/workload.h"

#define WT FR_WHITTED_TILE /* tile side: the largest packet */
#define WT_PIX (WT * WT)
#define MIN_WEIGHT 0.01f   /* secondary rays carrying less are not traced */
#define AMBIENT 0.1f

/* ---- materials --------------------------------------------------------------- */

static int in_list(const char *list, const char *name) {
  size_t n = strlen(name);
  for (const char *p = list; p && *p;) {
    const char *e = strchr(p, ',');
    size_t len = e ? (size_t)(e - p) : strlen(p);
    if (len == n && !memcmp(p, name, n)) return 1;
    p = e ? e + 1 : NULL;
  }
  return 0;
}

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

/* the scenes README's suggestions */
static void scene_defaults(const char *scene, const char **mirror, const char **glass) {
  if (!strcmp(scene, "kitchen")) { *mirror = "shiny_metal,metal"; *glass = "glass,glass_dragon"; }
  else if (!strcmp(scene, "museum")) { *mirror = "museum5_0"; *glass = "museum5_1"; }
}

fr_error fr_whitted_mats_build(const fr_scene *s, const char *mirror, const char *glass, fr_whitted_mats *out) {
  memset(out, 0, sizeof *out);
  fr_error err;
  if ((err = check_list(s, mirror, "mirror")) || (err = check_list(s, glass, "glass"))) return err;
  const int defaults = !mirror && !glass;
  if (defaults) scene_defaults(s->name, &mirror, &glass);
  const int by_mtl = defaults && !mirror && !glass;
  const int all = in_list(mirror, "all");
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
    int is_glass = m && (by_mtl ? kt > 0.0f : in_list(glass, m->name));
    int is_mirror = all || (m && (by_mtl ? m->illum == 3 && ks > 0.0f : in_list(mirror, m->name)));
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
  return FR_OK;
}

void fr_whitted_mats_free(fr_whitted_mats *m) {
  free(m->mat);
  memset(m, 0, sizeof *m);
}

static const fr_whitted_mat *mat_of(const fr_scene *s, const fr_whitted_mats *m, uint32_t prim) {
  uint32_t i = fr_scene_prim_material(s, prim);
  return &m->mat[i == FR_INVALID_ID || i + 1 >= m->count ? m->count - 1 : i];
}

void fr_whitted_mats_census(const fr_scene *s, const fr_whitted_mats *m, size_t *mirror_prims, size_t *glass_prims) {
  *mirror_prims = *glass_prims = 0;
  size_t n = fr_scene_triangle_count(s) + fr_scene_sphere_count(s);
  for (size_t t = 0; t < n; t++) {
    fr_surface k = mat_of(s, m, (uint32_t)t)->kind;
    *mirror_prims += k == FR_SURF_MIRROR;
    *glass_prims += k == FR_SURF_GLASS;
  }
}

/* ---- the tile engine ------------------------------------------------------------ */

/* a ray of a generation: its pixel, the weight it carries, its packet key
 * (block * 2 + kind: 0 camera or reflection, 1 refraction) */
typedef struct wray {
  fr_ray r;
  vec3 w;
  uint16_t pix;
  uint16_t key;
} wray;

typedef struct fr_whitted_scratch {
  size_t cap;
  wray *cur, *next, *shadow;
  fr_ray *rays;
  fr_hit *hits;
  uint8_t *occ;
  vec3 colour[WT_PIX];
} fr_whitted_scratch;

/* realloc that keeps the old block on failure */
static int grow(void **p, size_t bytes) {
  void *q = realloc(*p, bytes);
  if (!q) return 0;
  *p = q;
  return 1;
}

static int reserve(fr_whitted_scratch *S, size_t n) {
  if (n <= S->cap) return 1;
  size_t cap = S->cap ? S->cap : 4096;
  while (cap < n) cap *= 2;
  if (!grow((void **)&S->cur, cap * sizeof *S->cur) || !grow((void **)&S->next, cap * sizeof *S->next) ||
      !grow((void **)&S->shadow, cap * sizeof *S->shadow) || !grow((void **)&S->rays, cap * sizeof *S->rays) ||
      !grow((void **)&S->hits, cap * sizeof *S->hits) || !grow((void **)&S->occ, cap))
    return 0;
  S->cap = cap;
  return 1;
}

fr_whitted_scratch *fr_whitted_scratch_new(void) { return calloc(1, sizeof(fr_whitted_scratch)); }

void fr_whitted_scratch_free(fr_whitted_scratch *S) {
  if (!S) return;
  free(S->cur); free(S->next); free(S->shadow); free(S->rays); free(S->hits); free(S->occ);
  free(S);
}

/* Hands rays [0, n) of a generation to the tracer, one call per packet (run
 * of equal keys). */
static void trace_runs(const fr_tracer *t, const wray *g, fr_ray *rays, fr_hit *hits, uint8_t *occ, size_t n) {
  for (size_t i = 0; i < n; i++) rays[i] = g[i].r;
  for (size_t a = 0; a < n;) {
    size_t b = a + 1;
    while (b < n && g[b].key == g[a].key) b++;
    if (occ) t->occluded(t->ctx, rays + a, occ + a, b - a, 1);
    else t->intersect(t->ctx, rays + a, hits + a, b - a, 1);
    a = b;
  }
}

static float fresnel(float cosi, float eta, float *cost_out) {
  float k = 1.0f - eta * eta * (1.0f - cosi * cosi);
  if (k <= 0.0f) { *cost_out = 0.0f; return 1.0f; } /* total internal reflection */
  float cost = sqrtf(k);
  float rs = (eta * cosi - cost) / (eta * cosi + cost), rp = (eta * cost - cosi) / (eta * cost + cosi);
  *cost_out = cost;
  return 0.5f * (rs * rs + rp * rp);
}

static float vmax3(vec3 a) { return fmaxf(a.x, fmaxf(a.y, a.z)); }
static vec3 vmul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }

uint64_t fr_whitted_tile(const fr_workload *w, const fr_tracer *t, fr_whitted_scratch *S, int tx, int ty) {
  const int W = w->cam.width, H = w->cam.height;
  const int side = t->packet_side > 0 && t->packet_side <= WT ? t->packet_side : WT, per = WT / side;
  const fr_scene *sc = w->scene;
  const int max_depth = w->max_depth > 0 ? w->max_depth : 4;
  if (!reserve(S, 2 * WT_PIX)) return 0;
  size_t n = 0, traced = 0;
  if (t->intersect_frusta && w->camera_set && side == WT) {
    /* a multi-frusta tracer traces the camera rays of every full 16x16
     * quarter of the tile as 16 frusta; the tile is one packet (key 0) */
    for (int q = 0; q < 4; q++) {
      int qx = tx + 16 * (q % 2), qy = ty + 16 * (q / 2);
      if (qx + 16 > W || qy + 16 > H) continue;
      fr_camera_frusta(w, t, qx, qy, S->rays + n, S->hits + n);
      for (int i = 0; i < 256; i++, n++) {
        int f = i / 16, k = i % 16;
        int X = qx + 4 * (f % 4) + k % 4, Y = qy + 4 * (f / 4) + k / 4;
        wray *g = &S->cur[n];
        g->r = S->rays[n];
        g->w = v3(1, 1, 1);
        g->pix = (uint16_t)((Y - ty) * WT + (X - tx));
        g->key = 0;
      }
    }
    traced = n;
  }
  for (int b = 0; b < per * per; b++)
    for (int y = 0; y < side; y++)
      for (int x = 0; x < side; x++) {
        int X = tx + (b % per) * side + x, Y = ty + (b / per) * side + y;
        if (X >= W || Y >= H) continue;
        if (traced && X + 16 - X % 16 <= W && Y + 16 - Y % 16 <= H) continue; /* in a traced quarter */
        wray *g = &S->cur[n++];
        g->r = fr_camera_ray(&w->cam, X, Y);
        g->w = v3(1, 1, 1);
        g->pix = (uint16_t)((Y - ty) * WT + (X - tx));
        g->key = (uint16_t)(2 * b);
      }
  for (int i = 0; i < WT_PIX; i++) S->colour[i] = v3(0, 0, 0);
  uint64_t rays = 0;
  for (int depth = 0; n > 0; depth++) {
    trace_runs(t, S->cur + traced, S->rays + traced, S->hits + traced, NULL, n - traced);
    traced = 0;
    rays += n;
    size_t ns = 0, nn = 0;
    if (!reserve(S, 2 * n)) return rays;
    for (size_t i = 0; i < n; i++) {
      const wray *g = &S->cur[i];
      const fr_hit *h = &S->hits[i];
      if (h->prim == FR_INVALID_ID) {
        S->colour[g->pix] = v3_add(S->colour[g->pix], v3_scale(g->w, 0.05f));
        continue;
      }
      const fr_whitted_mat *m = mat_of(sc, w->mats, h->prim);
      vec3 d = v3_load(g->r.dir), p = v3_add(v3_load(g->r.org), v3_scale(d, h->t));
      float gn[3], pp[3] = {p.x, p.y, p.z};
      fr_scene_geometric_normal(sc, h->prim, pp, gn);
      vec3 ng = v3_norm(v3_load(gn));
      int entering = v3_dot(ng, d) < 0.0f;
      vec3 nf = entering ? ng : v3_scale(ng, -1.0f);
      vec3 kd = v3(m->kd[0], m->kd[1], m->kd[2]), ks = v3(m->ks[0], m->ks[1], m->ks[2]);
      S->colour[g->pix] = v3_add(S->colour[g->pix], vmul(g->w, v3_scale(kd, AMBIENT)));
      /* direct light: a shadow ray wherever the surface has a colour of its own */
      vec3 to = v3_sub(w->view.light, p);
      float dist = v3_len(to);
      vec3 l = v3_scale(to, 1.0f / dist);
      float ndl = v3_dot(nf, l);
      if (ndl > 0.0f && dist > 0.0f && (vmax3(kd) > 0.0f || (m->kind == FR_SURF_DIFFUSE && vmax3(ks) > 0.0f))) {
        vec3 lit = v3_scale(kd, ndl);
        if (m->kind == FR_SURF_DIFFUSE && m->ns > 0.0f && vmax3(ks) > 0.0f) {
          vec3 r = v3_sub(v3_scale(nf, 2.0f * ndl), l);
          float rv = -v3_dot(r, d);
          if (rv > 0.0f) lit = v3_add(lit, v3_scale(ks, powf(rv, m->ns)));
        }
        wray *sh = &S->shadow[ns++];
        sh->r = (fr_ray){{p.x, p.y, p.z}, w->eps, {l.x, l.y, l.z}, dist * (1.0f - 1e-4f)};
        sh->w = vmul(g->w, lit);
        sh->pix = g->pix;
        sh->key = (uint16_t)(g->key / 2);
      }
      if (depth >= max_depth || m->kind == FR_SURF_DIFFUSE) continue;
      float cosi = -v3_dot(d, nf);
      vec3 refl = v3_add(d, v3_scale(nf, 2.0f * cosi));
      vec3 wr = vmul(g->w, ks), wt = v3(0, 0, 0), tdir = v3(0, 0, 0);
      if (m->kind == FR_SURF_GLASS) {
        float eta = entering ? 1.0f / m->ior : m->ior, cost;
        float F = fresnel(cosi, eta, &cost);
        wr = v3_scale(g->w, F);
        wt = v3_scale(vmul(g->w, v3(m->kt[0], m->kt[1], m->kt[2])), 1.0f - F);
        tdir = v3_add(v3_scale(d, eta), v3_scale(nf, eta * cosi - cost));
      }
      if (vmax3(wr) > MIN_WEIGHT) {
        wray *r = &S->next[nn++];
        r->r = (fr_ray){{p.x, p.y, p.z}, w->eps, {refl.x, refl.y, refl.z}, INFINITY};
        r->w = wr;
        r->pix = g->pix;
        r->key = (uint16_t)(g->key & ~1u);
      }
      if (vmax3(wt) > MIN_WEIGHT) {
        tdir = v3_norm(tdir);
        wray *r = &S->next[nn++];
        r->r = (fr_ray){{p.x, p.y, p.z}, w->eps, {tdir.x, tdir.y, tdir.z}, INFINITY};
        r->w = wt;
        r->pix = g->pix;
        r->key = (uint16_t)(g->key | 1u);
      }
    }
    /* shadow rays, packet by packet (they follow their block's order) */
    trace_runs(t, S->shadow, S->rays, NULL, S->occ, ns);
    rays += ns;
    for (size_t i = 0; i < ns; i++)
      if (!S->occ[i]) S->colour[S->shadow[i].pix] = v3_add(S->colour[S->shadow[i].pix], S->shadow[i].w);
    /* the next generation grouped by key: reflection and refraction packets of each block */
    size_t count[2 * WT_PIX + 1];
    memset(count, 0, sizeof count);
    for (size_t i = 0; i < nn; i++) count[S->next[i].key + 1]++;
    for (int k = 1; k <= 2 * per * per; k++) count[k] += count[k - 1];
    for (size_t i = 0; i < nn; i++) S->cur[count[S->next[i].key]++] = S->next[i];
    n = nn;
  }
  if (w->image)
    for (int i = 0; i < WT_PIX; i++) {
      int X = tx + i % WT, Y = ty + i / WT;
      if (X >= W || Y >= H) continue;
      float *px = w->image + 3 * ((size_t)Y * (size_t)W + (size_t)X);
      px[0] = S->colour[i].x; px[1] = S->colour[i].y; px[2] = S->colour[i].z;
    }
  return rays;
}
