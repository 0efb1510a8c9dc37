#include "cli_scene_file.h"
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "cli.h"
#include "io/file_read.h"

static fr_scene_file file;
static int have_file;
static const char *root;
static char text[F_COUNT][96];

const fr_scene_file *cli_scene_file(void) { return have_file ? &file : NULL; }
const char *cli_scene_root(void) { return root; }

void cli_scene_file_done(void) {
  if (have_file) fr_scene_file_free(&file);
  have_file = 0;
}

static void set(cli_args *a, cli_flag_id f, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void set(cli_args *a, cli_flag_id f, const char *fmt, ...) {
  if (a->val[f]) return; /* the flag wins */
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(text[f], sizeof text[f], fmt, ap);
  va_end(ap);
  a->val[f] = text[f];
}
#define V3(v) (double)(v).x, (double)(v).y, (double)(v).z

int cli_scene_file_defaults(cli_args *a) {
  root = a->val[F_SCENE_ROOT];
  if (a->npos < 1 || !fr_has_suffix(a->pos[0], ".json")) return 0;
  cli_scene_file_done();
  if (fr_scene_file_read(a->pos[0], root, &file)) return cli_error(1, "%s", fr_last_error());
  have_file = 1;
  const fr_scene_file *f = &file;
  if (f->has_eye) set(a, F_EYE, "%.9g,%.9g,%.9g", V3(f->eye));
  if (f->has_at) set(a, F_AT, "%.9g,%.9g,%.9g", V3(f->at));
  if (f->has_up) set(a, F_UP, "%.9g,%.9g,%.9g", V3(f->up));
  if (f->has_fov) set(a, F_FOV, "%.9g", (double)f->fov);
  if (f->has_aperture) set(a, F_APERTURE, "%.9g", (double)f->aperture);
  if (f->has_focus) set(a, F_FOCUS, "%.9g", (double)f->focus);
  if (f->has_env_file) a->val[F_ENV] = a->val[F_ENV] || a->val[F_ENV_COLOR] ? a->val[F_ENV] : f->env_file;
  if (f->has_env_color && !a->val[F_ENV]) set(a, F_ENV_COLOR, "%.9g,%.9g,%.9g", V3(f->env_color));
  if (f->has_env_intensity) set(a, F_ENV_INTENSITY, "%.9g", (double)f->env_intensity);
  if (f->has_env_rotate) set(a, F_ENV_ROTATE, "%.9g", (double)f->env_rotate);
  if (f->has_area)
    set(a, F_AREA, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", V3(f->area[0]), V3(f->area[1]), V3(f->area[2]));
  if (f->has_point) set(a, F_LIGHT, "%.9g,%.9g,%.9g", V3(f->point));
  if (f->has_lights) set(a, F_LIGHTS, "env%s%s", f->has_area ? ",area" : "", f->has_point ? ",point" : "");
  if (f->has_shade) set(a, F_SHADE, "%s", f->shade);
  if (f->has_size) set(a, F_SIZE, "%dx%d", f->width, f->height);
  if (f->has_spp) set(a, F_SPP, "%d", f->spp);
  if (f->has_max_depth) set(a, F_MAX_DEPTH, "%d", f->max_depth);
  if (f->has_sampler) set(a, F_SAMPLER, "%s", f->sampler);
  if (f->has_seed) set(a, F_SEED, "%d", f->seed);
  return 0;
}
