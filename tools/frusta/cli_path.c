#include "cli_path.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "cli.h"
#include "cli_scene_file.h"
#include "render/surfaces.h"

int cli_path_from_args(const cli_args *a, cli_path *o) {
  memset(o, 0, sizeof *o);
  o->spp = 16, o->max_depth = 13, o->seed = 1, o->lights = CLI_LIGHT_ENV | CLI_LIGHT_AREA;
  o->env_color = v3(1, 1, 1), o->env_intensity = 1.0f, o->focus = -1.0f;
  o->env_file = a->val[F_ENV], o->mirror = a->val[F_MIRROR], o->glass = a->val[F_GLASS];
  o->aov = a->val[F_AOV] != NULL;
  int seed = 1, rc;
  static const char *const samplers[] = {"hammersley", "sobol"};
  int sampler = 0;
  if ((rc = cli_arg_int(a, F_SPP, 1, 65536, &o->spp)) || (rc = cli_arg_int(a, F_MAX_DEPTH, 1, FR_PATH_MAX_DEPTH, &o->max_depth)) ||
      (rc = cli_arg_float(a, F_ENV_INTENSITY, 0.0f, 1e6f, &o->env_intensity)) ||
      (rc = cli_arg_float(a, F_ENV_ROTATE, -360.0f, 360.0f, &o->env_rotate)) ||
      (rc = cli_arg_float(a, F_APERTURE, 0.0f, 1e9f, &o->aperture)) ||
      (rc = cli_arg_float(a, F_FOCUS, 1e-9f, 1e9f, &o->focus)) ||
      (rc = cli_arg_float(a, F_EXPOSURE, -30.0f, 30.0f, &o->exposure)) ||
      (rc = cli_arg_choice(a, F_SAMPLER, samplers, 2, &sampler)) || (rc = cli_arg_int(a, F_SEED, 0, 2147483647, &seed)))
    return rc;
  o->sampler = (fr_sampler_kind)sampler;
  o->seed = (unsigned)seed;
  if (a->val[F_ENV_COLOR]) {
    vec3 c;
    if (!cli_parse_vec3(a->val[F_ENV_COLOR], &c) || !(c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f) || !v3_finite(c))
      return cli_error(CLI_USAGE_ERROR, "--env-color wants three non-negative numbers r,g,b, got '%s'", a->val[F_ENV_COLOR]);
    if (o->env_file) return cli_error(CLI_USAGE_ERROR, "--env and --env-color: give one environment");
    o->env_color = c;
  }
  if (a->val[F_LIGHTS]) {
    const char *s = a->val[F_LIGHTS];
    o->lights = 0;
    if (strcmp(s, "none"))
      for (const char *p = s;;) {
        const char *e = strchr(p, ',');
        const size_t n = e ? (size_t)(e - p) : strlen(p);
        if (n == 3 && !strncmp(p, "env", 3)) o->lights |= CLI_LIGHT_ENV;
        else if (n == 4 && !strncmp(p, "area", 4)) o->lights |= CLI_LIGHT_AREA;
        else if (n == 5 && !strncmp(p, "point", 5)) o->lights |= CLI_LIGHT_POINT;
        else return cli_error(CLI_USAGE_ERROR, "--lights is a list of env, area and point, or none; not '%s'", s);
        if (!e) break;
        p = e + 1;
      }
  }
  return 0;
}

int cli_path_setup(const cli_path *o, fr_workload *w, cli_path_run *r) {
  memset(r, 0, sizeof *r);
  const fr_view *v = &w->view;
  if (o->env_file) {
    if (fr_env_load(&r->env, o->env_file)) return cli_error(1, "%s", fr_last_error());
  } else {
    fr_env_constant(&r->env, o->env_color);
  }
  if (!(o->lights & CLI_LIGHT_ENV)) { fr_env_free(&r->env); fr_env_constant(&r->env, v3(0, 0, 0)); }
  fr_env_orient(&r->env, v->up, o->env_rotate, o->env_intensity);
  size_t count;
  fr_error e = fr_path_mats_build(w->scene, o->mirror, o->glass, &r->mats, &count, &r->textures, &r->ntextures);
  if (e) {
    cli_path_free(r);
    return cli_error(e == FR_ERR_ARG ? CLI_USAGE_ERROR : 1, "%s", fr_last_error());
  }
  const fr_scene_file *file = cli_scene_file();
  for (size_t i = 0; file && i + 1 < count; i++) { /* the scene file's materials, by name */
    const fr_bsdf *b = fr_scene_file_find_material(file, fr_scene_material(w->scene, i)->name);
    if (b) r->mats[i] = *b;
  }
  fr_path_setup *P = &r->setup;
  P->mats = r->mats, P->count = count;
  if (fr_surfaces_build(w->scene, (int32_t)count - 1, &r->surf, &P->nsurf)) { cli_path_free(r); return cli_error(1, "%s", fr_last_error()); }
  P->surf = r->surf;
  P->textures = r->textures;
  P->lights.env = &r->env;
  /* the area and point lights bright enough that a white surface where the
   * camera looks, facing them, is as bright as under a white sky (irradiance pi) */
  const vec3 ac = v3_add(v->area_c, v3_scale(v3_add(v->area_e1, v->area_e2), 0.5f));
  const float area = v3_len(v3_cross(v->area_e1, v->area_e2));
  const float da = v3_len(v3_sub(ac, v->at)), dp = v3_len(v3_sub(v->light, v->at));
  P->lights.area = (o->lights & CLI_LIGHT_AREA) && area > 0.0f;
  P->lights.area_c = v->area_c, P->lights.area_e1 = v->area_e1, P->lights.area_e2 = v->area_e2;
  const float la = area > 0.0f ? 3.14159265f * da * da / area : 0.0f;
  P->lights.area_radiance = file && file->has_area_radiance ? file->area_radiance : v3(la, la, la);
  P->lights.point = (o->lights & CLI_LIGHT_POINT) != 0;
  P->lights.point_pos = v->light;
  const float ip = 3.14159265f * dp * dp;
  P->lights.point_intensity = file && file->has_point_intensity ? file->point_intensity : v3(ip, ip, ip);
  P->max_depth = o->max_depth;
  P->sampler = o->sampler;
  P->spp = o->spp, P->spp_begin = 0, P->spp_end = o->spp;
  P->aperture = o->aperture;
  P->focus = o->focus > 0.0f ? o->focus : v3_len(v3_sub(v->at, v->eye));
  P->seed = o->seed;
  w->path = P;
  char lights[32] = "";
  if (o->lights & CLI_LIGHT_ENV) strcat(lights, ",env");
  if (P->lights.area) strcat(lights, ",area");
  if (P->lights.point) strcat(lights, ",point");
  printf("path spp=%d max_depth=%d sampler=%s lights=%s env=%s area_radiance=%.4g point_intensity=%.4g aperture=%g "
         "focus=%g\n",
         o->spp, o->max_depth, fr_sampler_name(o->sampler), lights[0] ? lights + 1 : "none",
         o->env_file ? o->env_file : "constant", (double)P->lights.area_radiance.x, (double)P->lights.point_intensity.x,
         (double)P->aperture, (double)P->focus);
  return 0;
}

void cli_path_free(cli_path_run *r) {
  fr_env_free(&r->env);
  free(r->mats);
  free(r->surf);
  fr_path_textures_free(r->textures, r->ntextures);
  memset(r, 0, sizeof *r);
}
