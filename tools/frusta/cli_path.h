/* The path tracer's flags, shared by render and bench, and what they set up:
 * materials, lights and the environment (render/path.h). */
#ifndef FR_TOOL_CLI_PATH_H
#define FR_TOOL_CLI_PATH_H
#include "flags.h"
#include "light/environment.h"
#include "render/path.h"
#include "render/path_scene.h"
#include "render/workload.h"

enum { CLI_LIGHT_ENV = FR_PATH_LIGHT_ENV, CLI_LIGHT_AREA = FR_PATH_LIGHT_AREA, CLI_LIGHT_POINT = FR_PATH_LIGHT_POINT };

typedef struct cli_path {
  int spp, max_depth, lights;
  fr_sampler_kind sampler;
  unsigned seed;
  const char *env_file, *mirror, *glass;
  vec3 env_color;
  float env_intensity, env_rotate, aperture, focus, exposure; /* focus < 0: not given */
  vec3 area_radiance, point_intensity; /* a scene file's (0: automatic) */
  int aov;
} cli_path;

typedef fr_path_scene cli_path_run;

/* The flags; 0, or 2 after reporting a usage error. */
int cli_path_from_args(const cli_args *a, cli_path *o);
/* Loads the environment, builds the materials and lights for w's scene
 * and view, and points w->path at r->setup (whole frame: spp 0..spp);
 * 0, or the exit code after reporting. Prints one line of what it set. */
int cli_path_setup(const cli_path *o, fr_workload *w, cli_path_run *r);
void cli_path_free(cli_path_run *r);
/* The path tracer's fields of a renderer's description (spp aside). */
void cli_path_desc(const cli_path *o, fr_render_desc *d);
/* The line of what the path tracer was set up with. */
void cli_path_print(const cli_path *o, const fr_path_setup *P);
#endif
