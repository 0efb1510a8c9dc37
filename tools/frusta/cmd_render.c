/* frusta render: an image of a scene through the public renderer
 * (fr_renderer), with the command's measurement switches (Embree, large
 * packets, the soft-shadow preview's filter and sets, a cluster's ranks)
 * set through its internal tuning (api/renderer_tuning.h). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "api/renderer_tuning.h"
#include "api/scene.h"
#include "base/timer.h"
#include "cli.h"
#include "cli_cluster.h"
#include "cli_path.h"
#include "cli_scene_file.h"
#include "commands.h"
#include "embree_tracer.h"
#include "io/file_read.h"
#include "io/image_write.h"
#include "render/progressive.h"

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

/* out with ".albedo.exr" for its extension */
static void aov_name(const char *out, const char *kind, char *buf, size_t n) {
  const char *dot = strrchr(out, '.');
  const int stem = dot ? (int)(dot - out) : (int)strlen(out);
  snprintf(buf, n, "%.*s.%s.exr", stem, out, kind);
}

typedef struct render_job {
  fr_scene *s;
  fr_render_desc d;
  fr_renderer_tuning tune;
  const char *tracer, *mode; /* for the report: frusta or embree; mft, a trace mode or large packets */
  const cli_path *po;         /* the path flags, for the set-up line */
  int aov;
  const char *out;
} render_job;

/* Passes until done, with a progress line on a terminal; the image, its
 * guides (W*H*10 floats: rgb, albedo, normal, depth) written by rank 0. */
static int run(fr_renderer *r, const render_job *j, int report, float *img, uint64_t *rays, double *seconds,
               double *denoise_seconds) {
  const fr_render_desc *d = &j->d;
  const size_t np = (size_t)d->camera.width * (size_t)d->camera.height;
  const int path = d->shade == FR_RENDER_PATH;
  const int passes = fr_renderer_passes(r);
  const int tty = report && isatty(fileno(stderr)) && cli_cluster_leader() && passes > 1;
  const double t0 = fr_seconds();
  double last = t0;
  *rays = 0;
  int done = 0;
  for (int k = 0; !done; k++) {
    if (fr_renderer_pass(r, &done)) return cli_error(1, "%s", fr_last_error());
    fr_render_stats st;
    fr_renderer_stats(r, &st);
    *rays += st.rays;
    const double now = fr_seconds();
    if (tty && (now - last > 0.5 || done)) {
      last = now;
      const double el = now - t0, left = el / (k + 1) * (passes - k - 1 > 0 ? passes - k - 1 : 0);
      fprintf(stderr, "\r%s: %d/%d passes  %.1f Mrays/s  %.1f s, %.1f s left  ",
              fr_shade_mode_name((fr_shade_mode)d->shade), k + 1, passes, *rays / el * 1e-6, el, left);
      fflush(stderr);
    }
  }
  if (tty) fprintf(stderr, "\n");
  *seconds = fr_seconds() - t0;
  const int display = path && fr_has_suffix(j->out, ".png");
  if (fr_renderer_image(r, display, img, img + 3 * np, img + 6 * np, img + 9 * np)) return cli_error(1, "%s", fr_last_error());
  fr_render_stats st;
  fr_renderer_stats(r, &st);
  *denoise_seconds = st.denoise_seconds;
  return 0;
}

/* The image of j; with ref_out, also soft shadows' 256-sample unfiltered
 * reference, and how far the image is from it. */
static int render(const render_job *j, const char *ref_out) {
  const fr_render_desc *d = &j->d;
  const int W = d->camera.width, H = d->camera.height;
  const size_t np = (size_t)W * (size_t)H;
  fr_renderer *r = NULL, *ref = NULL;
  float *img = malloc(np * 10 * sizeof(float)), *vis = NULL, *rimg = NULL;
  int rc = 0;
  if (!img) { rc = cli_error(1, "out of memory for a %dx%d image", W, H); goto done; }
  const fr_error e = fr_renderer_new(j->s, d, &r);
  if (e) { /* FR_ERR_ARG: a flag's value (a material name), else a file or memory */
    rc = cli_error(e == FR_ERR_ARG ? CLI_USAGE_ERROR : 1, "%s", fr_last_error());
    goto done;
  }
  fr_renderer_tune(r, &j->tune);
  const fr_path_setup *P = fr_renderer_path_setup(r);
  if (P && cli_cluster_leader()) cli_path_print(j->po, P);
  const fr_whitted_mats *mats = fr_renderer_whitted_mats(r);
  if (mats && cli_cluster_leader()) cli_whitted_print(j->s, mats, d->max_depth);
  uint64_t rays;
  double seconds, denoise_seconds;
  if ((rc = run(r, j, 1, img, &rays, &seconds, &denoise_seconds))) goto done;
  if (!cli_cluster_leader()) goto done; /* rank 0 has the image */
  char albedo_out[4096], normal_out[4096];
  aov_name(j->out, "albedo", albedo_out, sizeof albedo_out);
  aov_name(j->out, "normal", normal_out, sizeof normal_out);
  if (fr_image_write(j->out, W, H, img) ||
      (j->aov && (fr_image_write(albedo_out, W, H, img + 3 * np) || fr_image_write(normal_out, W, H, img + 6 * np)))) {
    rc = cli_error(1, "%s", fr_last_error());
    goto done;
  }
  printf("rendered scene=%s tris=%zu size=%dx%d shade=%s spp=%d tracer=%s mode=%s isa=%s threads=%d "
         "build_seconds=%.3f rays=%llu seconds=%.3f mrays=%.2f denoise_seconds=%.4f -> %s%s%s%s%s\n",
         j->s->name, fr_scene_triangle_count(j->s), W, H, fr_shade_mode_name((fr_shade_mode)d->shade),
         fr_renderer_spp(r), j->tracer, j->mode, fr_isa_name(fr_get_isa()), d->threads, j->s->build_seconds,
         (unsigned long long)rays, seconds, rays / seconds * 1e-6, denoise_seconds, j->out, j->aov ? " " : "",
         j->aov ? albedo_out : "", j->aov ? " " : "", j->aov ? normal_out : "");
  if (ref_out) { /* 256 spread light samples, summed unfiltered */
    render_job rj = *j;
    rj.d.spp = 256;
    rj.tune.soft_preview = 0;
    rj.out = ref_out;
    vis = malloc(np * 2 * sizeof(float));
    rimg = malloc(np * 10 * sizeof(float));
    if (!vis || !rimg) { rc = cli_error(1, "out of memory for the reference"); goto done; }
    if (fr_renderer_new(j->s, &rj.d, &ref)) { rc = cli_error(1, "%s", fr_last_error()); goto done; }
    fr_renderer_tune(ref, &j->tune);
    if ((rc = run(ref, &rj, 0, rimg, &rays, &seconds, &denoise_seconds))) goto done;
    if (fr_image_write(ref_out, W, H, rimg)) { rc = cli_error(1, "%s", fr_last_error()); goto done; }
    fr_renderer_visibility(r, vis);
    fr_renderer_visibility(ref, vis + np);
    printf("reference light_samples=256 filter=off -> %s\nmae_visibility=%.4f mae_rgb=%.4f\n", ref_out,
           mae(vis, vis + np, 1, rimg, np), mae(img, rimg, 3, rimg, np));
  }
done:
  fr_renderer_release(r);
  fr_renderer_release(ref);
  free(img), free(vis), free(rimg);
  return rc;
}

int cmd_render(int argc, char **argv) {
  cli_args a;
  int rc = cli_args_parse(CLI_RENDER, argc, argv, 1, &a);
  if (rc) return rc == CLI_HELP_SHOWN ? 0 : rc;
  if ((rc = cli_scene_file_defaults(&a))) return rc;
  const char *scene = a.pos[0], *out = a.val[F_OUT], *ref_out = a.val[F_REFERENCE_OUT];
  int threads = omp_get_num_procs(), mft = -1; /* -1: not given */
  int light_samples = 16, filter = 1;
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
      (rc = cli_arg_choice(&a, F_LIGHT_SETS, sets, 2, &set)) || (rc = cli_arg_onoff(&a, F_FILTER, &filter)) ||
      (rc = cli_arg_onoff(&a, F_MFT, &mft)) || (rc = cli_arg_int(&a, F_LIGHT_SAMPLES, 16, 4096, &light_samples)) ||
      (rc = cli_arg_choice(&a, F_MODE, modes, 6, &mode)) || (rc = cli_arg_choice(&a, F_TRACER, tracers, 2, &embree)) ||
      (rc = cli_arg_onoff(&a, F_DENOISE, &denoise)))
    return rc;
  if ((a.val[F_MODE] || a.val[F_TRACER]) && shade != FR_SM_PATH)
    return cli_error(CLI_USAGE_ERROR, "--mode and --tracer choose how --shade path traces; other shades take --mft");
  if (a.val[F_MODE] && embree) return cli_error(CLI_USAGE_ERROR, "--mode is frusta's; --tracer embree traces streams");
  if (denoise && !fr_shade_mode_progressive((fr_shade_mode)shade))
    return cli_error(CLI_USAGE_ERROR, "--denoise is for path, ao and softshadow, not %s", shades[shade]);
  if (denoise && ref_out) return cli_error(CLI_USAGE_ERROR, "--reference-out and --denoise: give one");
  if (ref_out && shade != FR_SM_SOFTSHADOW) return cli_error(CLI_USAGE_ERROR, "--reference-out is for --shade softshadow");
  if (shade == FR_SM_AO && po.spp % 16)
    return cli_error(CLI_USAGE_ERROR, "ao: --spp wants a multiple of 16 (hemisphere rays per pixel), got '%s'", a.val[F_SPP]);
  if (light_samples % 16)
    return cli_error(CLI_USAGE_ERROR, "--light-samples wants a multiple of 16 (16..4096), got '%s'", a.val[F_LIGHT_SAMPLES]);
  if (!scene || !out)
    return cli_error(CLI_USAGE_ERROR, "usage: frusta render SCENE|--builtin --out FILE.png|.exr|.pfm [flags] "
                                      "(see frusta render --help)");
  if (!fr_image_format_known(out)) return cli_error(CLI_USAGE_ERROR, "%s: unknown image format (use .png, .exr or .pfm)", out);
  if (ref_out && !fr_image_format_known(ref_out))
    return cli_error(CLI_USAGE_ERROR, "%s: unknown image format (use .png, .exr or .pfm)", ref_out);
  if (shade == FR_SM_WHITTED && mft == 1 && wo.large_flags)
    return cli_error(CLI_USAGE_ERROR, "--mft on and --packet/--traversal/--cull: large packets need --mft off");

  fr_workload w;
  memset(&w, 0, sizeof w);
  fr_shade_mode_workload((fr_shade_mode)shade, &w.kind, &w.shade);
  fr_scene *s = NULL;
  fr_cluster_feed *feed = NULL;
  const int set_up = cli_workload_setup(scene, &v, threads, &s, &w);
  if ((rc = cli_cluster_join(set_up, &w, &feed))) {
    if (!set_up) fr_scene_release(s);
    return rc;
  }

  render_job j;
  memset(&j, 0, sizeof j);
  j.s = s, j.out = out, j.aov = shade == FR_SM_PATH && po.aov, j.po = &po;
  fr_render_desc *d = &j.d;
  fr_render_desc_default(d);
  cli_desc_view(&w.view, d);
  d->camera.width = v.width, d->camera.height = v.height;
  d->shade = (fr_render_shade)shade;
  cli_path_desc(&po, d);
  d->spp = shade == FR_SM_SOFTSHADOW ? light_samples : po.spp;
  if (shade == FR_SM_WHITTED) d->max_depth = wo.depth, d->mirror = wo.mirror, d->glass = wo.glass;
  d->denoise = denoise, d->threads = threads;
  d->camera_frusta = mft != 0 && !(shade == FR_SM_WHITTED && wo.large_flags);
  fr_renderer_tuning_default(&j.tune);
  j.tune.feed = w.feed;
  j.tune.whole_path_passes = w.feed != NULL; /* a cluster's tile takes all its samples at once */
  j.tune.progress = !fr_shade_mode_progressive((fr_shade_mode)shade);
  j.tune.soft_preview = d->spp == 16; /* more samples: their mean is the image, no preview needed */
  j.tune.soft_filter = filter;
  j.tune.soft_sets = set ? FR_LIGHT_SETS_SPREAD : FR_LIGHT_SETS_CELLS;
  /* Whitted: camera rays by multi-frusta tracing and the rest as streams
   * (the fastest), or with --mft off or any of --packet, --traversal,
   * --cull: large packets of --packet x --packet (so too with spheres,
   * which multi-frusta tracing does not see) */
  ebr_scene *e = NULL;
  fr_lp_tracer lpc = {s, cli_lp_scene(s), wo.lp, wo.packet};
  char lp_name[64];
  const int frusta = d->camera_frusta && !fr_scene_sphere_count(s) && shade != FR_SM_PATH;
  j.tracer = "frusta";
  j.mode = frusta ? "mft" : shade == FR_SM_PATH ? modes[mode] : "auto";
  if (embree) {
    ebr_options eo = {.threads = threads, .quality = 2}; /* high quality, not robust: Embree's fastest */
    if (ebr_create(s, eo, &e)) { rc = cli_error(1, "embree: cannot build the scene"); goto done; }
    j.tune.has_tracer = 1, j.tune.tracer = ebr_tracer(e, EBR_STREAM, EBR_FLAG_HINT, EBR_PACK_RAYS);
    j.tracer = "embree", j.mode = "stream";
  } else if (shade == FR_SM_WHITTED && !frusta) {
    j.tune.has_tracer = 1, j.tune.tracer = fr_tracer_lp(&lpc);
    snprintf(lp_name, sizeof lp_name, "packet%dx%d/%s/%s", wo.packet, wo.packet, fr_lp_traversal_name(wo.lp.traversal),
             fr_cull_name(wo.lp.cull));
    j.mode = lp_name;
  }
  if (shade == FR_SM_WHITTED && cli_cluster_leader()) printf("whitted tracer=%s\n", j.mode);
  if (!embree && fr_scene_set_trace_mode(s, (fr_trace_mode)mode)) { rc = cli_error(1, "%s", fr_last_error()); goto done; }
  rc = render(&j, ref_out);
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
done:
  ebr_release(e);
  fr_cluster_feed_free(feed);
  fr_scene_release(s);
  return rc;
}
