/* Scene files (scene_file.h), parsed with cJSON. */
#include "io/scene_file.h"
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"
#include "io/file_read.h"
#include "io/scene_path.h"
#include "material/material_mtl.h"

#define SCENE_FILE_MAX_BYTES ((size_t)16 << 20)

typedef struct ctx {
  const char *what, *dir, *root;
} ctx;

/* The dotted name of key inside where ("" at the top), as errors show it. */
static const char *key_of(const char *where, const char *key, char *buf, size_t cap) {
  snprintf(buf, cap, "%s%s%s", where, *where ? "." : "", key);
  return buf;
}

static fr_error bad(const ctx *c, const char *key, const char *expected) {
  return fr_fail(FR_ERR_FORMAT, "%s: %s: expected %s", c->what, key, expected);
}

/* Refuses keys the object does not know: a misspelt key is an error, not
 * a silent default. */
static fr_error known_keys(const ctx *c, const cJSON *o, const char *where, const char *const *keys) {
  if (!cJSON_IsObject(o)) return bad(c, where, "an object");
  for (const cJSON *it = o->child; it; it = it->next) {
    int ok = 0;
    for (const char *const *k = keys; *k && !ok; k++) ok = !strcmp(it->string, *k);
    if (!ok) {
      char list[512] = "";
      for (const char *const *k = keys; *k; k++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", k == keys ? "" : ", ", *k);
      char k[256];
      return fr_fail(FR_ERR_FORMAT, "%s: %s: unknown key (known: %s)", c->what, key_of(where, it->string, k, sizeof k), list);
    }
  }
  return FR_OK;
}

static fr_error number(const ctx *c, const cJSON *o, const char *where, const char *key, double lo, double hi,
                       float *out, int *has) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return FR_OK;
  char k[256], exp[128];
  key_of(where, key, k, sizeof k);
  snprintf(exp, sizeof exp, "a number in [%g, %g]", lo, hi);
  if (!cJSON_IsNumber(v) || !(v->valuedouble >= lo && v->valuedouble <= hi)) return bad(c, k, exp);
  *out = (float)v->valuedouble;
  if (has) *has = 1;
  return FR_OK;
}

static fr_error integer(const ctx *c, const cJSON *o, const char *where, const char *key, int lo, int hi, int *out,
                        int *has) {
  float f;
  int h = 0;
  fr_error e = number(c, o, where, key, lo, hi, &f, &h);
  if (e || !h) return e;
  const double v = cJSON_GetObjectItemCaseSensitive(o, key)->valuedouble;
  if (v != floor(v)) {
    char k[256], exp[64];
    key_of(where, key, k, sizeof k);
    snprintf(exp, sizeof exp, "a whole number in [%d, %d]", lo, hi);
    return bad(c, k, exp);
  }
  *out = (int)v;
  if (has) *has = 1;
  return FR_OK;
}

/* [x, y, z], each within [lo, hi] */
static fr_error triple(const ctx *c, const cJSON *o, const char *where, const char *key, double lo, double hi, vec3 *out,
                       int *has) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return FR_OK;
  char k[256], exp[128];
  key_of(where, key, k, sizeof k);
  snprintf(exp, sizeof exp, "three numbers [x, y, z] in [%g, %g]", lo, hi);
  if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3) return bad(c, k, exp);
  float xyz[3];
  for (int i = 0; i < 3; i++) {
    const cJSON *e = cJSON_GetArrayItem(v, i);
    if (!cJSON_IsNumber(e) || !(e->valuedouble >= lo && e->valuedouble <= hi)) return bad(c, k, exp);
    xyz[i] = (float)e->valuedouble;
  }
  *out = v3(xyz[0], xyz[1], xyz[2]);
  if (has) *has = 1;
  return FR_OK;
}

static fr_error string(const ctx *c, const cJSON *o, const char *where, const char *key, char *out, size_t cap,
                       int *has) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!v) return FR_OK;
  char k[256], exp[64];
  key_of(where, key, k, sizeof k);
  snprintf(exp, sizeof exp, "a string of at most %zu characters", cap - 1);
  if (!cJSON_IsString(v) || !v->valuestring[0] || strlen(v->valuestring) >= cap) return bad(c, k, exp);
  memcpy(out, v->valuestring, strlen(v->valuestring) + 1);
  if (has) *has = 1;
  return FR_OK;
}

/* A file the scene names, resolved against its folder and kept within root. */
static fr_error file_ref(const ctx *c, const cJSON *o, const char *where, const char *key, char *out, int *has) {
  char ref[PATH_MAX];
  int given = 0;
  fr_error e = string(c, o, where, key, ref, sizeof ref, &given);
  if (e || !given) return e;
  char scene[PATH_MAX];
  snprintf(scene, sizeof scene, "%s/scene", c->dir);
  char k[256];
  if (!fr_scene_ref_path_within(scene, ref, c->root, out, PATH_MAX))
    return fr_fail(FR_ERR_IO, "%s: %s: '%s' does not exist within %s (files a scene names stay in its folder, "
                              "or under --scene-root)", c->what, key_of(where, key, k, sizeof k), ref, c->root ? c->root : c->dir);
  if (has) *has = 1;
  return FR_OK;
}

static fr_error read_material(const ctx *c, const cJSON *o, const char *name, fr_bsdf *m) {
  static const char *const keys[] = {"type", "color", "emission", "ior", "preset", "eta", "k", "reflectance", "roughness",
                                     "attenuation_color", "attenuation_distance", "coat", "flake_color", "flake_density",
                                     "flake_scale", "flake_spread", "flake_jitter", "flake_roughness", "flipflop_color",
                                     "flipflop_falloff", NULL};
  char where[128];
  snprintf(where, sizeof where, "materials.%s", name);
  fr_error e = known_keys(c, o, where, keys);
  if (e) return e;
  char type[32];
  int has_type = 0;
  if ((e = string(c, o, where, "type", type, sizeof type, &has_type))) return e;
  fr_bsdf_kind kind;
  char k[160];
  snprintf(k, sizeof k, "%s.type", where);
  if (!has_type || !fr_bsdf_kind_parse(type, &kind)) return bad(c, k, "one of lambert, plastic, metal, glass, carpaint");
  *m = fr_bsdf_default(kind);
  char preset[32];
  int has_preset = 0, has_refl = 0;
  vec3 refl;
  if ((e = string(c, o, where, "preset", preset, sizeof preset, &has_preset))) return e;
  snprintf(k, sizeof k, "%s.preset", where);
  if (has_preset && (kind != FR_BSDF_METAL || !fr_bsdf_metal_preset(preset, m)))
    return bad(c, k, "a metal's preset: chrome, gold, copper, aluminium or silver");
  if ((e = triple(c, o, where, "color", 0, 1, &m->color, NULL)) || (e = triple(c, o, where, "emission", 0, 1e9, &m->emission, NULL)) ||
      (e = number(c, o, where, "ior", 1.0, 4.0, &m->ior, NULL)) || (e = triple(c, o, where, "eta", 0.01, 100, &m->eta, NULL)) ||
      (e = triple(c, o, where, "k", 0, 100, &m->k, NULL)) || (e = triple(c, o, where, "reflectance", 0, 1, &refl, &has_refl)) ||
      (e = number(c, o, where, "roughness", 0, 1, &m->roughness, NULL)) ||
      (e = triple(c, o, where, "attenuation_color", 0, 1, &m->attenuation_color, NULL)) ||
      (e = number(c, o, where, "attenuation_distance", 1e-9, 1e30, &m->attenuation_distance, NULL)) ||
      (e = number(c, o, where, "coat", 0, 1, &m->coat, NULL)) || (e = triple(c, o, where, "flake_color", 0, 1, &m->flake_color, NULL)) ||
      (e = number(c, o, where, "flake_density", 0, 1, &m->flake_density, NULL)) ||
      (e = number(c, o, where, "flake_scale", 0, 1e9, &m->flake_scale, NULL)) ||
      (e = number(c, o, where, "flake_spread", 0, 1, &m->flake_spread, NULL)) ||
      (e = number(c, o, where, "flake_jitter", 0, 1, &m->flake_jitter, NULL)) ||
      (e = number(c, o, where, "flake_roughness", 0, 1, &m->flake_roughness, NULL)) ||
      (e = triple(c, o, where, "flipflop_color", 0, 1, &m->flipflop_color, NULL)) ||
      (e = number(c, o, where, "flipflop_falloff", 0, 1, &m->flipflop_falloff, NULL)))
    return e;
  if (has_refl) fr_bsdf_metal_from_reflectance(m, refl);
  return FR_OK;
}

static fr_error read_all(const ctx *c, const cJSON *root, fr_scene_file *f) {
  static const char *const top[] = {"meshes", "materials", "camera", "environment", "lights", "render", NULL};
  fr_error e = known_keys(c, root, "", top);
  if (e) return e;
  const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(root, "meshes");
  if (!cJSON_IsArray(meshes) || cJSON_GetArraySize(meshes) < 1 || cJSON_GetArraySize(meshes) > FR_SCENE_FILE_MAX_MESHES)
    return bad(c, "meshes", "an array of 1 to 256 meshes");
  f->nmeshes = cJSON_GetArraySize(meshes);
  f->meshes = calloc((size_t)f->nmeshes, sizeof *f->meshes);
  if (!f->meshes) return fr_fail(FR_ERR_NOMEM, "out of memory");
  static const char *const mesh_keys[] = {"file", "material", "scale", "translate", NULL};
  int i = 0;
  for (const cJSON *m = meshes->child; m; m = m->next, i++) {
    char where[32];
    snprintf(where, sizeof where, "meshes[%d]", i);
    fr_scene_file_mesh *fm = &f->meshes[i];
    fm->scale = v3(1, 1, 1);
    int has_file = 0, has_scale = 0;
    float s;
    if ((e = known_keys(c, m, where, mesh_keys)) || (e = file_ref(c, m, where, "file", fm->path, &has_file)) ||
        (e = string(c, m, where, "material", fm->material, sizeof fm->material, NULL)) ||
        (e = triple(c, m, where, "translate", -1e9, 1e9, &fm->translate, NULL)))
      return e;
    if (!has_file) { char k[48]; snprintf(k, sizeof k, "%s.file", where); return bad(c, k, "a mesh file"); }
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(m, "scale");
    if (cJSON_IsNumber(sc)) {
      if ((e = number(c, m, where, "scale", 1e-9, 1e9, &s, &has_scale))) return e;
      fm->scale = v3(s, s, s);
    } else if ((e = triple(c, m, where, "scale", 1e-9, 1e9, &fm->scale, NULL))) {
      char k[48];
      snprintf(k, sizeof k, "%s.scale", where);
      return bad(c, k, "a positive number or three positive numbers");
    }
  }
  const cJSON *mats = cJSON_GetObjectItemCaseSensitive(root, "materials");
  if (mats) {
    if (!cJSON_IsObject(mats) || cJSON_GetArraySize(mats) > FR_SCENE_FILE_MAX_MATERIALS)
      return bad(c, "materials", "an object of at most 1024 materials by name");
    f->nmaterials = cJSON_GetArraySize(mats);
    f->materials = calloc((size_t)f->nmaterials + 1, sizeof *f->materials);
    if (!f->materials) return fr_fail(FR_ERR_NOMEM, "out of memory");
    int j = 0;
    for (const cJSON *m = mats->child; m; m = m->next, j++) {
      if (strlen(m->string) >= sizeof f->materials[j].name) return bad(c, "materials", "names of at most 63 characters");
      snprintf(f->materials[j].name, sizeof f->materials[j].name, "%s", m->string);
      if ((e = read_material(c, m, m->string, &f->materials[j].bsdf))) return e;
    }
  }
  for (int k = 0; k < f->nmeshes; k++)
    if (f->meshes[k].material[0] && !fr_scene_file_find_material(f, f->meshes[k].material))
      return fr_fail(FR_ERR_FORMAT, "%s: meshes[%d].material: '%s' is not among the file's materials", c->what, k,
                     f->meshes[k].material);
  const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
  static const char *const cam_keys[] = {"eye", "at", "up", "fov", "aperture", "focus", NULL};
  if (cam && ((e = known_keys(c, cam, "camera", cam_keys)) || (e = triple(c, cam, "camera", "eye", -1e9, 1e9, &f->eye, &f->has_eye)) ||
              (e = triple(c, cam, "camera", "at", -1e9, 1e9, &f->at, &f->has_at)) ||
              (e = triple(c, cam, "camera", "up", -1e9, 1e9, &f->up, &f->has_up)) ||
              (e = number(c, cam, "camera", "fov", 1e-3, 179.9, &f->fov, &f->has_fov)) ||
              (e = number(c, cam, "camera", "aperture", 0, 1e9, &f->aperture, &f->has_aperture)) ||
              (e = number(c, cam, "camera", "focus", 1e-9, 1e9, &f->focus, &f->has_focus))))
    return e;
  const cJSON *env = cJSON_GetObjectItemCaseSensitive(root, "environment");
  static const char *const env_keys[] = {"file", "color", "intensity", "rotate", NULL};
  if (env && ((e = known_keys(c, env, "environment", env_keys)) ||
              (e = file_ref(c, env, "environment", "file", f->env_file, &f->has_env_file)) ||
              (e = triple(c, env, "environment", "color", 0, 1e9, &f->env_color, &f->has_env_color)) ||
              (e = number(c, env, "environment", "intensity", 0, 1e6, &f->env_intensity, &f->has_env_intensity)) ||
              (e = number(c, env, "environment", "rotate", -360, 360, &f->env_rotate, &f->has_env_rotate))))
    return e;
  if (f->has_env_file && f->has_env_color) return bad(c, "environment", "a file or a color, not both");
  const cJSON *lights = cJSON_GetObjectItemCaseSensitive(root, "lights");
  static const char *const light_keys[] = {"area", "point", NULL}, *const area_keys[] = {"corner", "edge1", "edge2", "radiance", NULL},
                           *const point_keys[] = {"position", "intensity", NULL};
  if (lights) {
    if ((e = known_keys(c, lights, "lights", light_keys))) return e;
    f->has_lights = 1;
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(lights, "area"), *p = cJSON_GetObjectItemCaseSensitive(lights, "point");
    int h[3] = {0, 0, 0};
    if (a && ((e = known_keys(c, a, "lights.area", area_keys)) || (e = triple(c, a, "lights.area", "corner", -1e9, 1e9, &f->area[0], &h[0])) ||
              (e = triple(c, a, "lights.area", "edge1", -1e9, 1e9, &f->area[1], &h[1])) ||
              (e = triple(c, a, "lights.area", "edge2", -1e9, 1e9, &f->area[2], &h[2])) ||
              (e = triple(c, a, "lights.area", "radiance", 0, 1e9, &f->area_radiance, &f->has_area_radiance))))
      return e;
    if (a && !(h[0] && h[1] && h[2])) return bad(c, "lights.area", "corner, edge1 and edge2");
    f->has_area = a != NULL;
    int hp = 0;
    if (p && ((e = known_keys(c, p, "lights.point", point_keys)) || (e = triple(c, p, "lights.point", "position", -1e9, 1e9, &f->point, &hp)) ||
              (e = triple(c, p, "lights.point", "intensity", 0, 1e12, &f->point_intensity, &f->has_point_intensity))))
      return e;
    if (p && !hp) return bad(c, "lights.point.position", "three numbers");
    f->has_point = p != NULL;
  }
  const cJSON *r = cJSON_GetObjectItemCaseSensitive(root, "render");
  static const char *const render_keys[] = {"shade", "size", "spp", "max_depth", "sampler", "seed", NULL};
  if (r) {
    if ((e = known_keys(c, r, "render", render_keys)) || (e = string(c, r, "render", "shade", f->shade, sizeof f->shade, &f->has_shade)) ||
        (e = string(c, r, "render", "sampler", f->sampler, sizeof f->sampler, &f->has_sampler)) ||
        (e = integer(c, r, "render", "spp", 1, 65536, &f->spp, &f->has_spp)) ||
        (e = integer(c, r, "render", "max_depth", 1, 64, &f->max_depth, &f->has_max_depth)) ||
        (e = integer(c, r, "render", "seed", 0, 2147483647, &f->seed, &f->has_seed)))
      return e;
    const cJSON *sz = cJSON_GetObjectItemCaseSensitive(r, "size");
    if (sz) {
      const cJSON *w = cJSON_GetArrayItem(sz, 0), *h = cJSON_GetArrayItem(sz, 1);
      if (!cJSON_IsArray(sz) || cJSON_GetArraySize(sz) != 2 || !cJSON_IsNumber(w) || !cJSON_IsNumber(h) ||
          !(w->valuedouble >= 1 && w->valuedouble <= 65536 && h->valuedouble >= 1 && h->valuedouble <= 65536) ||
          w->valuedouble != floor(w->valuedouble) || h->valuedouble != floor(h->valuedouble))
        return bad(c, "render.size", "[width, height], whole numbers in [1, 65536]");
      f->width = (int)w->valuedouble, f->height = (int)h->valuedouble, f->has_size = 1;
    }
  }
  return FR_OK;
}

fr_error fr_scene_file_parse(const char *what, const char *data, const char *dir, const char *root, fr_scene_file *f) {
  memset(f, 0, sizeof *f);
  cJSON *j = cJSON_ParseWithOpts(data, NULL, 1);
  if (!j) {
    const char *at = cJSON_GetErrorPtr();
    size_t line = 1;
    for (const char *p = data; at && p < at && *p; p++) line += *p == '\n';
    return fr_fail(FR_ERR_FORMAT, "%s: line %zu: not valid JSON", what, line);
  }
  const ctx c = {what, dir, root};
  fr_error e = read_all(&c, j, f);
  cJSON_Delete(j);
  if (e) fr_scene_file_free(f);
  return e;
}

fr_error fr_scene_file_read(const char *path, const char *root, fr_scene_file *f) {
  memset(f, 0, sizeof *f);
  char *data;
  size_t size;
  fr_error e = fr_read_file_max(path, SCENE_FILE_MAX_BYTES, &data, &size);
  if (e) return e;
  if (strlen(data) != size) { free(data); return fr_fail(FR_ERR_FORMAT, "%s: a NUL byte in a JSON file", path); }
  char dir[PATH_MAX];
  snprintf(dir, sizeof dir, "%s", path);
  char *slash = strrchr(dir, '/');
  if (slash) *slash = 0;
  else snprintf(dir, sizeof dir, ".");
  e = fr_scene_file_parse(path, data, dir, root, f);
  free(data);
  return e;
}

void fr_scene_file_free(fr_scene_file *f) {
  free(f->meshes);
  free(f->materials);
  memset(f, 0, sizeof *f);
}

const fr_bsdf *fr_scene_file_find_material(const fr_scene_file *f, const char *name) {
  for (int i = 0; i < f->nmaterials; i++)
    if (!strcmp(f->materials[i].name, name)) return &f->materials[i].bsdf;
  return NULL;
}
