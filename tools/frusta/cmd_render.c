/* frusta render: an image of a scene through the workload engine. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "api/scene.h"
#include "cli.h"
#include "cli_cluster.h"
#include "cli_scene_file.h"
#include "commands.h"
#include "base/timer.h"
#include "cli_path.h"
#include "embree_tracer.h"
#include "film/denoise.h"
#include "film/tonemap.h"
#include "io/file_read.h"
#include "io/image_write.h"
#include "render/progressive.h"
#include "render/softshadow.h"
#include "render/whitted.h"
#include "render/workload.h"

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
  if (cli_cluster_leader() && fr_image_write(out, w->cam.width, w->cam.height, img)) {
    rc = cli_error(1, "%s", fr_last_error());
    goto done;
  }
  const fr_softshadow_opts used = fr_softshadow_used(so);
  printf("rendered scene=%s tris=%zu size=%dx%d shade=softshadow light_samples=%d filter=%s light_sets=%s tracer=%s "
         "isa=%s threads=%d rays=%llu seconds=%.3f mrays=%.2f -> %s\n",
         s->name, fr_scene_triangle_count(s), w->cam.width, w->cam.height, used.samples, used.filter ? "on" : "off",
         used.sets == FR_LIGHT_SETS_CELLS ? "cells" : "spread", mft ? "mft" : "auto", fr_isa_name(fr_get_isa()), threads,
         (unsigned long long)r.rays, r.seconds, (double)r.rays / r.seconds * 1e-6, out);
  if (ref_out) {
    fr_softshadow_opts ro = {256, 0, FR_LIGHT_SETS_SPREAD};
    fr_workload rw = *w;
    rw.seed = w->seed + 1000;
    rw.progress = 0;
    if (fr_render_softshadow(&rw, &t, &ro, rimg, rvis, &r)) { rc = cli_error(1, "%s", fr_last_error()); goto done; }
    if (cli_cluster_leader() && fr_image_write(ref_out, w->cam.width, w->cam.height, rimg)) {
      rc = cli_error(1, "%s", fr_last_error());
      goto done;
    }
    printf("reference light_samples=256 filter=off -> %s\nmae_visibility=%.4f mae_rgb=%.4f\n", ref_out,
           mae(vis, rvis, 1, rimg, np), mae(img, rimg, 3, rimg, np));
  }
done:
  free(img); free(vis); free(rimg); free(rvis);
  return rc;
}

/* out with ".albedo.exr" for its extension */
static void aov_name(const char *out, const char *kind, char *buf, size_t n) {
  const char *dot = strrchr(out, '.');
  const int stem = dot ? (int)(dot - out) : (int)strlen(out);
  snprintf(buf, n, "%.*s.%s.exr", stem, out, kind);
}

/* --shade path, ao, or softshadow with --denoise: passes summed
 * (render/progressive.h; path's are of FR_PATH_CHUNK samples), a progress
 * line, the mean optionally denoised, written linear (EXR, PFM) or
 * tone-mapped (PNG, path only; the others are in [0, 1] already). */
static int render_progressive(fr_scene *s, fr_workload *w, fr_shade_mode mode, const cli_path *po,
                              const fr_softshadow_opts *so, int denoise, const char *out, int threads, int trace_mode,
                              int embree, int mft) {
  const size_t np = (size_t)w->cam.width * (size_t)w->cam.height;
  const int path = mode == FR_SM_PATH;
  cli_path_run run;
  memset(&run, 0, sizeof run);
  int rc = path ? cli_path_setup(po, w, &run) : 0;
  if (rc) return rc;
  char albedo_out[4096], normal_out[4096];
  aov_name(out, "albedo", albedo_out, sizeof albedo_out);
  aov_name(out, "normal", normal_out, sizeof normal_out);
  float *img = malloc(np * 10 * sizeof(float));
  fr_progressive p;
  memset(&p, 0, sizeof p);
  fr_denoiser *dn = NULL;
  ebr_scene *e = NULL;
  if (!img || fr_progressive_init(&p, w, mode) || (denoise && fr_denoiser_new(w->cam.width, w->cam.height, &dn))) {
    rc = cli_error(1, "out of memory for a %dx%d image", w->cam.width, w->cam.height);
    goto done;
  }
  float *albedo = img + 3 * np, *normal = img + 6 * np, *depth = img + 9 * np;
  static const char *const mode_names[] = {"auto", "single", "packet8", "packet16", "hybrid16", "raystream"};
  if (embree) {
    ebr_options eo = {.threads = threads, .quality = 2}; /* high quality, not robust: Embree's fastest */
    if (ebr_create(s, eo, &e)) { rc = cli_error(1, "embree: cannot build the scene"); goto done; }
  } else if (fr_scene_set_trace_mode(s, (fr_trace_mode)trace_mode)) {
    rc = cli_error(1, "%s", fr_last_error());
    goto done;
  }
  /* camera rays (and soft shadows) as multi-frusta, as the other shades
   * trace them, unless the scene has spheres; paths trace streams only */
  fr_mft_tracer mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  const int use_mft = !e && mft != 0 && mode != FR_SM_PATH && !fr_scene_sphere_count(s);
  fr_tracer t = e ? ebr_tracer(e, EBR_STREAM, EBR_FLAG_HINT, EBR_PACK_RAYS) : use_mft ? fr_tracer_mft(&mctx) : fr_tracer_frusta(s);
  p.w.progress = 0;
  int passes;
  if (path && w->feed) {
    /* a cluster's tile takes all its samples at once: a worker's pixels
     * are then whole sums, the same bits as passes summed here */
    p.spp_per_pass = run.setup.spp;
    p.w.progress = 1;
    passes = 1;
  } else if (path) {
    p.spp_per_pass = FR_PATH_CHUNK;
    passes = (run.setup.spp + FR_PATH_CHUNK - 1) / FR_PATH_CHUNK;
  } else if (mode == FR_SM_SOFTSHADOW) {
    const fr_softshadow_opts used = fr_softshadow_used(so);
    p.soft = used;
    passes = used.samples / 16;
    p.soft_preview = passes == 1;
  } else {
    passes = po->spp / 16;
  }
  uint64_t rays = 0;
  const double t0 = fr_seconds();
  double last = t0;
  /* the progress line is for a person watching */
  const int tty = isatty(fileno(stderr)) && cli_cluster_leader() && passes > 1;
  for (int k = 0; k < passes; k++) {
    fr_workload_result r;
    fr_progressive_pass(&p, &t, NULL, &r);
    if (r.failed) { rc = cli_error(1, "%s", fr_last_error()); goto done; }
    rays += r.rays;
    const double now = fr_seconds();
    if (tty && (now - last > 0.5 || k + 1 == passes)) {
      last = now;
      const double el = now - t0, left = el / (k + 1) * (passes - k - 1);
      fprintf(stderr, "\r%s: %d/%d passes  %.1f Mrays/s  %.1f s, %.1f s left  ", fr_shade_mode_name(mode), k + 1, passes,
              rays / el * 1e-6, el, left);
      fflush(stderr);
    }
  }
  if (tty) fprintf(stderr, "\n");
  fr_progressive_resolve(&p, img, albedo, normal, depth);
  const double render_seconds = fr_seconds() - t0;
  double denoise_seconds = 0.0;
  if (!cli_cluster_leader()) goto done; /* rank 0 has the image */
  if (dn) {
    const double t1 = fr_seconds();
    fr_denoise(dn, img, albedo, normal, depth, fr_progressive_spp(&p), threads, img);
    denoise_seconds = fr_seconds() - t1;
  }
  const int png = fr_has_suffix(out, ".png");
  if (path && png) fr_tonemap_filmic(img, 3 * np, po->exposure);
  if (fr_image_write(out, w->cam.width, w->cam.height, img) ||
      (path && po->aov && (fr_image_write(albedo_out, w->cam.width, w->cam.height, albedo) ||
                           fr_image_write(normal_out, w->cam.width, w->cam.height, normal)))) {
    rc = cli_error(1, "%s", fr_last_error());
    goto done;
  }
  printf("rendered scene=%s tris=%zu size=%dx%d shade=%s spp=%d tracer=%s mode=%s isa=%s threads=%d "
         "build_seconds=%.3f rays=%llu seconds=%.3f mrays=%.2f denoise_seconds=%.4f -> %s%s%s%s%s\n",
         s->name, fr_scene_triangle_count(s), w->cam.width, w->cam.height, fr_shade_mode_name(mode), fr_progressive_spp(&p),
         e ? "embree" : "frusta", e ? "stream" : use_mft ? "mft" : mode_names[trace_mode], fr_isa_name(fr_get_isa()),
         threads, s->build_seconds, (unsigned long long)rays, render_seconds, rays / render_seconds * 1e-6,
         denoise_seconds, out, path && po->aov ? " " : "", path && po->aov ? albedo_out : "",
         path && po->aov ? " " : "", path && po->aov ? normal_out : "");
done:
  free(img);
  fr_progressive_free(&p);
  fr_denoiser_free(dn);
  ebr_release(e);
  cli_path_free(&run);
  return rc;
}

/* The image of the scene in shade, as the flags ask. */
static int render_scene(fr_scene *s, fr_workload *wp, const char *const *val, int shade, const cli_view *vp,
                        const cli_whitted *wop, const cli_path *pop, const fr_softshadow_opts *sop, int mft, int mode,
                        int embree, int denoise, int threads) {
  fr_workload w = *wp;
  const cli_view v = *vp;
  const cli_whitted wo = *wop;
  const cli_path po = *pop;
  const fr_softshadow_opts so = *sop;
  const char *out = val[F_OUT], *ref_out = val[F_REFERENCE_OUT];
  const char *const *shades = fr_shade_mode_names;
  int rc = 0;
  w.seed = 1;
  w.progress = 1;
  if (shade == FR_SM_PATH || shade == FR_SM_AO || (shade == FR_SM_SOFTSHADOW && denoise))
    return render_progressive(s, &w, (fr_shade_mode)shade, &po, &so, denoise, out, threads, mode, embree, mft);
  if (w.kind == FR_WL_SOFT16) /* multi-frusta tracing does not see spheres: such scenes go the packet way */
    return render_soft(s, &w, &so, mft != 0 && !fr_scene_sphere_count(s), out, ref_out, threads);
  fr_whitted_mats mats = {0};
  if (w.kind == FR_WL_WHITTED && (rc = cli_whitted_setup(s, &wo, &mats, &w))) return rc;
  w.image = calloc((size_t)v.width * (size_t)v.height * 3, sizeof(float));
  if (!w.image) { fr_whitted_mats_free(&mats); return cli_error(1, "out of memory for a %dx%d image", v.width, v.height); }
  /* Whitted: camera rays by multi-frusta tracing and the rest as streams
   * (the fastest), or with --mft off or any of --packet, --traversal,
   * --cull: large packets of --packet x --packet */
  fr_lp_tracer lpc = {s, cli_lp_scene(s), wo.lp, wo.packet};
  fr_mft_tracer mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  /* multi-frusta tracing does not see spheres: such scenes go the packet
   * way. Camera rays are traced as frusta by default for every shade, the
   * rest as streams (auto). */
  const int use_mft = mft != 0 && !fr_scene_sphere_count(s) && !(w.kind == FR_WL_WHITTED && wo.large_flags);
  fr_tracer t = use_mft ? fr_tracer_mft(&mctx) : w.kind != FR_WL_WHITTED ? fr_tracer_frusta(s) : fr_tracer_lp(&lpc);
  const int whitted_mft = w.kind == FR_WL_WHITTED && use_mft;
  if (w.kind == FR_WL_WHITTED && cli_cluster_leader()) {
    if (whitted_mft) printf("whitted tracer=mft\n");
    else printf("whitted tracer=packet%dx%d/%s/%s\n", wo.packet, wo.packet, fr_lp_traversal_name(wo.lp.traversal),
                fr_cull_name(wo.lp.cull));
  }
  fr_workload_result r = fr_workload_run(&w, &t);
  if (r.failed) rc = cli_error(1, "%s", fr_last_error());
  else if (!cli_cluster_leader()) rc = 0;
  else if (fr_image_write(out, v.width, v.height, w.image)) rc = cli_error(1, "%s", fr_last_error());
  else
    printf("rendered scene=%s tris=%zu size=%dx%d shade=%s tracer=%s isa=%s threads=%d build_seconds=%.3f rays=%llu "
           "seconds=%.3f mrays=%.2f -> %s\n",
           s->name, fr_scene_triangle_count(s), v.width, v.height, shades[shade],
           use_mft ? "mft" : w.kind == FR_WL_WHITTED ? "packets" : "auto", fr_isa_name(fr_get_isa()), threads,
           s->build_seconds, (unsigned long long)r.rays, r.seconds, (double)r.rays / r.seconds * 1e-6, out);
  free(w.image);
  fr_whitted_mats_free(&mats);
  return rc;
}

int cmd_render(int argc, char **argv) {
  cli_args a;
  int rc = cli_args_parse(CLI_RENDER, argc, argv, 1, &a);
  if (rc) return rc == CLI_HELP_SHOWN ? 0 : rc;
  if ((rc = cli_scene_file_defaults(&a))) return rc;
  const char *scene = a.pos[0], *out = a.val[F_OUT], *ref_out = a.val[F_REFERENCE_OUT];
  int threads = omp_get_num_procs(), mft = -1; /* -1: not given */
  fr_softshadow_opts so = {16, 1, FR_LIGHT_SETS_CELLS};
  const char *const *shades = fr_shade_mode_names;
  static const char *const sets[] = {"cells", "spread"}; /* FR_LIGHT_SETS_CELLS, _SPREAD */
  int shade = 0, set = 0, mode = 0, embree = 0, denoise = 0;
  static const char *const modes[] = {"auto", "single", "packet8", "packet16", "hybrid16", "raystream"}; /* fr_trace_mode order */
  static const char *const tracers[] = {"frusta", "embree"};
  cli_view v;
  cli_whitted wo;
  cli_path po;
  if ((rc = cli_view_from_args(&a, &v)) || (rc = cli_whitted_from_args(&a, &wo)) || (rc = cli_path_from_args(&a, &po)) ||
      (rc = cli_common_from_args(&a, &threads)) || (rc = cli_arg_choice(&a, F_SHADE, shades, FR_SM_COUNT, &shade)) ||
      (rc = cli_arg_choice(&a, F_LIGHT_SETS, sets, 2, &set)) || (rc = cli_arg_onoff(&a, F_FILTER, &so.filter)) ||
      (rc = cli_arg_onoff(&a, F_MFT, &mft)) || (rc = cli_arg_int(&a, F_LIGHT_SAMPLES, 16, 4096, &so.samples)) ||
      (rc = cli_arg_choice(&a, F_MODE, modes, 6, &mode)) || (rc = cli_arg_choice(&a, F_TRACER, tracers, 2, &embree)) ||
      (rc = cli_arg_onoff(&a, F_DENOISE, &denoise)))
    return rc;
  if ((a.val[F_MODE] || a.val[F_TRACER]) && shade != FR_SM_PATH)
    return cli_error(CLI_USAGE_ERROR, "--mode and --tracer choose how --shade path traces; other shades take --mft");
  if (a.val[F_MODE] && embree) return cli_error(CLI_USAGE_ERROR, "--mode is frusta's; --tracer embree traces streams");
  if (denoise && !fr_shade_mode_progressive((fr_shade_mode)shade))
    return cli_error(CLI_USAGE_ERROR, "--denoise is for path, ao and softshadow, not %s", shades[shade]);
  if (denoise && ref_out) return cli_error(CLI_USAGE_ERROR, "--reference-out and --denoise: give one");
  if (shade == FR_SM_AO && po.spp % 16)
    return cli_error(CLI_USAGE_ERROR, "ao: --spp wants a multiple of 16 (hemisphere rays per pixel), got '%s'", a.val[F_SPP]);
  so.sets = set ? FR_LIGHT_SETS_SPREAD : FR_LIGHT_SETS_CELLS;
  if (so.samples % 16)
    return cli_error(CLI_USAGE_ERROR, "--light-samples wants a multiple of 16 (16..4096), got '%s'", a.val[F_LIGHT_SAMPLES]);
  if (!scene || !out)
    return cli_error(CLI_USAGE_ERROR, "usage: frusta render SCENE|--builtin --out FILE.png|.exr|.pfm [flags] "
                                      "(see frusta render --help)");
  if (!fr_image_format_known(out)) return cli_error(CLI_USAGE_ERROR, "%s: unknown image format (use .png, .exr or .pfm)", out);
  if (ref_out && !fr_image_format_known(ref_out))
    return cli_error(CLI_USAGE_ERROR, "%s: unknown image format (use .png, .exr or .pfm)", ref_out);
  fr_workload w;
  memset(&w, 0, sizeof w);
  fr_shade_mode_workload((fr_shade_mode)shade, &w.kind, &w.shade);

  if (w.kind == FR_WL_WHITTED && mft == 1 && wo.large_flags)
    return cli_error(CLI_USAGE_ERROR, "--mft on and --packet/--traversal/--cull: large packets need --mft off");
  fr_scene *s = NULL;
  fr_cluster_feed *feed = NULL;
  const int set_up = cli_workload_setup(scene, &v, threads, &s, &w);
  if ((rc = cli_cluster_join(set_up, &w, &feed))) {
    if (!set_up) fr_scene_release(s);
    return rc;
  }
  rc = render_scene(s, &w, a.val, shade, &v, &wo, &po, &so, mft, mode, embree, denoise, threads);
  if (!rc && feed) { /* the last frame's deal: what each rank rendered, what came to rank 0 */
    uint64_t bytes = 0;
    printf("cluster ranks=%d threads_per_rank=%d rank_tiles=", fr_cluster_size(), threads);
    for (int k = 0; k < fr_cluster_size(); k++) {
      const fr_cluster_share sh = fr_cluster_feed_share(feed, k);
      printf("%s%d", k ? "," : "", sh.tiles);
      bytes += sh.bytes;
    }
    printf(" bytes_sent=%llu\n", (unsigned long long)bytes);
  }
  fr_cluster_feed_free(feed);
  fr_scene_release(s);
  return rc;
}
