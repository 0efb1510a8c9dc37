/* frusta render: an image of a scene through the workload engine. */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "cli.h"
#include "commands.h"
#include "io/image_write.h"
#include "render/workload.h"

int cmd_render(int argc, char **argv) {
  const char *scene = NULL, *out = NULL, *shade = "eyelight";
  cli_view v;
  memset(&v, 0, sizeof v);
  v.width = 1024; v.height = 1024;
  int threads = omp_get_num_procs();
  for (int i = 0; i < argc; i++) {
    int r = cli_view_flag(argc, argv, &i, &v);
    if (r < 0) return CLI_USAGE_ERROR;
    if (r > 0) continue;
    const char *a = argv[i];
    if (strcmp(a, "--out") == 0 || strcmp(a, "--shade") == 0 || strcmp(a, "--threads") == 0) {
      if (i + 1 >= argc) return cli_error(CLI_USAGE_ERROR, "%s needs a value", a);
      const char *val = argv[++i];
      if (a[2] == 'o') out = val;
      else if (a[2] == 's') shade = val;
      else if (!cli_parse_int(val, 1, 1024, &threads)) return cli_error(CLI_USAGE_ERROR, "--threads wants 1..1024, got '%s'", val);
    } else if (strcmp(a, "--builtin") == 0 || a[0] != '-') {
      if (scene) return cli_error(CLI_USAGE_ERROR, "render takes one scene");
      scene = a;
    } else return cli_error(CLI_USAGE_ERROR, "render: unknown option '%s'", a);
  }
  if (!scene || !out) return cli_error(CLI_USAGE_ERROR, "usage: frusta render SCENE|--builtin --out FILE.png|.exr|.pfm [--shade eyelight|normals|shadows]");
  if (!fr_image_format_known(out)) return cli_error(CLI_USAGE_ERROR, "%s: unknown image format (use .png, .exr or .pfm)", out);
  fr_workload w;
  memset(&w, 0, sizeof w);
  if (strcmp(shade, "eyelight") == 0) { w.kind = FR_WL_PRIMARY; w.shade = FR_SHADE_EYELIGHT; }
  else if (strcmp(shade, "normals") == 0) { w.kind = FR_WL_PRIMARY; w.shade = FR_SHADE_NORMALS; }
  else if (strcmp(shade, "shadows") == 0) { w.kind = FR_WL_SHADOW; w.shade = FR_SHADE_LIGHT; }
  else return cli_error(CLI_USAGE_ERROR, "--shade is eyelight, normals or shadows, not '%s'", shade);

  fr_scene *s;
  int rc = cli_workload_setup(scene, &v, threads, &s, &w);
  if (rc) return rc;
  w.seed = 1;
  w.progress = 1;
  w.image = calloc((size_t)v.width * (size_t)v.height * 3, sizeof(float));
  if (!w.image) { fr_scene_release(s); return cli_error(1, "out of memory for a %dx%d image", v.width, v.height); }
  fr_tracer t = fr_tracer_frusta(s);
  fr_workload_result r = fr_workload_run(&w, &t);
  if (fr_image_write(out, v.width, v.height, w.image)) rc = cli_error(1, "%s", fr_last_error());
  else
    printf("rendered scene=%s tris=%zu size=%dx%d shade=%s isa=%s threads=%d build_seconds=%.3f rays=%llu seconds=%.3f mrays=%.2f -> %s\n",
           s->name, fr_scene_triangle_count(s), v.width, v.height, shade, fr_isa_name(fr_get_isa()), threads,
           s->build_seconds, (unsigned long long)r.rays, r.seconds, (double)r.rays / r.seconds * 1e-6, out);
  free(w.image);
  fr_scene_release(s);
  return rc;
}
