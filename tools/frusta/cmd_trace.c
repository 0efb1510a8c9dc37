/* frusta trace SCENE RAYS --query closest|any --out FILE: answers a ray file
 * (../shared/spec/rayfile.md) with frusta, or with Embree for comparison.
 * --mode picks frusta's kernels: single rays (default), or the stream calls
 * in packet8, packet16, hybrid16, auto or raystream mode over consecutive
 * rays. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "commands.h"
#include "embree_tracer.h"
#include "io/file_read.h"
#include "io/rayfile.h"

int cmd_trace(int argc, char **argv) {
  const char *scene = NULL, *rays_path = NULL, *out = NULL, *query = NULL, *tracer = "frusta";
  static const char *mode_names[] = {"auto", "single", "packet8", "packet16", "hybrid16", "raystream"}; /* fr_trace_mode order */
  int mode = FR_TRACE_SINGLE;
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i];
    if ((strcmp(a, "--query") == 0 || strcmp(a, "--out") == 0 || strcmp(a, "--tracer") == 0 || strcmp(a, "--isa") == 0 ||
         strcmp(a, "--mode") == 0)) {
      if (i + 1 >= argc) return cli_error(CLI_USAGE_ERROR, "%s needs a value", a);
      const char *v = argv[++i];
      if (a[2] == 'q') query = v;
      else if (a[2] == 'o') out = v;
      else if (a[2] == 't') tracer = v;
      else if (a[2] == 'm') {
        mode = -1;
        for (int m = 0; m < (int)(sizeof mode_names / sizeof mode_names[0]); m++)
          if (strcmp(v, mode_names[m]) == 0) mode = m;
        if (mode < 0) return cli_error(CLI_USAGE_ERROR, "--mode is single, packet8, packet16, hybrid16, auto or raystream, not '%s'", v);
      } else if (cli_set_isa(v)) return 1;
    } else if (a[0] == '-' && !cli_is_builtin(a)) {
      return cli_error(CLI_USAGE_ERROR, "trace: unknown option '%s'", a);
    } else if (!scene) scene = a;
    else if (!rays_path) rays_path = a;
    else return cli_error(CLI_USAGE_ERROR, "trace: unexpected argument '%s'", a);
  }
  if (!scene || !rays_path || !out || !query)
    return cli_error(CLI_USAGE_ERROR, "usage: frusta trace SCENE RAYS --query closest|any --out FILE [--tracer frusta|embree] [--mode M]");
  int closest = strcmp(query, "closest") == 0;
  if (!closest && strcmp(query, "any") != 0) return cli_error(CLI_USAGE_ERROR, "--query is closest or any, not '%s'", query);
  int use_embree = strcmp(tracer, "embree") == 0;
  if (!use_embree && strcmp(tracer, "frusta") != 0) return cli_error(CLI_USAGE_ERROR, "--tracer is frusta or embree, not '%s'", tracer);

  fr_ray *rays;
  size_t n;
  if (fr_rays_read(rays_path, &rays, &n)) return cli_error(1, "%s", fr_last_error());
  fr_scene *s;
  int lrc = cli_load_scene(scene, &s);
  if (lrc) { free(rays); return lrc; }
  fr_trace_options topt;
  fr_trace_options_default(&topt);
  topt.mode = (fr_trace_mode)mode;
  fr_scene_set_trace_options(s, &topt);
  const int stream = !use_embree && mode != FR_TRACE_SINGLE;
  const size_t chunk = 4096; /* a multiple of 16: packets never straddle chunks */
  ebr_scene *e = NULL;
  if (use_embree) {
    ebr_options o = {.threads = 0, .quality = 2, .robust = 1}; /* robust: Embree's watertight mode */
    if (ebr_create(s, o, &e)) { free(rays); fr_scene_release(s); return cli_error(1, "embree: cannot build the scene"); }
  }
  int rc = 0;
  if (closest) {
    fr_hit *hits = malloc((n ? n : 1) * sizeof *hits);
    if (!hits) rc = cli_error(1, "out of memory for %zu hits", n);
    else {
      if (stream) {
#pragma omp parallel for schedule(dynamic, 1)
        for (size_t c = 0; c < n; c += chunk) fr_intersect_stream(s, rays + c, hits + c, n - c < chunk ? n - c : chunk);
      } else {
#pragma omp parallel for schedule(dynamic, 4096)
        for (size_t i = 0; i < n; i++) {
          if (e) ebr_intersect1(e, &rays[i], &hits[i]);
          else fr_intersect1(s, &rays[i], &hits[i]);
        }
      }
      if (fr_hits_write(out, hits, n)) rc = cli_error(1, "%s", fr_last_error());
    }
    free(hits);
  } else {
    uint8_t *occ = malloc(n ? n : 1);
    if (!occ) rc = cli_error(1, "out of memory for %zu rays", n);
    else {
      if (stream) {
#pragma omp parallel for schedule(dynamic, 1)
        for (size_t c = 0; c < n; c += chunk) fr_occluded_stream(s, rays + c, occ + c, n - c < chunk ? n - c : chunk);
      } else {
#pragma omp parallel for schedule(dynamic, 4096)
        for (size_t i = 0; i < n; i++) occ[i] = (uint8_t)(e ? ebr_occluded1(e, &rays[i]) : fr_occluded1(s, &rays[i]));
      }
      if (fr_occl_write(out, occ, n)) rc = cli_error(1, "%s", fr_last_error());
    }
    free(occ);
  }
  ebr_release(e);
  fr_scene_release(s);
  free(rays);
  return rc;
}
