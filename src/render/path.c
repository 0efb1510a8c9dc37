/*
 * The path tracer's tiles (see path.h).
 *
 * Sample dimensions: pair 0 the position within the pixel, pair 1 the lens,
 * and at bounce b the pairs 2 + 4b (light choice, BSDF lobe choice),
 * 3 + 4b (point on the light), 4 + 4b (BSDF direction), 5 + 4b (Russian
 * roulette).
 */
#include "render/path.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"
#include "base/timer.h"
#include "material/texture.h"
#include "api/scene.h"
#include "render/path_camera.h"
#include "render/path_frames.h"
#include "render/shadow_frusta.h"
#include "render/surfaces.h"
#include "render/tile.h"

/* A wave: a tile's paths for as many samples per pixel as fill it */
#define WAVE FR_PATH_WAVE
_Static_assert(WAVE >= TILE_PIX * FR_PATH_CHUNK && WAVE >= 32 * 32 * 2, "a pass's samples fill waves");
_Static_assert(WAVE <= 65536, "path_state.slot is 16 bits");
/* Sample points, environment lookups and hit frames are made for this many
 * paths at a time, as vector code */
#define POINT_BLOCK FR_PATH_FRAMES
/* the largest tile side (fr_path_tile_side) */
#define SIDE_MAX 32

typedef struct path_state {
  vec3 weight;     /* throughput: what the radiance found next is multiplied by */
  float pdf;       /* solid-angle pdf of the BSDF sample that made the ray (for MIS at an emitter it hits) */
  uint32_t sample; /* sample index within the pixel */
  uint32_t key;    /* the pixel's sampler key */
  uint16_t slot;   /* (sample - first sample of the wave) * the tile's pixels + pixel within the tile */
  uint8_t delta;   /* the ray left a delta lobe (or the camera): emitters it hits count whole */
  uint8_t depth;   /* segments before this one */
} path_state;

/* What shading a hit needs: the point, the geometric normal turned to the
 * side shaded, the shading frame (t, b, n), wo in it, the material and its
 * shading point. */
typedef struct hit_frame {
  vec3 p, ngo, n, t, b, wo;
  const fr_bsdf *m;
  fr_shading_point sp;
} hit_frame;

struct fr_path_scratch {
  fr_ray ray[WAVE];
  fr_hit hit[WAVE];
  path_state st[WAVE];
  fr_ray sray[WAVE];
  uint8_t occ[WAVE];
  vec3 scontrib[WAVE];
  uint16_t spix[WAVE];
  /* the camera hits' shadow rays to the point light, where a multi-frusta
   * tracer traces them from the light: each hit point, contribution and slot
   * (their verdicts go to occ once the other shadow rays' are used) */
  float ppts[3 * WAVE];
  vec3 pcontrib[WAVE];
  uint16_t ppix[WAVE];
  /* per sample and pixel, so that a pixel's samples are summed in their
   * order however many a wave holds: the image is the same bits for any
   * split of the samples into calls */
  vec3 acc[WAVE], alb[WAVE], nrm[WAVE];
  float dep[WAVE];
  double stage[FR_STAGES];
  /* the block of paths being shaded (frame_block, next_events,
   * continue_paths): the lanes' inputs and frames, the hits' materials,
   * the frames as the shader reads them, the states, which paths go on
   * from their hit, and a textured material's copy */
  fr_path_frame_in lanes_in;
  fr_path_frames lanes;
  int32_t mat[POINT_BLOCK];
  hit_frame frame[POINT_BLOCK];
  path_state bst[POINT_BLOCK];
  uint8_t live[POINT_BLOCK];
  fr_bsdf textured[POINT_BLOCK];
  /* the tile's pixels: coordinates in the image, sampler keys, and whether
   * each lies inside it */
  float pix_x[SIDE_MAX * SIDE_MAX], pix_y[SIDE_MAX * SIDE_MAX];
  uint32_t pix_key[SIDE_MAX * SIDE_MAX];
  uint8_t pix_in[SIDE_MAX * SIDE_MAX];
};

fr_path_scratch *fr_path_scratch_new(void) {
  fr_path_scratch *s = fr_alloc_aligned(sizeof(fr_path_scratch), 64);
  if (s) memset(s->stage, 0, sizeof s->stage);
  return s;
}
void fr_path_scratch_free(fr_path_scratch *s) { fr_free_aligned(s); }
void fr_path_scratch_stages(const fr_path_scratch *s, double *stage) {
  if (s)
    for (int k = 0; k < FR_STAGES; k++) stage[k] += s->stage[k];
}

static float power_heuristic(float a, float b) {
  const float a2 = a * a, b2 = b * b;
  return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

/* The number of lights next-event estimation chooses among, uniformly. */
static int light_count(const fr_path_lights *L) { return !L->env->black + L->area + L->point; }

/* The area light as the shader tests it, made once per tile: its normal
 * n = e1 x e2 (not unit) and the vectors that give a point x's place on
 * it, s = (x - c) . ds and u = (x - c) . du (ds = (e2 x n) / n.n,
 * du = (n x e1) / n.n: the triple products of its edges, precomputed). */
typedef struct quad_light { vec3 c, e1, e2, n, ds, du, radiance; } quad_light;

static quad_light quad_light_of(const fr_path_lights *L) {
  const vec3 n = v3_cross(L->area_e1, L->area_e2);
  const float n2 = v3_dot(n, n), k = n2 > 0.0f ? 1.0f / n2 : 0.0f;
  return (quad_light){L->area_c, L->area_e1, L->area_e2, n, v3_scale(v3_cross(L->area_e2, n), k),
                      v3_scale(v3_cross(n, L->area_e1), k), L->area_radiance};
}

/* t of the ray (o, d) through the area light within (tnear, tfar), or 0. */
static float area_hit(const quad_light *q, vec3 o, vec3 d, float tnear, float tfar) {
  const float den = v3_dot(d, q->n);
  if (den == 0.0f) return 0.0f;
  const float t = v3_dot(v3_sub(q->c, o), q->n) / den;
  if (!(t > tnear && t < tfar)) return 0.0f;
  const vec3 x = v3_sub(v3_add(o, v3_scale(d, t)), q->c);
  const float s = v3_dot(x, q->ds), u = v3_dot(x, q->du);
  return s >= 0.0f && s <= 1.0f && u >= 0.0f && u <= 1.0f ? t : 0.0f;
}

/* Solid-angle pdf of sampling the area light's point at distance dist
 * along unit d: dist^2 / (area cos) = dist^2 / |d . n|. */
static float area_pdf(const quad_light *q, vec3 d, float dist) {
  const float c = fabsf(v3_dot(q->n, d));
  return c > 0.0f ? dist * dist / c : 0.0f;
}

/* The light uc picks of n (environment, area, point: those there are). */
static int light_pick(int n, float uc) {
  const int k = (int)(uc * (float)n);
  return k >= n ? n - 1 : k;
}

/* What a block of paths reads of an image environment, fetched together
 * before the block is shaded: the light samples of the paths that hit
 * something and pick the environment (fr_env_sample_batch; ready[b]: path
 * b's is here), the texels the bounces that escape see (sky[b], NULL
 * where none, with sin theta there), and the background the camera rays
 * that escape see (bg[b] where seen[b]). */
typedef struct env_block {
  vec3 dir[POINT_BLOCK], le[POINT_BLOCK], bg[POINT_BLOCK];
  float pdf[POINT_BLOCK];
  uint8_t ready[POINT_BLOCK], seen[POINT_BLOCK];
  const float *sky[POINT_BLOCK];
  float sky_sin[POINT_BLOCK];
} env_block;

/* One light sample from p: direction, distance (INFINITY for the
 * environment), radiance arriving, solid-angle pdf including the choice
 * of light, and whether it is a delta light; the environment's from eb
 * where it is ready there (eb may be NULL). 0 when none. */
static int sample_light(const fr_path_lights *L, const quad_light *q, const env_block *eb, size_t b, vec3 p, float uc,
                        float u1, float u2, vec3 *wi, float *dist, vec3 *le, float *pdf, int *delta) {
  const int n = light_count(L);
  if (!n) return 0;
  int k = light_pick(n, uc);
  *delta = 0;
  if (!L->env->black && k-- == 0) {
    float pe;
    if (eb && eb->ready[b]) *wi = eb->dir[b], *le = eb->le[b], pe = eb->pdf[b];
    else *le = fr_env_sample(L->env, u1, u2, wi, &pe);
    *dist = INFINITY;
    *pdf = pe / (float)n;
    return pe > 0.0f;
  }
  if (L->area && k-- == 0) {
    const vec3 x = v3_add(q->c, v3_add(v3_scale(q->e1, u1), v3_scale(q->e2, u2)));
    const vec3 to = v3_sub(x, p);
    const float d = v3_len(to);
    if (!(d > 0.0f) || v3_dot(to, q->n) >= 0.0f) return 0; /* behind the lamp */
    *wi = v3_scale(to, 1.0f / d);
    *dist = d;
    *le = q->radiance;
    *pdf = area_pdf(q, *wi, d) / (float)n;
    return *pdf > 0.0f;
  }
  const vec3 to = v3_sub(L->point_pos, p);
  const float d = v3_len(to);
  if (!(d > 0.0f)) return 0;
  *wi = v3_scale(to, 1.0f / d);
  *dist = d;
  *le = v3_scale(L->point_intensity, 1.0f / (d * d));
  *pdf = 1.0f / (float)n;
  *delta = 1;
  return 1;
}

static vec3 to_local(vec3 w, vec3 t, vec3 b, vec3 n) { return v3(v3_dot(w, t), v3_dot(w, b), v3_dot(w, n)); }
static vec3 to_world(vec3 w, vec3 t, vec3 b, vec3 n) {
  return v3_add(v3_add(v3_scale(t, w.x), v3_scale(b, w.y)), v3_scale(n, w.z));
}
/* Whether w lies on the same side of the shading normal n as of the
 * geometric normal ng (both oriented alike). */
static int same_side(vec3 w, vec3 n, vec3 ng) { return (v3_dot(w, n) > 0.0f) == (v3_dot(w, ng) > 0.0f); }
static int nonzero(vec3 c) { return c.x > 0.0f || c.y > 0.0f || c.z > 0.0f; }

static void add3(float *dst, vec3 v) { dst[0] += v.x, dst[1] += v.y, dst[2] += v.z; }

/* The contributions of the n shadow rays that nothing occluded, each to its slot. */
static void add_unoccluded(vec3 *acc, const uint8_t *occ, const uint16_t *slot, const vec3 *contrib, size_t n) {
  for (size_t k = 0; k < n; k++)
    if (!occ[k]) acc[slot[k]] = v3_add(acc[slot[k]], contrib[k]);
}

/* The sample points of dimension pairs d .. d + npairs - 1 for the next
 * POINT_BLOCK paths of st[0..left): pair q's in pts[2q] and pts[2q + 1]. */
static void block_points(const fr_path_setup *P, const path_state *st, size_t left, uint32_t d, int npairs,
                         float pts[][POINT_BLOCK]) {
  const size_t m = left < POINT_BLOCK ? left : POINT_BLOCK;
  uint32_t key[POINT_BLOCK], idx[POINT_BLOCK];
  for (size_t j = 0; j < m; j++) key[j] = st[j].key, idx[j] = st[j].sample;
  for (int q = 0; q < npairs; q++)
    fr_sample2d_batch(P->sampler, key, idx, (uint32_t)P->spp, d + (uint32_t)q, m, pts[2 * q], pts[2 * q + 1]);
}

/* Pair d + q of path st, the b-th of its block: from the block's points
 * (pts, where they are vector code), or made here (NULL: only where a path
 * needs them). */
static inline void path_point(const fr_path_setup *P, const float (*pts)[POINT_BLOCK], size_t b, const path_state *st,
                              uint32_t d, int q, float *u1, float *u2) {
  if (pts) *u1 = pts[2 * q][b], *u2 = pts[2 * q + 1][b];
  else fr_sample2d(P->sampler, st->key, st->sample, (uint32_t)P->spp, d + (uint32_t)q, u1, u2);
}

/* eb for the next POINT_BLOCK paths of st[0..left) and their hits (dimension
 * pairs dim: 0 picks the light, 1 places the sample on it). */
static void env_block_sample(const fr_path_setup *P, const float (*pts)[POINT_BLOCK], const path_state *st,
                             const fr_ray *ray, const fr_hit *hit, size_t left, uint32_t dim, env_block *eb) {
  const size_t m = left < POINT_BLOCK ? left : POINT_BLOCK;
  memset(eb->ready, 0, sizeof eb->ready);
  memset(eb->seen, 0, sizeof eb->seen);
  memset(eb->sky, 0, sizeof eb->sky);
  const fr_env *e = P->lights.env;
  const int n = light_count(&P->lights);
  if (e->black || !e->rgb) return; /* nothing to fetch */
  float u1[POINT_BLOCK], u2[POINT_BLOCK], pdf[POINT_BLOCK], sx[POINT_BLOCK], sy[POINT_BLOCK], sz[POINT_BLOCK];
  float sin_t[POINT_BLOCK], bx[POINT_BLOCK], by[POINT_BLOCK], bz[POINT_BLOCK];
  const float *tex[POINT_BLOCK];
  vec3 dir[POINT_BLOCK], le[POINT_BLOCK];
  uint8_t idx[POINT_BLOCK], sky[POINT_BLOCK], bg[POINT_BLOCK];
  size_t c = 0, ns = 0, nb = 0;
  for (size_t j = 0; j < m; j++) {
    if (hit[j].prim == FR_INVALID_ID) { /* a bounce into the sky, or the background seen (filtered) */
      const float *d = ray[j].dir;
      if (st[j].depth > 0) sx[ns] = d[0], sy[ns] = d[1], sz[ns] = d[2], sky[ns++] = (uint8_t)j;
      else bx[nb] = d[0], by[nb] = d[1], bz[nb] = d[2], bg[nb++] = (uint8_t)j;
      continue;
    }
    float uc, ul;
    path_point(P, pts, j, st + j, dim, 0, &uc, &ul);
    if (light_pick(n, uc) != 0) continue; /* the environment is light 0 */
    path_point(P, pts, j, st + j, dim, 1, &u1[c], &u2[c]);
    idx[c++] = (uint8_t)j;
  }
  fr_env_eval_smooth_batch(e, nb, bx, by, bz, le);
  for (size_t q = 0; q < nb; q++) eb->bg[bg[q]] = le[q], eb->seen[bg[q]] = 1;
  fr_env_texel_batch(e, ns, sx, sy, sz, tex, sin_t);
  for (size_t q = 0; q < ns; q++) {
    eb->sky[sky[q]] = tex[q], eb->sky_sin[sky[q]] = sin_t[q];
    __builtin_prefetch(tex[q]);
  }
  fr_env_sample_batch(e, c, u1, u2, dir, le, pdf);
  for (size_t q = 0; q < c; q++) {
    const size_t j = idx[q];
    eb->dir[j] = dir[q], eb->le[j] = le[q], eb->pdf[j] = pdf[q], eb->ready[j] = 1;
  }
}

/* The lanes' inputs for a block's hits: the ray and distance, the
 * geometric normal (a triangle's record, or p - c on a sphere), whether the
 * material is glass, and the shading normal where the mesh has one; mat[j]
 * the hit's material. A miss's lane gets any finite numbers. */
static void frames_gather(const fr_workload *w, const fr_ray *ray, const fr_hit *hit, size_t m, fr_path_frame_in *in,
                          int32_t *mat) {
  const fr_path_setup *P = w->path;
  for (size_t j = 0; j < m; j++) {
    const uint32_t prim = hit[j].prim;
    const vec3 o = v3_load(ray[j].org), d = v3_load(ray[j].dir);
    in->ox[j] = o.x, in->oy[j] = o.y, in->oz[j] = o.z, in->dx[j] = d.x, in->dy[j] = d.y, in->dz[j] = d.z;
    in->t[j] = hit[j].t;
    in->shading[j] = 0;
    float ng[3] = {0.0f, 0.0f, 1.0f}, sn[3] = {0.0f, 0.0f, 1.0f};
    mat[j] = 0;
    if (prim < P->nsurf) {
      const fr_surface *sf = &P->surf[prim];
      ng[0] = sf->ng[0], ng[1] = sf->ng[1], ng[2] = sf->ng[2];
      mat[j] = sf->mat;
      in->shading[j] = fr_scene_shading_normal(w->scene, prim, hit[j].u, hit[j].v, sn);
    } else if (prim != FR_INVALID_ID) { /* a sphere: the normal is p - c */
      const vec3 p = v3_add(o, v3_scale(d, hit[j].t));
      const float pp[3] = {p.x, p.y, p.z};
      fr_scene_geometric_normal(w->scene, prim, pp, ng);
      mat[j] = fr_surface_material(w->scene, prim, (int32_t)P->count - 1);
    }
    in->ax[j] = ng[0], in->ay[j] = ng[1], in->az[j] = ng[2];
    in->sx[j] = sn[0], in->sy[j] = sn[1], in->sz[j] = sn[2];
    in->glass[j] = P->mats[mat[j]].kind == FR_BSDF_GLASS;
  }
}

/* The frames of a block's hits, by the ISA's lanes. */
static void frames_make(const fr_path_frame_in *in, size_t m, fr_path_frames *f) {
  const fr_isa isa = fr_get_isa();
  if (isa == FR_ISA_AVX512) fr_path_frames_make_avx512(in, m, f);
  else if (isa == FR_ISA_AVX2) fr_path_frames_make_avx2(in, m, f);
  else fr_path_frames_make_scalar(in, m, f);
}

/* The paths k0 .. k0 + m - 1 of the wave: adds what a segment that ended
 * at the area light or in the sky brings; for those that hit a surface
 * makes their frames (S->frame, the states in S->bst, S->live), adds the
 * surface's emission and the first hit's AOVs. n: the wave's paths. */
static void frame_block(const fr_workload *w, const quad_light *quad, const env_block *eb, fr_path_scratch *S,
                        size_t k0, size_t m, size_t n, int depth) {
  const fr_path_setup *P = w->path;
  const fr_path_lights *L = &P->lights;
  const int nlights = light_count(L);
  fr_path_frames *f = &S->lanes;
  /* the next block's records and corner indices start loading while this
   * one is made */
  for (size_t k = k0 + m; k < k0 + 2 * m && k < n; k++) {
    const uint32_t prim = S->hit[k].prim;
    if (prim < P->nsurf) {
      __builtin_prefetch(&P->surf[prim]);
      fr_scene_prefetch_shading(w->scene, prim);
    }
  }
  frames_gather(w, S->ray + k0, S->hit + k0, m, &S->lanes_in, S->mat);
  frames_make(&S->lanes_in, m, f);
  for (size_t j = 0; j < m; j++) {
    const size_t k = k0 + j;
    S->live[j] = 0;
    path_state st = S->st[k];
    const fr_ray *r = &S->ray[k];
    const fr_hit h = S->hit[k];
    const vec3 o = v3_load(r->org), d = v3_load(r->dir);
    const int hit = h.prim != FR_INVALID_ID;
    /* the area light, which is not in the scene's geometry, in front of the hit */
    const float ta = L->area ? area_hit(quad, o, d, r->tnear, hit ? h.t : INFINITY) : 0.0f;
    if (ta > 0.0f) { /* the lamp: it emits from its front, its back is dark */
      if (depth == 0) S->dep[st.slot] = ta;
      if (v3_dot(d, quad->n) < 0.0f) {
        const float w_mis = st.delta ? 1.0f : power_heuristic(st.pdf, area_pdf(quad, d, ta) / (float)nlights);
        S->acc[st.slot] = v3_add(S->acc[st.slot], v3_scale(v3_mul(st.weight, quad->radiance), w_mis));
      }
      continue;
    }
    if (!hit) {
      float pe = 0.0f;
      const vec3 le = depth == 0   ? (eb->seen[j] ? eb->bg[j] : fr_env_eval_smooth(L->env, d)) /* the background */
                      : eb->sky[j] ? fr_env_texel_radiance(L->env, eb->sky[j], eb->sky_sin[j], st.delta ? NULL : &pe)
                      : st.delta   ? fr_env_eval(L->env, d)
                                   : fr_env_eval_pdf(L->env, d, &pe);
      const float w_mis = st.delta ? 1.0f : power_heuristic(st.pdf, pe / (float)nlights);
      S->acc[st.slot] = v3_add(S->acc[st.slot], v3_scale(v3_mul(st.weight, le), w_mis));
      continue;
    }
    hit_frame *fr = &S->frame[j];
    fr->p = v3(f->px[j], f->py[j], f->pz[j]);
    fr->ngo = v3(f->gx[j], f->gy[j], f->gz[j]);
    fr->n = v3(f->nx[j], f->ny[j], f->nz[j]);
    fr->t = v3(f->tx[j], f->ty[j], f->tz[j]);
    fr->b = v3(f->bx[j], f->by[j], f->bz[j]);
    fr->wo = v3(f->wx[j], f->wy[j], f->wz[j]);
    const fr_bsdf *mat = &P->mats[S->mat[j]];
    float st2[2];
    if (mat->color_tex >= 0 && fr_scene_texcoord(w->scene, h.prim, h.u, h.v, st2)) {
      S->textured[j] = *mat;
      S->textured[j].color = fr_texture_lookup(&P->textures[mat->color_tex], st2[0], st2[1]);
      mat = &S->textured[j];
    }
    fr->m = mat;
    const int front = f->front[j];
    if (mat->kind == FR_BSDF_GLASS && !front) { /* the segment ran inside: Beer's law */
      const float a_k = h.t / mat->attenuation_distance;
      const vec3 a = mat->attenuation_color;
      st.weight = v3_mul(st.weight, v3(powf(a.x, a_k), powf(a.y, a_k), powf(a.z, a_k)));
    }
    if (front && nonzero(mat->emission)) S->acc[st.slot] = v3_add(S->acc[st.slot], v3_mul(st.weight, mat->emission));
    fr_bsdf_prepare(mat, fr->p, &fr->sp);
    if (depth == 0) S->dep[st.slot] = h.t;
    if (depth == 0 && (w->gbuf_albedo || w->gbuf_normal)) {
      S->alb[st.slot] = v3_add(S->alb[st.slot], fr_bsdf_albedo(mat));
      S->nrm[st.slot] = v3_add(S->nrm[st.slot], v3_dot(fr->n, d) < 0.0f ? fr->n : v3_scale(fr->n, -1.0f)); /* facing the camera */
    }
    S->bst[j] = st;
    S->live[j] = 1;
  }
}

/* Next-event estimation for the block's live paths: a light sample each
 * (dimension pair dim + 0 picks the light, dim + 1 places the sample),
 * its contribution and shadow ray appended at S->scontrib, S->sray and
 * S->spix[*ns]; with point_apart, a sample of the point light goes as its
 * hit point to S->ppts, S->pcontrib and S->ppix[*np] instead (the same
 * segment, which fr_path_tile traces from the light). */
static void next_events(const fr_workload *w, const quad_light *quad, const env_block *eb,
                        const float (*pts)[POINT_BLOCK], fr_path_scratch *S, size_t m, uint32_t dim, int point_apart,
                        size_t *ns, size_t *np) {
  const fr_path_setup *P = w->path;
  const fr_path_lights *L = &P->lights;
  if (!light_count(L)) return;
  for (size_t j = 0; j < m; j++) {
    if (!S->live[j]) continue;
    const path_state *st = &S->bst[j];
    const hit_frame *f = &S->frame[j];
    if (!fr_bsdf_has_smooth(f->m, &f->sp)) continue;
    float uc, ul, u1, u2;
    path_point(P, pts, j, st, dim, 0, &uc, &ul);
    path_point(P, pts, j, st, dim, 1, &u1, &u2);
    vec3 wi, le;
    float dist, pl;
    int delta;
    if (sample_light(L, quad, eb, j, f->p, uc, u1, u2, &wi, &dist, &le, &pl, &delta) && same_side(wi, f->n, f->ngo)) {
      float pb;
      const vec3 fv = fr_bsdf_eval(f->m, &f->sp, f->wo, to_local(wi, f->t, f->b, f->n), &pb);
      if (nonzero(fv) && nonzero(le)) {
        const float w_mis = delta ? 1.0f : power_heuristic(pl, pb);
        const vec3 contrib = v3_scale(v3_mul(v3_mul(st->weight, fv), le), w_mis / pl);
        if (point_apart && delta) { /* only the point light is a delta light */
          float *q = S->ppts + 3 * *np;
          q[0] = f->p.x, q[1] = f->p.y, q[2] = f->p.z;
          S->pcontrib[*np] = contrib;
          S->ppix[(*np)++] = st->slot;
          continue;
        }
        S->scontrib[*ns] = contrib;
        S->sray[*ns] = make_ray(f->p, wi, w->eps, isinf(dist) ? INFINITY : dist * (1.0f - 1e-4f));
        S->spix[(*ns)++] = st->slot;
      }
    }
  }
}

/* The next segment of the block's live paths: a BSDF sample each (pair
 * dim + 0's second number picks the lobe, dim + 2 the direction), Russian
 * roulette (dim + 3), and the survivors' states and rays written at
 * S->st[*nn] and S->ray[*nn], never past the block's first path. */
static void continue_paths(const fr_workload *w, const float (*pts)[POINT_BLOCK], fr_path_scratch *S, size_t m,
                           uint32_t dim, int depth, size_t *nn) {
  const fr_path_setup *P = w->path;
  for (size_t j = 0; j < m; j++) {
    if (!S->live[j]) continue;
    path_state st = S->bst[j];
    const hit_frame *f = &S->frame[j];
    float uc, ul, v1, v2, ur, unused;
    path_point(P, pts, j, &st, dim, 0, &uc, &ul);
    path_point(P, pts, j, &st, dim, 2, &v1, &v2);
    fr_bsdf_sample bs;
    if (!fr_bsdf_sample_dir(f->m, &f->sp, f->wo, ul, v1, v2, &bs)) continue;
    const vec3 wi = to_world(bs.wi, f->t, f->b, f->n);
    if (!same_side(wi, f->n, f->ngo)) continue; /* through the surface by the shading normal alone: a leak */
    st.weight = v3_mul(st.weight, bs.weight);
    const float q = fr_maxf(st.weight.x, fr_maxf(st.weight.y, st.weight.z)) / FR_PATH_RR_WEIGHT;
    if (q < 1.0f) {
      path_point(P, pts, j, &st, dim, 3, &ur, &unused);
      if (!(ur < q)) continue;
      st.weight = v3_scale(st.weight, 1.0f / q);
    }
    st.pdf = bs.pdf;
    st.delta = (uint8_t)bs.delta;
    st.depth = (uint8_t)(depth + 1);
    S->st[*nn] = st;
    S->ray[(*nn)++] = make_ray(f->p, wi, w->eps, INFINITY);
  }
}

/* Pixel i of a tile of the given side, in blocks of 4x4 (consecutive 16
 * are coherent). */
static void tile_pixel(int i, int side, int *x, int *y) {
  const int b = i / 16, k = i % 16, per_row = side / 4;
  *x = 4 * (b % per_row) + k % 4;
  *y = 4 * (b / per_row) + k / 4;
}

int fr_path_tile_side(const fr_path_setup *P) {
  const int spp = P->spp_end - P->spp_begin;
  return spp <= 2 ? SIDE_MAX : TILE;
}
_Static_assert(TILE <= SIDE_MAX, "a tile's pixels fit the scratch");

/* The camera rays of paths st[0..n) (their first segments) into ray, a
 * block at a time as vector code: pair 0 places each sample in its pixel,
 * pair 1 on the lens. */
static void camera_rays(const fr_workload *w, fr_path_scratch *S, const path_state *st, size_t n, int npix,
                        float (*block)[POINT_BLOCK], fr_ray *ray) {
  const fr_path_setup *P = w->path;
  const fr_camera *c = &w->cam;
  const vec3 ru = v3_norm(c->right), uu = v3_norm(c->up);
  const fr_path_camera cam = {{c->eye.x, c->eye.y, c->eye.z}, {c->fwd.x, c->fwd.y, c->fwd.z},
                              {c->right.x, c->right.y, c->right.z}, {c->up.x, c->up.y, c->up.z},
                              {ru.x, ru.y, ru.z}, {uu.x, uu.y, uu.z}, (float)c->width, (float)c->height,
                              P->aperture, P->focus};
  const int lens = P->aperture > 0.0f, batches = fr_sampler_batches(P->sampler, (uint32_t)P->spp);
  const fr_isa isa = fr_get_isa();
  for (size_t k0 = 0; k0 < n; k0 += POINT_BLOCK) {
    const size_t m = n - k0 < POINT_BLOCK ? n - k0 : POINT_BLOCK;
    float x[POINT_BLOCK], y[POINT_BLOCK];
    if (batches) block_points(P, st + k0, m, 0, 1 + lens, block);
    for (size_t j = 0; j < m; j++) {
      const path_state *p = &st[k0 + j];
      const int i = p->slot % npix;
      x[j] = S->pix_x[i], y[j] = S->pix_y[i];
      if (!batches)
        for (int q = 0; q <= lens; q++) path_point(P, NULL, j, p, 0, q, &block[2 * q][j], &block[2 * q + 1][j]);
    }
    const float *lx = lens ? block[2] : NULL, *ly = lens ? block[3] : NULL;
    if (isa == FR_ISA_AVX512) fr_path_camera_rays_avx512(&cam, m, x, y, block[0], block[1], lx, ly, ray + k0);
    else if (isa == FR_ISA_AVX2) fr_path_camera_rays_avx2(&cam, m, x, y, block[0], block[1], lx, ly, ray + k0);
    else fr_path_camera_rays_scalar(&cam, m, x, y, block[0], block[1], lx, ly, ray + k0);
  }
}

uint64_t fr_path_tile(const fr_workload *w, const fr_tracer *t, fr_path_scratch *S, int tx, int ty) {
  const fr_path_setup *P = w->path;
  const fr_path_lights *L = &P->lights;
  const fr_camera *c = &w->cam;
  const int W = c->width, H = c->height;
  const uint32_t seed = P->seed;
  const quad_light quad = quad_light_of(L);
  uint64_t rays = 0;
  const int side = fr_path_tile_side(P), npix = side * side, chunk = WAVE / npix;
  for (int i = 0; i < npix; i++) {
    int x, y;
    tile_pixel(i, side, &x, &y);
    x += tx, y += ty;
    S->pix_in[i] = x < W && y < H;
    S->pix_x[i] = (float)x, S->pix_y[i] = (float)y;
    S->pix_key[i] = fr_sampler_pixel_key(seed, (uint32_t)y * (uint32_t)W + (uint32_t)x);
  }
  float block[8][POINT_BLOCK];
  env_block eb;
  const int batches = fr_sampler_batches(P->sampler, (uint32_t)P->spp);
  const float(*pts)[POINT_BLOCK] = batches ? (const float(*)[POINT_BLOCK])block : NULL;
  for (int s0 = P->spp_begin; s0 < P->spp_end; s0 += chunk) {
    const int s1 = s0 + chunk < P->spp_end ? s0 + chunk : P->spp_end;
    double t0 = fr_seconds();
    const size_t nslot = (size_t)(s1 - s0) * (size_t)npix;
    memset(S->acc, 0, nslot * sizeof S->acc[0]);
    memset(S->alb, 0, nslot * sizeof S->alb[0]);
    memset(S->nrm, 0, nslot * sizeof S->nrm[0]);
    for (size_t k = 0; k < nslot; k++) S->dep[k] = FR_PATH_DEPTH_MISS;
    size_t n = 0;
    for (int s = s0; s < s1; s++)
      for (int i = 0; i < npix; i++)
        if (S->pix_in[i])
          S->st[n++] = (path_state){v3(1, 1, 1), 0.0f, (uint32_t)s, S->pix_key[i], (uint16_t)((s - s0) * npix + i), 1, 0};
    camera_rays(w, S, S->st, n, npix, block, S->ray);
    for (int depth = 0; n; depth++) {
      double t1 = fr_seconds();
      S->stage[FR_STAGE_SHADE] += t1 - t0;
      t->intersect(t->ctx, S->ray, S->hit, n, depth == 0);
      rays += n;
      double t2 = fr_seconds();
      S->stage[depth ? FR_STAGE_SECONDARY : FR_STAGE_CAMERA] += t2 - t1;
      size_t nn = 0, ns = 0, np = 0;
      const uint32_t dim = 2u + 4u * (uint32_t)depth;
      /* The camera hits' shadow rays to a point light end at one point, in
       * the 4x4 blocks the camera rays came in: 16 make a frustum from the
       * light (render/shadow_frusta.h), as the Whitted renderer's. Later
       * bounces' hits lie scattered, and their rays go as rays. */
      const int point_apart = t->occluded_frusta && L->point && depth == 0;
      for (size_t k0 = 0; k0 < n; k0 += POINT_BLOCK) {
        const size_t m = n - k0 < POINT_BLOCK ? n - k0 : POINT_BLOCK;
        if (pts) block_points(P, S->st + k0, m, dim, 4, block);
        env_block_sample(P, pts, S->st + k0, S->ray + k0, S->hit + k0, m, dim, &eb);
        frame_block(w, &quad, &eb, S, k0, m, n, depth);
        next_events(w, &quad, &eb, pts, S, m, dim, point_apart, &ns, &np);
        if (depth + 1 < P->max_depth) continue_paths(w, pts, S, m, dim, depth, &nn);
      }
      double t3 = fr_seconds();
      S->stage[FR_STAGE_SHADE] += t3 - t2;
      if (ns) {
        t->occluded(t->ctx, S->sray, S->occ, ns, 0);
        rays += ns;
        add_unoccluded(S->acc, S->occ, S->spix, S->scontrib, ns);
      }
      if (np) { /* a path has one light sample a bounce: its slot is in one list or the other */
        const float light[3] = {L->point_pos.x, L->point_pos.y, L->point_pos.z};
        const fr_shadow_rays src = {NULL, light, S->ppts, w->eps};
        fr_shadow_frusta_occluded(t, &src, S->occ, np, 1);
        rays += np;
        add_unoccluded(S->acc, S->occ, S->ppix, S->pcontrib, np);
      }
      t0 = fr_seconds();
      S->stage[FR_STAGE_SHADOW] += t0 - t3;
      n = nn;
    }
    for (int i = 0; i < npix; i++) {
      int x, y;
      tile_pixel(i, side, &x, &y);
      x += tx, y += ty;
      if (x >= W || y >= H) continue;
      const size_t px = (size_t)y * (size_t)W + (size_t)x, o = 3 * px;
      for (int s = 0; s < s1 - s0; s++) {
        const size_t k = (size_t)s * (size_t)npix + (size_t)i;
        if (w->image) add3(w->image + o, S->acc[k]);
        if (w->gbuf_albedo) add3(w->gbuf_albedo + o, S->alb[k]);
        if (w->gbuf_normal) add3(w->gbuf_normal + o, S->nrm[k]);
        if (w->gbuf_depth) w->gbuf_depth[px] += S->dep[k];
      }
    }
  }
  return rays;
}
