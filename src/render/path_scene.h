/* What the path tracer needs of a scene and a view, made once: the
 * environment, the materials (MTL mapped to BSDFs, textures), the surfaces
 * and the lights, into an fr_path_setup. For the command, the viewer's
 * renderer and fr_renderer alike. */
#ifndef FR_RENDER_PATH_SCENE_H
#define FR_RENDER_PATH_SCENE_H
#include "light/environment.h"
#include "render/path.h"
#include "render/views.h"

enum { FR_PATH_LIGHT_ENV = 1, FR_PATH_LIGHT_AREA = 2, FR_PATH_LIGHT_POINT = 4 };

typedef struct fr_path_options {
  int spp, max_depth, lights;     /* lights: FR_PATH_LIGHT_* */
  fr_sampler_kind sampler;
  unsigned seed;
  const char *env_file;           /* lat-long .hdr or .exr; NULL: env_color */
  vec3 env_color;
  float env_intensity, env_rotate; /* rotate: degrees about the view's up */
  const char *mirror, *glass;     /* comma-separated material names made mirror or glass (NULL: none) */
  float aperture, focus;          /* thin lens; focus <= 0: the distance from eye to at */
  vec3 area_radiance, point_intensity; /* 0: as bright as fr_path_scene_init says */
} fr_path_options;

/* 16 spp, depth 13, the environment (white) and the view's area light, seed 1. */
void fr_path_options_default(fr_path_options *o);

typedef struct fr_path_scene {
  fr_env env;
  fr_bsdf *mats;
  size_t count;                   /* materials, the last the default */
  struct fr_texture *textures;
  size_t ntextures;
  struct fr_surface *surf;
  fr_path_setup setup;            /* whole frame: spp 0..spp */
} fr_path_scene;

/* Sets up r for scene s seen from v. The materials are the MTL's, and a
 * scene file's where it names one. The area and point lights are, unless
 * o says, as bright as makes a white surface where the camera looks,
 * facing them, as bright as under a white sky. Errors: the
 * environment's (FR_ERR_IO, FR_ERR_FORMAT), FR_ERR_ARG (an unknown mirror
 * or glass name), FR_ERR_NOMEM; r is then empty. */
fr_error fr_path_scene_init(fr_path_scene *r, const fr_scene *s, const fr_view *v, const fr_path_options *o);
void fr_path_scene_free(fr_path_scene *r);
/* The distance in focus: focus where positive, else from v's eye to its at. */
float fr_path_focus(float focus, const fr_view *v);
#endif
