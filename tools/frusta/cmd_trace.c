/* frusta trace SCENE RAYS --query closest|any --out FILE: answers a ray file
 * (docs/rayfile.md) with frusta, or with Embree for comparison.
 * --mode picks frusta's kernels: single rays (default), or the stream calls
 * in packet8, packet16, hybrid16, auto or raystream mode over consecutive
 * rays. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "cli_scene_file.h"
#include "commands.h"
#include "embree_tracer.h"
#include "io/file_read.h"
#include "io/rayfile.h"

int cmd_trace(int argc, char **argv) {
  cli_args a;
  int rc = cli_args_parse(CLI_TRACE, argc, argv, 2, &a);
  if (rc) return rc == CLI_HELP_SHOWN ? 0 : rc;
  if ((rc = cli_scene_file_defaults(&a))) return rc;
  const char *scene = a.pos[0], *rays_path = a.pos[1], *out = a.val[F_OUT];
  static const char *const modes[] = {"auto", "single", "packet8", "packet16", "hybrid16", "raystream"}; /* fr_trace_mode order */
  static const char *const queries[] = {"any", "closest"}, *const tracers[] = {"frusta", "embree"};
  int mode = FR_TRACE_SINGLE, closest = 0, use_embree = 0;
  if ((rc = cli_arg_choice(&a, F_MODE, modes, 6, &mode)) || (rc = cli_arg_choice(&a, F_QUERY, queries, 2, &closest)) ||
      (rc = cli_arg_choice(&a, F_TRACER, tracers, 2, &use_embree)) || (a.val[F_ISA] && (rc = cli_set_isa(a.val[F_ISA]))))
    return rc;
  if (!scene || !rays_path || !out || !a.val[F_QUERY])
    return cli_error(CLI_USAGE_ERROR, "usage: frusta trace SCENE RAYS --query closest|any --out FILE [flags] "
                                      "(see frusta trace --help)");

  fr_ray *rays;
  size_t n;
  if (fr_rays_read(rays_path, &rays, &n)) return cli_error(1, "%s", fr_last_error());
  fr_scene *s;
  int lrc = cli_load_scene(scene, &s);
  if (lrc) { free(rays); return lrc; }
  fr_scene_set_trace_mode(s, (fr_trace_mode)mode);
  const int stream = !use_embree && mode != FR_TRACE_SINGLE;
  const size_t chunk = 4096; /* a multiple of 16: packets never straddle chunks */
  ebr_scene *e = NULL;
  if (use_embree) {
    ebr_options o = {.threads = 0, .quality = 2, .robust = 1}; /* robust: Embree's watertight mode */
    if (ebr_create(s, o, &e)) { free(rays); fr_scene_release(s); return cli_error(1, "embree: cannot build the scene"); }
  }
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
