#include "path_scene.h"
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "render/surfaces.h"

void fr_path_options_default(fr_path_options *o) {
  memset(o, 0, sizeof *o);
  o->spp = 16, o->max_depth = 13, o->seed = 1, o->lights = FR_PATH_LIGHT_ENV | FR_PATH_LIGHT_AREA;
  o->sampler = FR_SAMPLER_HAMMERSLEY;
  o->env_color = v3(1, 1, 1), o->env_intensity = 1.0f;
}

static int positive(vec3 c) { return c.x > 0.0f || c.y > 0.0f || c.z > 0.0f; }

fr_error fr_path_scene_init(fr_path_scene *r, const fr_scene *s, const fr_view *v, const fr_path_options *o) {
  memset(r, 0, sizeof *r);
  if (o->env_file) {
    fr_error e = fr_env_load(&r->env, o->env_file);
    if (e) return e;
  } else {
    fr_env_constant(&r->env, o->env_color);
  }
  if (!(o->lights & FR_PATH_LIGHT_ENV)) { fr_env_free(&r->env); fr_env_constant(&r->env, v3(0, 0, 0)); }
  fr_env_orient(&r->env, v->up, o->env_rotate, o->env_intensity);
  fr_error e = fr_path_mats_build(s, o->mirror, o->glass, &r->mats, &r->count, &r->textures, &r->ntextures);
  for (size_t i = 0; !e && i + 1 < r->count; i++) {
    const fr_bsdf *b = fr_scene_file_bsdf(s, fr_scene_material(s, i)->name);
    if (b) r->mats[i] = *b;
  }
  fr_path_setup *P = &r->setup;
  if (!e) e = fr_surfaces_build(s, (int32_t)r->count - 1, &r->surf, &P->nsurf);
  if (e) { fr_path_scene_free(r); return e; }
  P->mats = r->mats, P->count = r->count;
  P->surf = r->surf;
  P->textures = r->textures;
  P->lights.env = &r->env;
  const vec3 ac = v3_add(v->area_c, v3_scale(v3_add(v->area_e1, v->area_e2), 0.5f));
  const float area = v3_len(v3_cross(v->area_e1, v->area_e2));
  const float da = v3_len(v3_sub(ac, v->at)), dp = v3_len(v3_sub(v->light, v->at));
  P->lights.area = (o->lights & FR_PATH_LIGHT_AREA) && area > 0.0f;
  P->lights.area_c = v->area_c, P->lights.area_e1 = v->area_e1, P->lights.area_e2 = v->area_e2;
  const float la = area > 0.0f ? 3.14159265f * da * da / area : 0.0f;
  P->lights.area_radiance = positive(o->area_radiance) ? o->area_radiance : v3(la, la, la);
  P->lights.point = (o->lights & FR_PATH_LIGHT_POINT) != 0;
  P->lights.point_pos = v->light;
  const float ip = 3.14159265f * dp * dp;
  P->lights.point_intensity = positive(o->point_intensity) ? o->point_intensity : v3(ip, ip, ip);
  P->max_depth = o->max_depth;
  P->sampler = o->sampler;
  P->spp = o->spp, P->spp_begin = 0, P->spp_end = o->spp;
  P->aperture = o->aperture;
  P->focus = fr_path_focus(o->focus, v);
  P->seed = o->seed;
  return FR_OK;
}

float fr_path_focus(float focus, const fr_view *v) { return focus > 0.0f ? focus : v3_len(v3_sub(v->at, v->eye)); }

void fr_path_scene_free(fr_path_scene *r) {
  fr_env_free(&r->env);
  free(r->mats);
  free(r->surf);
  fr_path_textures_free(r->textures, r->ntextures);
  memset(r, 0, sizeof *r);
}
