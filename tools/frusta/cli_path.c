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
  const fr_scene_file *file = cli_scene_file(); /* its lights' brightness (0: automatic) */
  if (file && file->has_area_radiance) o->area_radiance = file->area_radiance;
  if (file && file->has_point_intensity) o->point_intensity = file->point_intensity;
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

void cli_path_print(const cli_path *o, const fr_path_setup *P) {
  char lights[32] = "";
  if (o->lights & CLI_LIGHT_ENV) strcat(lights, ",env");
  if (P->lights.area) strcat(lights, ",area");
  if (P->lights.point) strcat(lights, ",point");
  printf("path spp=%d max_depth=%d sampler=%s lights=%s env=%s area_radiance=%.4g point_intensity=%.4g aperture=%g "
         "focus=%g\n",
         o->spp, o->max_depth, fr_sampler_name(o->sampler), lights[0] ? lights + 1 : "none",
         o->env_file ? o->env_file : "constant", (double)P->lights.area_radiance.x, (double)P->lights.point_intensity.x,
         (double)P->aperture, (double)P->focus);
}

int cli_path_setup(const cli_path *o, fr_workload *w, cli_path_run *r) {
  const fr_view *v = &w->view;
  fr_path_options po;
  fr_path_options_default(&po);
  po.spp = o->spp, po.max_depth = o->max_depth, po.lights = o->lights, po.sampler = o->sampler, po.seed = o->seed;
  po.env_file = o->env_file, po.env_color = o->env_color, po.env_intensity = o->env_intensity;
  po.env_rotate = o->env_rotate, po.mirror = o->mirror, po.glass = o->glass;
  po.aperture = o->aperture, po.focus = o->focus;
  po.area_radiance = o->area_radiance, po.point_intensity = o->point_intensity;
  fr_error e = fr_path_scene_init(r, w->scene, v, &po);
  if (e) return cli_error(e == FR_ERR_ARG ? CLI_USAGE_ERROR : 1, "%s", fr_last_error());
  fr_path_setup *P = &r->setup;
  w->path = P;
  cli_path_print(o, P);
  return 0;
}

void cli_path_free(cli_path_run *r) { fr_path_scene_free(r); }

void cli_path_desc(const cli_path *o, fr_render_desc *d) {
  d->max_depth = o->max_depth, d->sampler = o->sampler, d->seed = o->seed, d->lights = (unsigned)o->lights;
  d->environment = o->env_file;
  v3_store(d->env_color, o->env_color);
  d->env_intensity = o->env_intensity, d->env_rotate = o->env_rotate;
  d->mirror = o->mirror, d->glass = o->glass;
  d->aperture = o->aperture, d->focus = o->focus > 0.0f ? o->focus : 0.0f;
  v3_store(d->area_radiance, o->area_radiance);
  v3_store(d->light_intensity, o->point_intensity);
  d->exposure = o->exposure;
}
