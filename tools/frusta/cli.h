/* Argument parsing and scene setup shared by the subcommands. */
#ifndef FR_TOOL_CLI_H
#define FR_TOOL_CLI_H
#include "base/vec3.h"
#include "flags.h"
#include "frusta.h"
#include "render/views.h"

#define CLI_USAGE_ERROR 2

/* Prints "frusta: <message>" on one line to stderr; returns 1 (or 2 for usage). */
int cli_error(int code, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The last message cli_error gave; with quiet set it prints nothing (the
 * ranks of a cluster but rank 0, whose messages rank 0 tells). */
const char *cli_last_error(void);
void cli_set_quiet(int quiet);

int cli_parse_vec3(const char *s, vec3 *out);
int cli_parse_int(const char *s, int lo, int hi, int *out);
int cli_parse_float(const char *s, float *out);
int cli_parse_size(const char *s, int *w, int *h);

/* View flags shared by render and bench. */
typedef struct cli_view {
  int has_eye, has_at, has_up, has_fov, has_light, has_area;
  vec3 eye, at, up, light, area[3];
  float fov;
  int width, height;
  float smooth;   /* crease angle of the shading normals made where a file has none (0: flat) */
} cli_view;

/* The view flags (1024x1024 and the scene's view where not given), and
 * --threads and --isa; 0, or 2 after reporting a usage error. */
int cli_view_from_args(const cli_args *a, cli_view *v);
int cli_common_from_args(const cli_args *a, int *threads);
/* The scene's own view with the flags applied. */
fr_view cli_resolve_view(const fr_scene *s, const cli_view *v);

/* Loads "--builtin" or a file and commits it; reports errors itself. */
/* A scene argument: a file, --builtin, or --builtin=NAME (default, sphereflake). */
int cli_is_builtin(const char *arg);
int cli_load_scene(const char *arg, fr_scene **s);
/* The same with smooth shading normals (fr_scene_smooth) of crease angle smooth, if > 0. */
int cli_load_scene_smooth(const char *arg, float smooth, fr_scene **s);
/* Applies FRUSTA_ISA / --isa; reports errors itself. */
int cli_set_isa(const char *name);
float cli_scene_eps(const fr_scene *s);


struct fr_workload;
/* Loads and commits the scene and fills w's view, camera, eps and threads
 * from the flags; reports errors itself (returns the exit code). */
int cli_workload_setup(const char *scene, const cli_view *v, int threads, fr_scene **s, struct fr_workload *w);
const char *cli_scene_name(const fr_scene *s);

/* Whitted and large-packet flags shared by render and bench:
 * --mirror NAMES --glass NAMES --depth N --traversal T --cull C --packet N */
#include "render/whitted.h"
#include "trace/lpacket/lpacket.h"
/* The scene's trees as the large-packet kernels take them. */
fr_lp_scene cli_lp_scene(const fr_scene *s);
typedef struct cli_whitted {
  const char *mirror, *glass; /* NULL: the scene's defaults */
  int depth;                  /* 1..FR_WHITTED_MAX_DEPTH, default 4 */
  fr_lp_opts lp;              /* default ranged, corners */
  int packet;                 /* render: packet side, default 16 */
  int large_flags;            /* --packet, --traversal or --cull given */
} cli_whitted;
void cli_whitted_default(cli_whitted *o);
/* The Whitted and large-packet flags; 0, or 2 after reporting. */
int cli_whitted_from_args(const cli_args *a, cli_whitted *o);
/* Builds the Whitted materials into w (w->mats must point at *mats); reports
 * errors itself and prints how many triangles mirror and refract. */
int cli_whitted_setup(const fr_scene *s, const cli_whitted *o, struct fr_whitted_mats *mats, struct fr_workload *w);
/* The line of how many triangles the Whitted materials m make mirror and glass. */
void cli_whitted_print(const fr_scene *s, const struct fr_whitted_mats *m, int depth);
/* A renderer description's camera (eye, at, up, fov) and lights (the
 * point light and the quad light) from v. */
void cli_desc_view(const fr_view *v, fr_render_desc *d);
#endif
