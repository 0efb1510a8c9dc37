/* The public scene API: creation, commit (BVH build), queries and tracing. */
#include "scene.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "accel/bvh_presplit.h"
#include "base/alloc.h"
#include "base/error.h"
#include "base/timer.h"
#include "base/tuning.h"
#include "geom/builtin_scene.h"
#include "io/file_read.h"
#include "io/import.h"
#include "io/scene_file.h"
#include "trace/bvh2_reference.h"
#include "trace/kernels.h"
#include "trace/sphere_traverse.h"
#include "accel/sphere_bvh.h"

static fr_scene *scene_new(void) {
  fr_scene *s = calloc(1, sizeof *s);
  if (!s) return NULL;
  fr_mesh_init(&s->mesh);
  fr_env_tuning env;
  fr_env_tuning_read(&env);
  s->single_width = env.bvh_width;
  fr_tuning_default(&s->trace);
  return s;
}

void fr_scene_apply_prefetch(fr_scene *s) {
  fr_bvhn *b[2] = {&s->bvh4, &s->bvh8};
  for (int i = 0; i < 2; i++) {
    b[i]->prefetch = s->trace.prefetch < 0 ? fr_bvhn_prefetch_auto(b[i]) : s->trace.prefetch;
    b[i]->packet_prefetch = s->trace.prefetch < 0 ? fr_bvhn_packet_prefetch_auto(b[i]) : s->trace.prefetch;
  }
}

fr_error fr_scene_set_tuning(fr_scene *s, const fr_tuning *t) {
  if (!s || !t) return fr_fail(FR_ERR_ARG, "fr_scene_set_tuning: NULL argument");
  fr_error e = fr_tuning_check(t);
  if (e) return e;
  if (t->packet_bvh_width == 4 && (e = fr_scene_need_bvh4(s))) return e;
  s->trace = *t;
  fr_scene_apply_prefetch(s);
  return FR_OK;
}

void fr_scene_get_tuning(const fr_scene *s, fr_tuning *t) { *t = s->trace; }

fr_error fr_scene_set_trace_mode(fr_scene *s, fr_trace_mode mode) {
  if (!s) return fr_fail(FR_ERR_ARG, "fr_scene_set_trace_mode: NULL scene");
  if (mode < FR_TRACE_AUTO || mode > FR_TRACE_RAYSTREAM) return fr_fail(FR_ERR_ARG, "unknown trace mode %d", (int)mode);
  s->trace.mode = mode;
  return FR_OK;
}

fr_trace_mode fr_scene_get_trace_mode(const fr_scene *s) { return s ? s->trace.mode : FR_TRACE_AUTO; }

fr_error fr_scene_set_bvh_width(fr_scene *s, int width) {
  if (!s || (width != 4 && width != 8)) return fr_fail(FR_ERR_ARG, "BVH width must be 4 or 8");
  if (width == 4) {
    fr_error e = fr_scene_need_bvh4(s);
    if (e) return e;
  }
  s->single_width = width;
  return FR_OK;
}

/* The scene's name: its folder for files in a folder named after it
 * (../shared/scenes/spd_balls/balls.ply.zst -> spd_balls), else the file name
 * without extensions. */
static void scene_name(const char *path, char *out, size_t cap) {
  char buf[4096];
  snprintf(buf, sizeof buf, "%s", path);
  char *slash = strrchr(buf, '/');
  char *file = slash ? slash + 1 : buf;
  char *dot = strchr(file, '.');
  if (dot) *dot = 0;
  if (slash) {
    *slash = 0;
    char *pslash = strrchr(buf, '/');
    const char *dir = pslash ? pslash + 1 : buf;
    size_t fl = strlen(file), dl = strlen(dir);
    if (dl >= fl && strcmp(dir + dl - fl, file) == 0) { snprintf(out, cap, "%s", dir); return; }
  }
  snprintf(out, cap, "%s", file);
}

/* Appends mesh `add` (scaled and moved) to m, its materials merged by
 * name, or all of its triangles given the material `only` (if not empty). */
static fr_error append_mesh(fr_mesh *m, const fr_mesh *add, vec3 scale, vec3 move, const char *only) {
  if (add->nverts > UINT32_MAX - m->nverts) return fr_fail(FR_ERR_UNSUPPORTED, "too many vertices");
  const uint32_t base = (uint32_t)m->nverts;
  fr_error e = FR_OK;
  uint32_t *remap = calloc(add->nmats + 1, sizeof *remap), only_id = FR_INVALID_ID;
  if (!remap) return fr_fail(FR_ERR_NOMEM, "out of memory");
  for (size_t i = 0; i < add->nmats && !e; i++) {
    const size_t before = m->nmats;
    e = fr_mesh_material(m, add->mats[i].name, &remap[i]);
    if (!e && m->nmats > before) m->mats[remap[i]] = add->mats[i]; /* new here: the file's parameters */
  }
  if (!e && only && only[0]) e = fr_mesh_material(m, only, &only_id);
  for (size_t v = 0; v < add->nverts && !e; v++) {
    const float *p = add->pos + 3 * v;
    e = fr_mesh_add_vertex(m, p[0] * scale.x + move.x, p[1] * scale.y + move.y, p[2] * scale.z + move.z);
  }
  const uint32_t nbase = (uint32_t)m->nrm.n, tbase = (uint32_t)m->uv.n;
  for (size_t i = 0; i < add->nrm.n && !e; i++) { /* a normal scales by the inverse */
    const float *n = add->nrm.val + 3 * i;
    e = fr_mesh_add_normal(m, n[0] / scale.x, n[1] / scale.y, n[2] / scale.z);
  }
  for (size_t i = 0; i < add->uv.n && !e; i++) e = fr_mesh_add_uv(m, add->uv.val[2 * i], add->uv.val[2 * i + 1]);
  for (size_t t = 0; t < add->ntris && !e; t++) {
    const uint32_t *ix = add->idx + 3 * t, am = add->mat ? add->mat[t] : FR_INVALID_ID;
    const uint32_t mat = only_id != FR_INVALID_ID ? only_id : am < add->nmats ? remap[am] : FR_INVALID_ID;
    e = fr_mesh_add_triangle(m, ix[0] + base, ix[1] + base, ix[2] + base, mat);
    if (!e && fr_mesh_has_normals(add, t)) {
      const uint32_t *nx = add->nrm.idx + 3 * t;
      e = fr_mesh_set_normals(m, m->ntris - 1, nx[0] + nbase, nx[1] + nbase, nx[2] + nbase);
    }
    if (!e && fr_mesh_has_uvs(add, t)) {
      const uint32_t *tx = add->uv.idx + 3 * t;
      e = fr_mesh_set_uvs(m, m->ntris - 1, tx[0] + tbase, tx[1] + tbase, tx[2] + tbase);
    }
  }
  free(remap);
  return e;
}

fr_error fr_scene_load_json(const char *path, const char *root, fr_scene **out) {
  *out = NULL;
  fr_scene_file f;
  fr_error e = fr_scene_file_read(path, root, &f);
  if (e) return e;
  fr_scene *s = scene_new();
  if (!s) { fr_scene_file_free(&f); return fr_fail(FR_ERR_NOMEM, "out of memory"); }
  for (int i = 0; i < f.nmeshes && !e; i++) {
    fr_mesh m;
    fr_mesh_init(&m);
    e = fr_import(f.meshes[i].path, &m);
    if (!e) e = append_mesh(&s->mesh, &m, f.meshes[i].scale, f.meshes[i].translate, f.meshes[i].material);
    fr_mesh_free(&m);
  }
  if (!e) e = fr_mesh_validate(&s->mesh, path);
  if (!e && !(s->file = malloc(sizeof *s->file))) e = fr_fail(FR_ERR_NOMEM, "out of memory");
  if (e) { fr_scene_release(s); fr_scene_file_free(&f); return e; }
  scene_name(path, s->name, sizeof s->name);
  free(f.meshes); /* in the scene now */
  f.meshes = NULL, f.nmeshes = 0;
  *s->file = f;
  *out = s;
  return FR_OK;
}

fr_error fr_scene_load(const char *path, fr_scene **out) {
  if (!out) return fr_fail(FR_ERR_ARG, "fr_scene_load: out is NULL");
  *out = NULL;
  if (path && fr_has_suffix(path, ".json")) return fr_scene_load_json(path, NULL, out);
  fr_scene *s = scene_new();
  if (!s) return fr_fail(FR_ERR_NOMEM, "out of memory");
  fr_error e = fr_import(path, &s->mesh);
  if (e) { fr_scene_release(s); return e; }
  scene_name(path, s->name, sizeof s->name);
  *out = s;
  return FR_OK;
}

fr_error fr_scene_smooth(fr_scene *s, float crease_deg) {
  if (!s) return fr_fail(FR_ERR_ARG, "fr_scene_smooth: scene is NULL");
  if (s->committed) return fr_fail(FR_ERR_STATE, "fr_scene_smooth: scene already committed");
  if (!(crease_deg >= 0.0f && crease_deg <= 180.0f)) return fr_fail(FR_ERR_ARG, "crease angle %g is not in [0, 180]", crease_deg);
  return fr_mesh_smooth_normals(&s->mesh, crease_deg);
}

int fr_scene_shading_normal(const fr_scene *s, uint32_t prim, float u, float v, float n[3]) {
  const fr_mesh *m = &s->mesh;
  if (!m->nrm.idx || prim >= m->ntris) return 0;
  const uint32_t *ix = m->nrm.idx + 3 * (size_t)prim;
  if (ix[0] >= m->nrm.n || ix[1] >= m->nrm.n || ix[2] >= m->nrm.n) return 0; /* FR_INVALID_ID: none */
  const float *a = m->nrm.val + 3 * (size_t)ix[0], *b = m->nrm.val + 3 * (size_t)ix[1], *c = m->nrm.val + 3 * (size_t)ix[2];
  const float w = 1.0f - u - v;
  const float x = w * a[0] + u * b[0] + v * c[0], y = w * a[1] + u * b[1] + v * c[1], z = w * a[2] + u * b[2] + v * c[2];
  const float l2 = x * x + y * y + z * z;
  if (!(l2 > 1e-12f)) return 0; /* zero corners (none given) or opposite ones */
  const float r = 1.0f / sqrtf(l2);
  n[0] = x * r, n[1] = y * r, n[2] = z * r;
  return 1;
}

int fr_scene_texcoord(const fr_scene *s, uint32_t prim, float u, float v, float st[2]) {
  const fr_mesh *m = &s->mesh;
  if (prim >= m->ntris || !fr_mesh_has_uvs(m, prim)) return 0;
  const uint32_t *ix = m->uv.idx + 3 * (size_t)prim;
  const float *a = m->uv.val + 2 * (size_t)ix[0], *b = m->uv.val + 2 * (size_t)ix[1], *c = m->uv.val + 2 * (size_t)ix[2];
  const float w = 1.0f - u - v;
  st[0] = w * a[0] + u * b[0] + v * c[0];
  st[1] = w * a[1] + u * b[1] + v * c[1];
  return 1;
}

fr_error fr_scene_builtin(fr_scene **out) {
  if (!out) return fr_fail(FR_ERR_ARG, "fr_scene_builtin: out is NULL");
  *out = NULL;
  fr_scene *s = scene_new();
  if (!s) return fr_fail(FR_ERR_NOMEM, "out of memory");
  fr_error e = fr_builtin_scene(&s->mesh);
  if (!e) e = fr_mesh_validate(&s->mesh, "builtin");
  if (e) { fr_scene_release(s); return e; }
  snprintf(s->name, sizeof s->name, "builtin");
  *out = s;
  return FR_OK;
}

fr_error fr_scene_from_arrays(const float *xyz, size_t nverts, const uint32_t *idx, size_t ntris, fr_scene **out) {
  return fr_scene_from_buffers(xyz, nverts, 0, idx, ntris, 0, 0, out);
}

fr_error fr_scene_from_buffers(const float *positions, size_t nverts, size_t vertex_stride, const uint32_t *indices,
                               size_t ntris, size_t index_stride, unsigned flags, fr_scene **out) {
  if (!out || (!positions && nverts) || (!indices && ntris))
    return fr_fail(FR_ERR_ARG, "fr_scene_from_buffers: NULL array");
  *out = NULL;
  const size_t vs = vertex_stride ? vertex_stride : 3 * sizeof(float);
  const size_t is = index_stride ? index_stride : 3 * sizeof(uint32_t);
  if (vs < 3 * sizeof(float) || vs % sizeof(float) || is < 3 * sizeof(uint32_t) || is % sizeof(uint32_t))
    return fr_fail(FR_ERR_ARG, "fr_scene_from_buffers: strides %zu and %zu bytes are not whole records of at least "
                   "3 floats and 3 indices", vs, is);
  if (flags & ~(unsigned)FR_SHARE_BUFFERS) return fr_fail(FR_ERR_ARG, "fr_scene_from_buffers: unknown flags 0x%x", flags);
  const int share = (flags & FR_SHARE_BUFFERS) != 0;
  if (share && (vs != 3 * sizeof(float) || is != 3 * sizeof(uint32_t)))
    return fr_fail(FR_ERR_ARG, "fr_scene_from_buffers: shared buffers must be tightly packed (strides 12 and 12)");
  fr_scene *s = scene_new();
  if (!s) return fr_fail(FR_ERR_NOMEM, "out of memory");
  fr_error e = FR_OK;
  if (share) {
    s->mesh.borrowed = 1;
    s->mesh.pos = (float *)positions; /* read only: the scene never writes to a borrowed mesh */
    s->mesh.nverts = nverts;
    s->mesh.idx = (uint32_t *)indices;
    s->mesh.ntris = ntris;
  } else {
    const unsigned char *pv = (const unsigned char *)positions, *pi = (const unsigned char *)indices;
    for (size_t i = 0; i < nverts && !e; i++) {
      const float *v = (const float *)(pv + i * vs);
      e = fr_mesh_add_vertex(&s->mesh, v[0], v[1], v[2]);
    }
    for (size_t i = 0; i < ntris && !e; i++) {
      const uint32_t *t = (const uint32_t *)(pi + i * is);
      e = fr_mesh_add_triangle(&s->mesh, t[0], t[1], t[2], FR_INVALID_ID);
    }
  }
  if (!e) e = fr_mesh_validate(&s->mesh, "arrays");
  if (e) { fr_scene_release(s); return e; }
  snprintf(s->name, sizeof s->name, "arrays");
  *out = s;
  return FR_OK;
}

fr_error fr_scene_new(fr_scene **out) {
  if (!out) return fr_fail(FR_ERR_ARG, "fr_scene_new: out is NULL");
  *out = scene_new();
  if (!*out) return fr_fail(FR_ERR_NOMEM, "out of memory");
  snprintf((*out)->name, sizeof (*out)->name, "api");
  return FR_OK;
}

fr_error fr_scene_builtin_sphereflake(int depth, fr_scene **out) {
  if (!out) return fr_fail(FR_ERR_ARG, "fr_scene_builtin_sphereflake: out is NULL");
  *out = NULL;
  if (depth < 0 || depth > 5) return fr_fail(FR_ERR_ARG, "sphereflake depth %d (0..5)", depth);
  fr_scene *s = scene_new();
  if (!s) return fr_fail(FR_ERR_NOMEM, "out of memory");
  fr_error e = fr_builtin_sphereflake(depth, &s->mesh, &s->spheres);
  if (e) { fr_scene_release(s); return e; }
  snprintf(s->name, sizeof s->name, "sphereflake");
  *out = s;
  return FR_OK;
}

fr_error fr_scene_builtin_materials(fr_scene **out) {
  if (!out) return fr_fail(FR_ERR_ARG, "fr_scene_builtin_materials: out is NULL");
  *out = NULL;
  fr_scene *s = scene_new();
  if (!s) return fr_fail(FR_ERR_NOMEM, "out of memory");
  fr_error e = fr_builtin_materials(&s->mesh, &s->spheres);
  if (e) { fr_scene_release(s); return e; }
  snprintf(s->name, sizeof s->name, "materials");
  *out = s;
  return FR_OK;
}

void fr_scene_release(fr_scene *s) {
  if (!s) return;
  fr_mesh_free(&s->mesh);
  fr_spheres_free(&s->spheres);
  fr_bvh2_free(&s->sphere_bvh);
  fr_bvh2_free(&s->bvh2_mft);
  fr_bvh2_free(&s->bvh2);
  fr_bvhn_free(&s->bvh4);
  fr_bvhn_free(&s->bvh8);
  fr_plane_occluders_free(&s->planes);
  if (s->file) fr_scene_file_free(s->file);
  free(s->file);
  free(s);
}

const fr_bsdf *fr_scene_file_bsdf(const fr_scene *s, const char *name) {
  return s && s->file && name ? fr_scene_file_find_material(s->file, name) : NULL;
}

/* The SAH tree over the non-degenerate triangles (n of them); sets s->bounds. */
static fr_error build_tree(fr_scene *s, fr_build_tree *tree, size_t *count) {
  const fr_mesh *m = &s->mesh;
  if (m->ntris >= FR_TRI4_THIN) /* ids share a word with the thin flag (accel/bvhn.h) */
    return fr_fail(FR_ERR_UNSUPPORTED, "%s: %zu triangles; frusta traces fewer than 2^31", s->name, m->ntris);
  aabb *boxes = fr_alloc_aligned(fr_mul_size(m->ntris, sizeof(aabb)), 64); /* owned by fr_presplit too */
  uint32_t *ids = fr_alloc_aligned(fr_mul_size(m->ntris, sizeof(uint32_t)), 64);
  if (!boxes || !ids) { fr_free_aligned(boxes); fr_free_aligned(ids); return fr_fail(FR_ERR_NOMEM, "out of memory for %zu triangles", m->ntris); }
  size_t n = 0;
  s->bounds = aabb_empty();
  /* Beyond FR_MAX_COORDINATE the kernels' products of coordinate
   * differences lose the hits: such a scene is refused rather than traced
   * wrongly. */
  float reach = 0.0f;
  for (size_t t = 0; t < m->ntris; t++) {
    if (fr_mesh_triangle_degenerate(m, t)) continue;
    for (int k = 0; k < 3; k++)
      for (int a = 0; a < 3; a++) reach = fmaxf(reach, fabsf(m->pos[3 * (size_t)m->idx[3 * t + k] + a]));
    if (!fr_mesh_triangle_resolvable(m, t)) continue;
    aabb b = aabb_empty();
    for (int k = 0; k < 3; k++) b = aabb_grow(b, v3_load(m->pos + 3 * (size_t)m->idx[3 * t + k]));
    boxes[n] = b;
    ids[n++] = (uint32_t)t;
    s->bounds = aabb_merge(s->bounds, b);
  }
  *count = n;
  if (!(reach <= FR_MAX_COORDINATE)) {
    fr_free_aligned(boxes);
    fr_free_aligned(ids);
    return fr_fail(FR_ERR_UNSUPPORTED, "%s: coordinates up to %g; frusta traces scenes within %g of the origin", s->name,
                   (double)reach, (double)FR_MAX_COORDINATE);
  }
  if (n == 0 && s->spheres.n == 0) {
    fr_free_aligned(boxes);
    fr_free_aligned(ids);
    return fr_fail(FR_ERR_FORMAT, "%s: %s", s->name,
                   m->ntris ? "every triangle is degenerate or too small to trace" : "no triangles and no spheres");
  }
  /* FRUSTA_PRESPLIT=off|on overrides the choice (below), for measurements
   * and tests */
  fr_env_tuning env;
  fr_env_tuning_read(&env);
  const int off = env.presplit == 0, on = env.presplit == 1;
  fr_error e = fr_build_sah(boxes, ids, n, tree);
  size_t refs = n;
  /* Keep the presplit tree only where it wins clearly: its duplicated
   * references cost memory and build time (docs/design.md, "Presplitting").
   * Running out of memory on the way just keeps the plain tree. */
  if (!e && !off &&
      fr_presplit(m, s->bounds, FR_PRESPLIT_BUDGET, on ? 0.0 : FR_PRESPLIT_MIN_SHARE, &boxes, &ids, &refs) == FR_OK &&
      refs != n) {
    fr_build_tree split;
    if (fr_build_sah(boxes, ids, refs, &split) == FR_OK) {
      if (on || fr_build_tree_sah(&split) < FR_PRESPLIT_MIN_GAIN * fr_build_tree_sah(tree)) {
        fr_build_tree_free(tree);
        *tree = split;
      } else {
        fr_build_tree_free(&split);
      }
    }
  }
  fr_free_aligned(boxes);
  fr_free_aligned(ids);
  return e;
}

fr_error fr_scene_build_bvh2(fr_scene *s, int max_leaf, fr_bvh2 *out) {
  if (!s || !s->committed) return fr_fail(FR_ERR_ARG, "fr_scene_build_bvh2: scene not committed");
  fr_build_tree tree;
  size_t n;
  fr_error e = build_tree(s, &tree, &n);
  if (e) return e;
  e = fr_bvh2_from_build(&tree, &s->mesh, max_leaf, out);
  fr_build_tree_free(&tree);
  return e;
}

/* The BVH4 serves only the MIC paper's 4-wide modes (single4, packets on a
 * BVH4), so it is built when one is asked for (FRUSTA_BVH_WIDTH=4 or set
 * before the commit, fr_scene_set_bvh_width or packet_bvh_width later):
 * it was a third of the conversions' time and, with its Shevtsov
 * records, 89-106 bytes per triangle that the default modes never read. */
static int wants_bvh4(const fr_scene *s) { return s->single_width == 4 || s->trace.packet_bvh_width == 4; }

/* The traversal structures, all made from one tree and independent of each
 * other but for the multi-frusta tree, a copy cut from the binary one. Each
 * conversion is serial, so two threads share them: the BVH8 (single rays
 * and packets) on one, the rest on the other. In a row they took 57% of
 * conference's commit and 59% of dragon's. An error is raised again on the
 * calling thread, whose message is the one fr_last_error reads. */
static fr_error convert_tree(fr_scene *s, const fr_build_tree *tree) {
  const fr_mesh *m = &s->mesh;
  fr_error e[2] = {FR_OK, FR_OK};
  char msg[2][256] = {"", ""};
#pragma omp parallel sections
  {
#pragma omp section
    {
      e[0] = fr_bvhn_from_build(tree, m, 8, &s->bvh8);
      if (e[0]) snprintf(msg[0], sizeof msg[0], "%s", fr_last_error());
    }
#pragma omp section
    {
      e[1] = fr_bvh2_from_build(tree, m, FR_BUILD_MAX_LEAF, &s->bvh2);
      if (!e[1]) e[1] = fr_bvh2_shallow(tree, &s->bvh2, FR_MFT_LEAF, &s->bvh2_mft);
      if (!e[1] && wants_bvh4(s)) e[1] = fr_bvhn_from_build(tree, m, 4, &s->bvh4);
      if (!e[1]) e[1] = fr_sphere_bvh_build(&s->spheres, &s->sphere_bvh);
      if (e[1]) snprintf(msg[1], sizeof msg[1], "%s", fr_last_error());
    }
  }
  for (int i = 0; i < 2; i++)
    if (e[i]) return fr_fail(e[i], "%s", msg[i]);
  return FR_OK;
}

/* What a commit that failed after convert_tree had built. */
static void free_trees(fr_scene *s) {
  fr_bvh2_free(&s->bvh2_mft); fr_bvh2_free(&s->bvh2); fr_bvhn_free(&s->bvh4); fr_bvhn_free(&s->bvh8); fr_bvh2_free(&s->sphere_bvh);
}

fr_error fr_scene_commit(fr_scene *s) {
  if (!s) return fr_fail(FR_ERR_ARG, "fr_scene_commit: scene is NULL");
  if (s->committed) return FR_OK;
  double t0 = fr_seconds();
  const fr_mesh *m = &s->mesh;
  fr_build_tree tree;
  size_t n;
  fr_error e = build_tree(s, &tree, &n);
  if (e) return e;
  s->skipped = m->ntris - n;
  e = convert_tree(s, &tree);
  fr_build_tree_free(&tree);
  if (e) {
    free_trees(s);
    return e;
  }
  /* FRUSTA_PLANES=off leaves them out, for measurements */
  fr_env_tuning env;
  fr_env_tuning_read(&env);
  if (env.planes) {
    e = fr_plane_occluders_find(m, &s->planes);
    if (e) {
      free_trees(s);
      return e;
    }
  }
  s->bvh2.planes = s->bvh8.planes = s->bvh4.planes = s->planes.n ? &s->planes : NULL;
  s->bounds = aabb_merge(s->bounds, s->sphere_bvh.bounds);
  s->build_seconds = fr_seconds() - t0;
  s->committed = 1;
  fr_scene_apply_prefetch(s);
  return FR_OK;
}

/* Builds the BVH4 of a committed scene if it has none: the SAH tree again
 * (the same tree: the build is deterministic), then its 4-wide layout. */
fr_error fr_scene_need_bvh4(fr_scene *s) {
  if (!s->committed || s->bvh4.nodes) return FR_OK;
  fr_build_tree tree;
  size_t n;
  const aabb bounds = s->bounds; /* build_tree sets them to the triangles' alone */
  fr_error e = build_tree(s, &tree, &n);
  s->bounds = bounds;
  if (e) return e;
  e = fr_bvhn_from_build(&tree, &s->mesh, 4, &s->bvh4);
  fr_build_tree_free(&tree);
  if (e) return e;
  s->bvh4.planes = s->planes.n ? &s->planes : NULL;
  fr_scene_apply_prefetch(s);
  return FR_OK;
}

size_t fr_scene_triangle_count(const fr_scene *s) { return s ? s->mesh.ntris : 0; }
size_t fr_scene_vertex_count(const fr_scene *s) { return s ? s->mesh.nverts : 0; }
const float *fr_scene_vertices(const fr_scene *s) { return s ? s->mesh.pos : NULL; }
const uint32_t *fr_scene_indices(const fr_scene *s) { return s ? s->mesh.idx : NULL; }
size_t fr_scene_skipped_triangles(const fr_scene *s) { return s ? s->skipped : 0; }
size_t fr_scene_material_count(const fr_scene *s) { return s ? s->mesh.nmats : 0; }
const fr_material *fr_scene_material(const fr_scene *s, size_t i) { return s && i < s->mesh.nmats ? &s->mesh.mats[i] : NULL; }

uint32_t fr_scene_triangle_material(const fr_scene *s, uint32_t prim) {
  if (!s || !s->mesh.mat || prim >= s->mesh.ntris) return FR_INVALID_ID;
  return s->mesh.mat[prim];
}

uint32_t fr_scene_prim_material(const fr_scene *s, uint32_t prim) {
  if (!s || prim == FR_INVALID_ID) return FR_INVALID_ID;
  if (prim < s->mesh.ntris) return fr_scene_triangle_material(s, prim);
  size_t i = prim - s->mesh.ntris;
  return i < s->spheres.n ? s->spheres.mat[i] : FR_INVALID_ID;
}

fr_error fr_scene_add_sphere(fr_scene *s, const float center[3], float radius, uint32_t material) {
  if (!s || !center) return fr_fail(FR_ERR_ARG, "fr_scene_add_sphere: NULL argument");
  if (s->committed) return fr_fail(FR_ERR_STATE, "fr_scene_add_sphere: scene already committed");
  if (material != FR_INVALID_ID && material >= s->mesh.nmats)
    return fr_fail(FR_ERR_ARG, "fr_scene_add_sphere: material %u of %zu", material, s->mesh.nmats);
  return fr_spheres_add(&s->spheres, center, radius, material);
}

fr_error fr_scene_add_material(fr_scene *s, const fr_material *mat, uint32_t *index) {
  if (!s || !mat) return fr_fail(FR_ERR_ARG, "fr_scene_add_material: NULL argument");
  if (s->committed) return fr_fail(FR_ERR_STATE, "fr_scene_add_material: scene already committed");
  char name[sizeof mat->name];
  memcpy(name, mat->name, sizeof name);
  name[sizeof name - 1] = 0;
  uint32_t i;
  fr_error e = fr_mesh_material(&s->mesh, name, &i);
  if (e) return e;
  s->mesh.mats[i] = *mat;
  memcpy(s->mesh.mats[i].name, name, sizeof name);
  if (index) *index = i;
  return FR_OK;
}

size_t fr_scene_sphere_count(const fr_scene *s) { return s ? s->spheres.n : 0; }

int fr_scene_sphere(const fr_scene *s, size_t i, float center[3], float *radius) {
  if (!s || i >= s->spheres.n) return 0;
  for (int a = 0; a < 3; a++) center[a] = s->spheres.s[i].c[a];
  *radius = s->spheres.s[i].r;
  return 1;
}

int fr_scene_geometric_normal(const fr_scene *s, uint32_t prim, const float p[3], float n[3]) {
  n[0] = n[1] = n[2] = 0.0f;
  if (!s || prim == FR_INVALID_ID) return 0;
  if (prim < s->mesh.ntris) {
    const uint32_t *ix = s->mesh.idx + 3 * (size_t)prim;
    vec3 a = v3_load(s->mesh.pos + 3 * (size_t)ix[0]), b = v3_load(s->mesh.pos + 3 * (size_t)ix[1]);
    vec3 c = v3_load(s->mesh.pos + 3 * (size_t)ix[2]);
    vec3 g = v3_cross(v3_sub(b, a), v3_sub(c, a));
    n[0] = g.x; n[1] = g.y; n[2] = g.z;
    return 1;
  }
  size_t i = prim - s->mesh.ntris;
  if (i >= s->spheres.n) return 0;
  for (int a = 0; a < 3; a++) n[a] = p[a] - s->spheres.s[i].c[a];
  return 1;
}

void fr_scene_bounds(const fr_scene *s, float lower[3], float upper[3]) {
  aabb b = aabb_empty();
  if (s && s->committed) b = s->bounds;
  else if (s) {
    for (size_t i = 0; i < s->mesh.nverts; i++) b = aabb_grow(b, v3_load(s->mesh.pos + 3 * i));
    for (size_t i = 0; i < s->spheres.n; i++) b = aabb_merge(b, fr_sphere_box(&s->spheres.s[i]));
  }
  lower[0] = b.lo.x; lower[1] = b.lo.y; lower[2] = b.lo.z;
  upper[0] = b.hi.x; upper[1] = b.hi.y; upper[2] = b.hi.z;
}

fr_error fr_scene_stats(const fr_scene *s, fr_bvh_stats *st) {
  if (!s || !st) return fr_fail(FR_ERR_ARG, "fr_scene_stats: NULL argument");
  if (!s->committed) return fr_fail(FR_ERR_STATE, "fr_scene_stats: scene not committed");
  memset(st, 0, sizeof *st);
  st->bvh2_inner = s->bvh2.nnodes;
  st->bvh2_leaves = s->bvh2.nleaves;
  st->bvh2_sah = fr_bvh2_sah(&s->bvh2);
  st->bvh2_leaf_fill = s->bvh2.nleaves ? (double)s->bvh2.nprims / (double)s->bvh2.nleaves : 0.0;
  st->bvh2_bytes = s->bvh2.nnodes * sizeof(fr_bvh2_node);
  const fr_bvhn *src[2] = {&s->bvh4, &s->bvh8};
  fr_wide_stats *dst[2] = {&st->bvh4, &st->bvh8};
  for (int i = 0; i < 2; i++) {
    if (!src[i]->nodes) continue; /* a BVH4 not built yet (wants_bvh4): zeros */
    fr_bvhn_stats b;
    fr_bvhn_stats_get(src[i], &b);
    *dst[i] = (fr_wide_stats){b.inner, b.leaves, b.node_bytes, b.tri_bytes, b.sah, b.sah_blocks, b.node_fill, b.leaf_fill, b.depth, b.packet_tri_bytes, b.blocks, b.block_fill};
  }
  st->references = s->bvh2.nprims;
  st->build_seconds = s->build_seconds;
  st->single_width = s->single_width;
  return FR_OK;
}

void fr_intersect1_reference(const fr_scene *s, const fr_ray *ray, fr_hit *hit) {
  if (!s->committed) { fr_hit_miss(hit); return; }
  fr_bvh2_intersect_reference(&s->bvh2, &s->mesh, ray, hit);
  fr_spheres_intersect1_brute(&s->sphere_bvh, fr_scene_sphere_base(s), ray, hit);
}

int fr_occluded1_reference(const fr_scene *s, const fr_ray *ray) {
  if (!s->committed) return 0;
  if (fr_bvh2_occluded_reference(&s->bvh2, &s->mesh, ray)) return 1;
  fr_hit h;
  fr_hit_miss(&h);
  fr_spheres_intersect1_brute(&s->sphere_bvh, fr_scene_sphere_base(s), ray, &h);
  return h.prim != FR_INVALID_ID;
}
