/* frusta render: an image of a scene through the workload engine. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "cli.h"
#include "commands.h"
#include "io/image_write.h"
#include "render/softshadow.h"
#include "render/whitted.h"
#include "render/workload.h"

static int onoff(const char *flag, const char *val, int *out) {
  if (!strcmp(val, "on")) *out = 1;
  else if (!strcmp(val, "off")) *out = 0;
  else return cli_error(CLI_USAGE_ERROR, "%s is on or off, not '%s'", flag, val);
  return 0;
}

/* Mean absolute difference of two images of ch channels per pixel, over
 * the n pixels that hit (not background in the RGB image img). */
static double mae(const float *a, const float *b, int ch, const float *img, size_t n) {
  double sum = 0.0;
  size_t cnt = 0;
  for (size_t i = 0; i < n; i++) {
    if (img[3 * i] == 0.05f && img[3 * i + 1] == 0.05f && img[3 * i + 2] == 0.05f) continue; /* background */
    for (int c = 0; c < ch; c++) sum += fabs((double)a[(size_t)ch * i + c] - (double)b[(size_t)ch * i + c]);
    cnt += (size_t)ch;
  }
  return cnt ? sum / (double)cnt : 0.0;
}

/* --shade softshadow: visibility by multi-frusta tracing, optionally against a
 * many-sample reference rendered in the same run. */
static int render_soft(fr_scene *s, fr_workload *w, const fr_softshadow_opts *so, int mft, const char *out,
                       const char *ref_out, int threads) {
  size_t np = (size_t)w->cam.width * (size_t)w->cam.height;
  float *img = malloc(np * 3 * sizeof(float)), *vis = malloc(np * sizeof(float));
  float *rimg = ref_out ? malloc(np * 3 * sizeof(float)) : NULL, *rvis = ref_out ? malloc(np * sizeof(float)) : NULL;
  int rc = 0;
  if (!img || !vis || (ref_out && (!rimg || !rvis))) { rc = cli_error(1, "out of memory for a %dx%d image", w->cam.width, w->cam.height); goto done; }
  fr_mft_tracer ctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  fr_tracer t = mft ? fr_tracer_mft(&ctx) : fr_tracer_frusta(s);
  fr_workload_result r;
  if (fr_render_softshadow(w, &t, so, img, vis, &r)) { rc = cli_error(1, "%s", fr_last_error()); goto done; }
  if (fr_image_write(out, w->cam.width, w->cam.height, img)) { rc = cli_error(1, "%s", fr_last_error()); goto done; }
  printf("rendered scene=%s tris=%zu size=%dx%d shade=softshadow light_samples=%d filter=%s light_sets=%s tracer=%s "
         "isa=%s threads=%d rays=%llu seconds=%.3f mrays=%.2f -> %s\n",
         s->name, fr_scene_triangle_count(s), w->cam.width, w->cam.height, so->samples, so->filter ? "on" : "off",
         so->sets == FR_LIGHT_SETS_CELLS ? "cells" : "spread", mft ? "mft" : "auto", fr_isa_name(fr_get_isa()), threads,
         (unsigned long long)r.rays, r.seconds, (double)r.rays / r.seconds * 1e-6, out);
  if (ref_out) {
    fr_softshadow_opts ro = {256, 0, FR_LIGHT_SETS_SPREAD};
    fr_workload rw = *w;
    rw.seed = w->seed + 1000;
    rw.progress = 0;
    if (fr_render_softshadow(&rw, &t, &ro, rimg, rvis, &r)) { rc = cli_error(1, "%s", fr_last_error()); goto done; }
    if (fr_image_write(ref_out, w->cam.width, w->cam.height, rimg)) { rc = cli_error(1, "%s", fr_last_error()); goto done; }
    printf("reference light_samples=256 filter=off -> %s\nmae_visibility=%.4f mae_rgb=%.4f\n", ref_out,
           mae(vis, rvis, 1, rimg, np), mae(img, rimg, 3, rimg, np));
  }
done:
  free(img); free(vis); free(rimg); free(rvis);
  return rc;
}

int cmd_render(int argc, char **argv) {
  const char *scene = NULL, *out = NULL, *shade = "eyelight";
  cli_view v;
  memset(&v, 0, sizeof v);
  v.width = 1024; v.height = 1024;
  int threads = omp_get_num_procs(), mft = -1; /* -1: not given */
  const char *ref_out = NULL;
  fr_softshadow_opts so = {16, 1, FR_LIGHT_SETS_CELLS};
  cli_whitted wo;
  cli_whitted_default(&wo);
  for (int i = 0; i < argc; i++) {
    int r = cli_view_flag(argc, argv, &i, &v);
    if (r == 0) r = cli_whitted_flag(argc, argv, &i, &wo);
    if (r < 0) return CLI_USAGE_ERROR;
    if (r > 0) continue;
    const char *a = argv[i];
    if (!strcmp(a, "--light-samples") || !strcmp(a, "--filter") || !strcmp(a, "--light-sets") || !strcmp(a, "--mft") ||
        !strcmp(a, "--reference-out")) {
      if (i + 1 >= argc) return cli_error(CLI_USAGE_ERROR, "%s needs a value", a);
      const char *val = argv[++i];
      if (!strcmp(a, "--light-samples")) {
        if (!cli_parse_int(val, 16, 4096, &so.samples) || so.samples % 16)
          return cli_error(CLI_USAGE_ERROR, "--light-samples wants a multiple of 16 (16..4096), got '%s'", val);
      } else if (!strcmp(a, "--filter")) {
        if (onoff(a, val, &so.filter)) return CLI_USAGE_ERROR;
      } else if (!strcmp(a, "--mft")) {
        if (onoff(a, val, &mft)) return CLI_USAGE_ERROR;
      } else if (!strcmp(a, "--reference-out")) {
        ref_out = val;
      } else if (!strcmp(val, "cells")) so.sets = FR_LIGHT_SETS_CELLS;
      else if (!strcmp(val, "spread")) so.sets = FR_LIGHT_SETS_SPREAD;
      else return cli_error(CLI_USAGE_ERROR, "--light-sets is cells or spread, not '%s'", val);
      continue;
    }
    if (strcmp(a, "--out") == 0 || strcmp(a, "--shade") == 0 || strcmp(a, "--threads") == 0) {
      if (i + 1 >= argc) return cli_error(CLI_USAGE_ERROR, "%s needs a value", a);
      const char *val = argv[++i];
      if (a[2] == 'o') out = val;
      else if (a[2] == 's') shade = val;
      else if (!cli_parse_int(val, 1, 1024, &threads)) return cli_error(CLI_USAGE_ERROR, "--threads wants 1..1024, got '%s'", val);
    } else if (cli_is_builtin(a) || a[0] != '-') {
      if (scene) return cli_error(CLI_USAGE_ERROR, "render takes one scene");
      scene = a;
    } else return cli_error(CLI_USAGE_ERROR, "render: unknown option '%s'", a);
  }
  if (!scene || !out)
    return cli_error(CLI_USAGE_ERROR, "usage: frusta render SCENE|--builtin --out FILE.png|.exr|.pfm "
                                      "[--shade eyelight|normals|shadows|softshadow|whitted]");
  if (!fr_image_format_known(out)) return cli_error(CLI_USAGE_ERROR, "%s: unknown image format (use .png, .exr or .pfm)", out);
  if (ref_out && !fr_image_format_known(ref_out))
    return cli_error(CLI_USAGE_ERROR, "%s: unknown image format (use .png, .exr or .pfm)", ref_out);
  fr_workload w;
  memset(&w, 0, sizeof w);
  if (strcmp(shade, "eyelight") == 0) { w.kind = FR_WL_PRIMARY; w.shade = FR_SHADE_EYELIGHT; }
  else if (strcmp(shade, "normals") == 0) { w.kind = FR_WL_PRIMARY; w.shade = FR_SHADE_NORMALS; }
  else if (strcmp(shade, "shadows") == 0) { w.kind = FR_WL_SHADOW; w.shade = FR_SHADE_LIGHT; }
  else if (strcmp(shade, "softshadow") == 0) { w.kind = FR_WL_SOFT16; w.shade = FR_SHADE_LIGHT; }
  else if (strcmp(shade, "whitted") == 0) { w.kind = FR_WL_WHITTED; w.shade = FR_SHADE_LIGHT; }
  else return cli_error(CLI_USAGE_ERROR, "--shade is eyelight, normals, shadows, softshadow or whitted, not '%s'", shade);

  fr_scene *s;
  int rc = cli_workload_setup(scene, &v, threads, &s, &w);
  if (rc) return rc;
  w.seed = 1;
  w.progress = 1;
  if (w.kind == FR_WL_SOFT16) {
    /* multi-frusta tracing does not see spheres: such scenes go the packet way */
    rc = render_soft(s, &w, &so, mft != 0 && !fr_scene_sphere_count(s), out, ref_out, threads);
    fr_scene_release(s);
    return rc;
  }
  fr_whitted_mats mats = {0};
  if (w.kind == FR_WL_WHITTED && (rc = cli_whitted_setup(s, &wo, &mats, &w))) { fr_scene_release(s); return rc; }
  w.image = calloc((size_t)v.width * (size_t)v.height * 3, sizeof(float));
  if (!w.image) { fr_whitted_mats_free(&mats); fr_scene_release(s); return cli_error(1, "out of memory for a %dx%d image", v.width, v.height); }
  /* Whitted: camera rays by multi-frusta tracing and the rest as streams
   * (the fastest measured, see docs/performance-log.md), or with --mft off or any of
   * --packet, --traversal, --cull: large packets of --packet x --packet */
  fr_lp_tracer lpc = {s, cli_lp_scene(s), wo.lp, wo.packet};
  fr_mft_tracer mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  if (w.kind == FR_WL_WHITTED && mft == 1 && wo.large_flags) {
    fr_whitted_mats_free(&mats); fr_scene_release(s); free(w.image);
    return cli_error(CLI_USAGE_ERROR, "--mft on and --packet/--traversal/--cull: large packets need --mft off");
  }
  /* multi-frusta tracing does not see spheres: such scenes go the packet
   * way. Camera rays are traced as frusta by default for every shade (1.5-2.8x
   * packets on the shared scenes, docs/performance-log.md "Multi-frusta triangle tests
   * without branches"); the rest as streams (auto). */
  const int use_mft = mft != 0 && !fr_scene_sphere_count(s) && !(w.kind == FR_WL_WHITTED && wo.large_flags);
  fr_tracer t = use_mft ? fr_tracer_mft(&mctx) : w.kind != FR_WL_WHITTED ? fr_tracer_frusta(s) : fr_tracer_lp(&lpc);
  const int whitted_mft = w.kind == FR_WL_WHITTED && use_mft;
  if (w.kind == FR_WL_WHITTED) {
    if (whitted_mft) printf("whitted tracer=mft\n");
    else printf("whitted tracer=packet%dx%d/%s/%s\n", wo.packet, wo.packet, fr_lp_traversal_name(wo.lp.traversal),
                fr_cull_name(wo.lp.cull));
  }
  fr_workload_result r = fr_workload_run(&w, &t);
  if (fr_image_write(out, v.width, v.height, w.image)) rc = cli_error(1, "%s", fr_last_error());
  else
    printf("rendered scene=%s tris=%zu size=%dx%d shade=%s tracer=%s isa=%s threads=%d build_seconds=%.3f rays=%llu "
           "seconds=%.3f mrays=%.2f -> %s\n",
           s->name, fr_scene_triangle_count(s), v.width, v.height, shade,
           use_mft ? "mft" : w.kind == FR_WL_WHITTED ? "packets" : "auto", fr_isa_name(fr_get_isa()), threads,
           s->build_seconds, (unsigned long long)r.rays, r.seconds, (double)r.rays / r.seconds * 1e-6, out);
  free(w.image);
  fr_whitted_mats_free(&mats);
  fr_scene_release(s);
  return rc;
}
