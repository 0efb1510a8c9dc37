/* The path tracer's materials for a scene (path.h). */
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "base/error.h"
#include "material/material_mtl.h"
#include "material/texture.h"
#include "render/path.h"
#include "render/views.h"

/* The built-in material showcase's materials by name. */
static void showcase(const char *name, fr_bsdf *m) {
  if (!strcmp(name, "chrome") || !strcmp(name, "gold")) {
    *m = fr_bsdf_default(FR_BSDF_METAL);
    fr_bsdf_metal_preset(name, m);
    m->roughness = !strcmp(name, "gold") ? 0.3f : 0.0f;
  } else if (!strcmp(name, "carpaint")) {
    *m = fr_bsdf_default(FR_BSDF_CARPAINT);
    m->flake_scale = 60.0f;
  } else if (!strcmp(name, "glass")) {
    *m = fr_bsdf_default(FR_BSDF_GLASS);
    m->attenuation_color = v3(0.85f, 0.95f, 0.9f);
    m->attenuation_distance = 2.0f;
  }
}

void fr_path_textures_free(fr_texture *t, size_t n) {
  for (size_t i = 0; t && i < n; i++) fr_texture_free(&t[i]);
  free(t);
}

/* Each material's map_Kd, loaded once per file. */
static fr_error load_textures(const fr_scene *s, fr_bsdf *m, size_t nm, fr_texture **out, size_t *nout) {
  fr_texture *tex = NULL;
  size_t nt = 0;
  const char **names = calloc(nm + 1, sizeof *names);
  if (!names) return fr_fail(FR_ERR_NOMEM, "out of memory");
  fr_error e = FR_OK;
  for (size_t i = 0; i < nm && !e; i++) {
    const char *file = fr_scene_material(s, i)->map_kd;
    if (!file[0] || m[i].kind == FR_BSDF_METAL || m[i].kind == FR_BSDF_GLASS) continue;
    size_t k = 0;
    while (k < nt && strcmp(names[k], file)) k++;
    if (k == nt) {
      fr_texture *grown = realloc(tex, (nt + 1) * sizeof *tex);
      if (!grown) { e = fr_fail(FR_ERR_NOMEM, "out of memory"); break; }
      tex = grown;
      if ((e = fr_texture_load(&tex[nt], file))) break;
      names[nt++] = file;
    }
    m[i].color_tex = (int)k;
  }
  free(names);
  if (e) { fr_path_textures_free(tex, nt); return e; }
  *out = tex, *nout = nt;
  return FR_OK;
}

fr_error fr_path_mats_build(const fr_scene *s, const char *mirror, const char *glass, fr_bsdf **mats, size_t *count,
                            fr_texture **textures, size_t *ntextures) {
  if (!mirror && !glass) fr_view_surfaces(s->name, &mirror, &glass);
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  const float scale = v3_len(v3_sub(v3_load(hi), v3_load(lo)));
  const size_t nm = fr_scene_material_count(s);
  fr_bsdf *m = malloc((nm + 1) * sizeof *m);
  if (!m) return fr_fail(FR_ERR_NOMEM, "out of memory for %zu materials", nm + 1);
  for (size_t i = 0; i < nm; i++) {
    const fr_material *mt = fr_scene_material(s, i);
    m[i] = fr_bsdf_from_mtl(mt, 0.5f * scale);
    if (fr_names_contain(glass, mt->name)) {
      m[i] = fr_bsdf_default(FR_BSDF_GLASS);
      m[i].ior = mt->ior > 1.0f && mt->ior < 4.0f ? mt->ior : 1.5f;
    } else if (fr_names_contain(mirror, mt->name)) {
      m[i] = fr_bsdf_default(FR_BSDF_METAL);
      fr_bsdf_metal_preset("chrome", &m[i]);
    }
  }
  if (!strcmp(s->name, "materials"))
    for (size_t i = 0; i < nm; i++) showcase(fr_scene_material(s, i)->name, &m[i]);
  m[nm] = fr_bsdf_default(FR_BSDF_LAMBERT);
  fr_error e = load_textures(s, m, nm, textures, ntextures);
  if (e) { free(m); return e; }
  *mats = m;
  *count = nm + 1;
  return FR_OK;
}

