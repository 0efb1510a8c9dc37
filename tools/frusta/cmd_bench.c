/*
 * frusta bench: the workloads of ../shared/spec/workloads.md, frusta and Embree
 * side by side in one process, on the same scene, rays and threads. Each
 * (tracer, mode) run is repeated K times; the line reports the best and the
 * median. The repetitions are interleaved, round-robin over every run
 * selected for a workload: this VM's speed drifts by up to 2x within one
 * process, and runs done one after the other each saw a different stretch
 * of it, so their ratios measured the host as much as the tracers.
 */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "cli.h"
#include "commands.h"
#include "embree_tracer.h"
#include "render/workload.h"
#include "trace/counters.h"

/* single: the default single-ray BVH (8-wide); single4: the MIC paper's BVH4;
 * packet8/packet16: packets alone; hybrid16: packets dropping to single rays;
 * auto: what fr_intersect_stream does by default; mft: camera rays and soft
 * shadows by multi-frusta tracing, the other rays as auto; raystream: every
 * ray in ray streams of up to 64; packetNxN: large
 * packets of N x N rays on the binary BVH (--traversal, --cull). */
static const char *frusta_modes[] = {"single", "single4", "packet8", "packet16", "hybrid16", "auto", "mft",
                                     "raystream", "packet2x2", "packet4x4", "packet8x8", "packet16x16", "packet32x32"};
#define N_FRUSTA_MODES 13
#define MODE_MFT 6
#define MODE_LARGE 8 /* packet2x2 .. packet32x32 */

static void set_frusta_mode(fr_scene *s, int m, const fr_trace_options *base, int single_width) {
  static const fr_trace_mode modes[] = {FR_TRACE_SINGLE, FR_TRACE_SINGLE, FR_TRACE_PACKET8, FR_TRACE_PACKET16,
                                        FR_TRACE_HYBRID16, FR_TRACE_AUTO, FR_TRACE_AUTO, FR_TRACE_RAYSTREAM};
  fr_trace_options o = *base;
  o.mode = m < MODE_LARGE ? modes[m] : FR_TRACE_AUTO;
  fr_scene_set_trace_options(s, &o);
  fr_scene_set_bvh_width(s, m == 0 ? 8 : m == 1 ? 4 : single_width);
}

static int parse_onoff(const char *flag, const char *val, int *out) {
  if (!strcmp(val, "on")) *out = 1;
  else if (!strcmp(val, "off")) *out = 0;
  else return cli_error(CLI_USAGE_ERROR, "%s is on or off, not '%s'", flag, val);
  return 0;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* One (tracer, mode) run of a workload: how to trace, and what its
 * repetitions measured. */
typedef struct bench_run {
  const char *tracer; /* "frusta" or "embree" */
  int mode;           /* index into frusta_modes, or an ebr_mode */
  char name[96];
  fr_lp_tracer lpc;   /* large packets: the tracer's context */
  fr_tracer t;
  double secs[64];
  double stage[64][FR_STAGES]; /* Whitted: each repetition's stage times */
  uint64_t rays;
  fr_counters c;      /* summed over the repetitions */
  ebr_flag flag;      /* Embree: the context flag and packing traced */
  ebr_packing packing;
} bench_run;

static void report(const fr_workload *w0, const bench_run *r, const char *scene, size_t tris, int repeat) {
  double secs[64];
  memcpy(secs, r->secs, sizeof(double) * (size_t)repeat);
  qsort(secs, (size_t)repeat, sizeof(double), cmp_double);
  double best = secs[0], med = secs[repeat / 2];
  const char *tracer = r->tracer, *mode = r->name;
  uint64_t rays = r->rays;
  char embree[64] = "";
  if (r->tracer[0] == 'e')
    snprintf(embree, sizeof embree, " flag=%s packing=%s", ebr_flag_name(r->flag), ebr_packing_name(r->packing));
  printf("scene=%s tris=%zu workload=%s tracer=%s mode=%s threads=%d rays=%llu seconds=%.4f mrays=%.2f median_seconds=%.4f median_mrays=%.2f%s\n",
         scene, tris, fr_workload_name(w0->kind), tracer, mode, w0->threads, (unsigned long long)rays, best,
         (double)rays / best * 1e-6, med, (double)rays / med * 1e-6, embree);
  if (w0->kind == FR_WL_WHITTED) {
    /* the stages of the fastest repetition, in thread-seconds: which part of
     * a Whitted frame the tracer speeds up, and how much is the renderer's */
    int b = 0;
    for (int i = 1; i < repeat; i++)
      if (r->secs[i] < r->secs[b]) b = i;
    const double *st = r->stage[b];
    printf("stages tracer=%s mode=%s workload=%s camera_s=%.4f shadow_s=%.4f secondary_s=%.4f shade_s=%.4f\n", tracer,
           mode, fr_workload_name(w0->kind), st[FR_STAGE_CAMERA], st[FR_STAGE_SHADOW], st[FR_STAGE_SECONDARY],
           st[FR_STAGE_SHADE]);
  }
  fr_counters c = r->c;
  if (fr_counters_enabled() && c.rays)
    printf("counters tracer=%s mode=%s workload=%s per_ray nodes=%.2f box_tests=%.2f leaves=%.2f tri_tests=%.2f "
           "cache_tries=%llu cache_hits=%llu\n",
           tracer, mode, fr_workload_name(w0->kind), (double)c.nodes / c.rays, (double)c.box_tests / c.rays,
           (double)c.leaves / c.rays, (double)c.tri_tests / c.rays, (unsigned long long)c.cache_tries,
           (unsigned long long)c.cache_hits);
  if (fr_counters_enabled() && c.mft_batches)
    printf("counters tracer=%s mode=%s workload=%s batches=%llu per_batch nodes=%.2f box_tests=%.2f "
           "avg_active_frusta=%.2f tris=%.2f tri_frusta=%.2f tri_frusta_left=%.2f ray_batches=%llu stream_batches=%llu cached_leaves=%llu "
           "stopped_batches=%llu shafts=%llu shaft_fails=%llu shaft_box_tests=%.2f shaft_batches=%llu plane_rays=%llu plane_frusta=%llu plane_whole=%llu\n",
           tracer, mode, fr_workload_name(w0->kind), (unsigned long long)c.mft_batches,
           (double)c.mft_nodes / c.mft_batches, (double)c.mft_box_tests / c.mft_batches,
           c.mft_box_tests ? (double)c.mft_box_lanes / c.mft_box_tests : 0.0, (double)c.mft_tris / c.mft_batches,
           (double)c.mft_tri_frusta / c.mft_batches, (double)c.mft_tri_left / c.mft_batches,
           (unsigned long long)c.mft_ray_batches, (unsigned long long)c.mft_stream_batches,
           (unsigned long long)c.mft_cached_leaves, (unsigned long long)c.mft_stopped_batches,
           (unsigned long long)c.mft_shafts, (unsigned long long)c.mft_shaft_fails,
           (double)c.mft_shaft_box_tests / c.mft_batches, (unsigned long long)c.mft_shaft_batches,
           (unsigned long long)c.mft_plane_rays, (unsigned long long)c.mft_plane_frusta,
           (unsigned long long)c.mft_plane_whole);
  if (fr_counters_enabled() && c.packets)
    printf("counters tracer=%s mode=%s workload=%s packets=%llu per_packet pk_nodes=%.2f pk_box_tests=%.2f "
           "pk_tri_tests=%.2f pk_quad_tests=%.2f ia_culled=%.2f mailbox_hits=%.2f switches=%.2f avg_active_box=%.2f "
           "avg_active_tri=%.2f plane_rays=%.2f\n",
           tracer, mode, fr_workload_name(w0->kind), (unsigned long long)c.packets, (double)c.pk_nodes / c.packets,
           (double)c.pk_box_tests / c.packets, (double)c.pk_tri_tests / c.packets, (double)c.pk_quad_tests / c.packets,
           (double)c.ia_culled / c.packets,
           (double)c.mailbox_hits / c.packets, (double)c.switches / c.packets,
           c.pk_box_tests ? (double)c.pk_box_lanes / c.pk_box_tests : 0.0,
           c.pk_tri_tests ? (double)c.pk_tri_lanes / c.pk_tri_tests : 0.0, (double)c.pk_plane_rays / c.packets);
  if (fr_counters_enabled() && c.lp_packets)
    printf("counters tracer=%s mode=%s workload=%s packets=%llu per_packet rays=%.1f nodes=%.2f culled=%.2f "
           "box_chunks=%.2f leaves=%.2f prims=%.2f tris_culled=%.2f tri_chunks=%.2f spheres_culled=%.2f sphere_chunks=%.2f\n",
           tracer, mode, fr_workload_name(w0->kind), (unsigned long long)c.lp_packets, (double)c.rays / c.lp_packets,
           (double)c.lp_nodes / c.lp_packets, (double)c.lp_culled / c.lp_packets,
           (double)c.lp_box_chunks / c.lp_packets, (double)c.lp_leaves / c.lp_packets,
           (double)c.lp_tris / c.lp_packets, (double)c.lp_tri_culled / c.lp_packets,
           (double)c.lp_tri_chunks / c.lp_packets, (double)c.lp_sph_culled / c.lp_packets,
           (double)c.lp_sph_chunks / c.lp_packets);
  fflush(stdout);
}

/* --mode: all, or a comma-separated list of mode names; *fsel and *esel get
 * the frusta and Embree modes picked (bit m: frusta_modes[m], ebr_mode m).
 * A name must belong to a tracer in use. */
static int parse_modes(const char *list, int use_frusta, int use_embree, unsigned *fsel, unsigned *esel) {
  *fsel = *esel = 0;
  if (!strcmp(list, "all")) {
    if (use_frusta) *fsel = (1u << N_FRUSTA_MODES) - 1;
    if (use_embree) *esel = (1u << EBR_MODE_COUNT) - 1;
    return 0;
  }
  char buf[256];
  if (strlen(list) >= sizeof buf) return cli_error(CLI_USAGE_ERROR, "--mode: list too long");
  memcpy(buf, list, strlen(list) + 1);
  for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
    int known = 0;
    ebr_mode em;
    for (int m = 0; m < N_FRUSTA_MODES; m++)
      if (use_frusta && !strcmp(tok, frusta_modes[m])) { *fsel |= 1u << m; known = 1; }
    if (use_embree && ebr_mode_parse(tok, &em)) { *esel |= 1u << em; known = 1; }
    if (!known)
      return cli_error(CLI_USAGE_ERROR, "no tracer in use has mode '%s' (frusta: single, single4, packet8, packet16, "
                       "hybrid16, auto, mft, raystream, packet2x2 .. packet32x32; embree: single, packet4, packet8, packet16, "
                       "stream; or all)", tok);
  }
  if (!*fsel && !*esel) return cli_error(CLI_USAGE_ERROR, "--mode: no mode given");
  return 0;
}

/* Embree at its best: every context flag and packing the run may use
 * (flag < 0, packing < 0: all that apply) traced twice, interleaved; the
 * run keeps the fastest. Packing by samples applies where the workload's
 * rays come in runs of 16 per pixel (soft16, ao16) and packets or streams
 * group them. */
static void choose_embree_variant(const fr_workload *w, ebr_scene *e, bench_run *r, int flag, int packing) {
  const int runs16 = w->kind == FR_WL_SOFT16 || w->kind == FR_WL_AO16;
  const int grouped = r->mode != EBR_SINGLE;
  double best[EBR_FLAG_COUNT][EBR_PACK_COUNT];
  int use[EBR_FLAG_COUNT][EBR_PACK_COUNT], n = 0;
  for (int f = 0; f < EBR_FLAG_COUNT; f++)
    for (int p = 0; p < EBR_PACK_COUNT; p++) {
      use[f][p] = (flag < 0 || flag == f) && (packing < 0 ? p == EBR_PACK_RAYS || (runs16 && grouped) : packing == p);
      best[f][p] = 1e30;
      n += use[f][p];
    }
  r->flag = flag < 0 ? EBR_FLAG_HINT : (ebr_flag)flag;
  r->packing = packing < 0 ? EBR_PACK_RAYS : (ebr_packing)packing;
  if (n > 1)
    for (int rep = 0; rep < 2; rep++)
      for (int f = 0; f < EBR_FLAG_COUNT; f++)
        for (int p = 0; p < EBR_PACK_COUNT; p++) {
          if (!use[f][p]) continue;
          fr_tracer t = ebr_tracer(e, (ebr_mode)r->mode, (ebr_flag)f, (ebr_packing)p);
          fr_workload_result res = fr_workload_run(w, &t);
          if (res.seconds < best[f][p]) best[f][p] = res.seconds;
          if (best[f][p] < best[r->flag][r->packing] || !use[r->flag][r->packing]) {
            r->flag = (ebr_flag)f;
            r->packing = (ebr_packing)p;
          }
        }
  r->t = ebr_tracer(e, (ebr_mode)r->mode, r->flag, r->packing);
}

int cmd_bench(int argc, char **argv) {
  const char *scene = NULL, *workload = NULL, *mode = NULL, *tracer = "frusta";
  cli_view v;
  memset(&v, 0, sizeof v);
  v.width = 1024; v.height = 1024;
  int threads = omp_get_num_procs(), repeat = 3, embree_flag = -1, embree_packing = -1;
  fr_trace_options topt;
  fr_trace_options_default(&topt);
  fr_mft_opts mopt = fr_mft_opts_default();
  int mft_leaf = FR_MFT_LEAF, mft_leaf_set = 0, mft_no_fallback = 0, mft_no_shaft = 0;
  fr_light_sets light_sets = FR_LIGHT_SETS_SPREAD;
  cli_whitted wo;
  cli_whitted_default(&wo);
  for (int i = 0; i < argc; i++) {
    int r = cli_view_flag(argc, argv, &i, &v);
    if (r == 0) r = cli_whitted_flag(argc, argv, &i, &wo);
    if (r < 0) return CLI_USAGE_ERROR;
    if (r > 0) continue;
    const char *a = argv[i];
    if (!strcmp(a, "--threshold") || !strcmp(a, "--mailbox") || !strcmp(a, "--axis-aligned") || !strcmp(a, "--ia") ||
        !strcmp(a, "--packet-width") || !strcmp(a, "--corner-rays") || !strcmp(a, "--shrink") || !strcmp(a, "--mft-leaf") ||
        !strcmp(a, "--corner-cost") || !strcmp(a, "--mft-fallback") || !strcmp(a, "--mft-shaft") ||
        !strcmp(a, "--light-sets") || !strcmp(a, "--prefetch") || !strcmp(a, "--stream-spread") ||
        !strcmp(a, "--coherent-threshold") || !strcmp(a, "--quad") || !strcmp(a, "--hybrid-tune") ||
        !strcmp(a, "--occluder-cache") || !strcmp(a, "--anyhit-order")) {
      if (i + 1 >= argc) return cli_error(CLI_USAGE_ERROR, "%s needs a value", a);
      const char *val = argv[++i];
      if (!strcmp(a, "--light-sets")) {
        if (!strcmp(val, "spread")) light_sets = FR_LIGHT_SETS_SPREAD;
        else if (!strcmp(val, "cells")) light_sets = FR_LIGHT_SETS_CELLS;
        else return cli_error(CLI_USAGE_ERROR, "--light-sets is spread or cells, not '%s'", val);
      } else if (!strcmp(a, "--shrink")) {
        /* on: corner rays and intervals (the default); corners: the paper's CR alone */
        if (!strcmp(val, "off")) mopt.shrink = FR_MFT_SHRINK_OFF;
        else if (!strcmp(val, "corners")) mopt.shrink = FR_MFT_SHRINK_CORNERS;
        else if (!strcmp(val, "on")) mopt.shrink = FR_MFT_SHRINK_ALL;
        else return cli_error(CLI_USAGE_ERROR, "--shrink is on, corners or off, not '%s'", val);
      } else if (!strcmp(a, "--corner-rays")) {
        if (parse_onoff(a, val, &mopt.corner_rays)) return CLI_USAGE_ERROR;
      } else if (!strcmp(a, "--mft-fallback")) {
        int on = 1;
        if (parse_onoff(a, val, &on)) return CLI_USAGE_ERROR;
        mft_no_fallback = !on;
      } else if (!strcmp(a, "--mft-shaft")) {
        int on = 1;
        if (parse_onoff(a, val, &on)) return CLI_USAGE_ERROR;
        mft_no_shaft = !on;
      } else if (!strcmp(a, "--corner-cost")) {
        if (!cli_parse_float(val, &mopt.corner_cost) || !(mopt.corner_cost >= 0.0f && mopt.corner_cost <= 16.0f))
          return cli_error(CLI_USAGE_ERROR, "--corner-cost wants 0..16, got '%s'", val);
      } else if (!strcmp(a, "--mft-leaf")) {
        if (!cli_parse_int(val, 1, FR_BVH2_MAX_LEAF, &mft_leaf))
          return cli_error(CLI_USAGE_ERROR, "--mft-leaf wants 1..%d, got '%s'", FR_BVH2_MAX_LEAF, val);
        mft_leaf_set = 1;
      } else if (!strcmp(a, "--prefetch")) {
        if (!strcmp(val, "auto")) topt.prefetch = -1;
        else if (!strcmp(val, "on") || !strcmp(val, "off")) topt.prefetch = !strcmp(val, "on");
        else return cli_error(CLI_USAGE_ERROR, "--prefetch is on, off or auto, not '%s'", val);
      } else if (!strcmp(a, "--anyhit-order")) {
        if (!strcmp(val, "auto")) topt.anyhit_order = -1;
        else if (!strcmp(val, "rank") || !strcmp(val, "nearest")) topt.anyhit_order = !strcmp(val, "nearest");
        else return cli_error(CLI_USAGE_ERROR, "--anyhit-order is auto, rank or nearest, not '%s'", val);
      } else if (!strcmp(a, "--stream-spread")) {
        if (!cli_parse_float(val, &topt.stream_spread) || !(topt.stream_spread >= 0.0f && topt.stream_spread <= 2.0f))
          return cli_error(CLI_USAGE_ERROR, "--stream-spread wants 0..2, got '%s'", val);
      } else if (!strcmp(a, "--threshold")) {
        if (!cli_parse_int(val, 0, 16, &topt.hybrid_threshold)) return cli_error(CLI_USAGE_ERROR, "--threshold wants 0..16, got '%s'", val);
      } else if (!strcmp(a, "--coherent-threshold")) {
        if (!cli_parse_int(val, 0, 16, &topt.coherent_threshold))
          return cli_error(CLI_USAGE_ERROR, "--coherent-threshold wants 0..16, got '%s'", val);
      } else if (!strcmp(a, "--packet-width")) {
        if (!cli_parse_int(val, 4, 8, &topt.packet_bvh_width) || (topt.packet_bvh_width != 4 && topt.packet_bvh_width != 8))
          return cli_error(CLI_USAGE_ERROR, "--packet-width is 4 or 8, not '%s'", val);
      } else if (parse_onoff(a, val, !strcmp(a, "--mailbox") ? &topt.mailbox : !strcmp(a, "--ia") ? &topt.ia_cull
                                     : !strcmp(a, "--quad") ? &topt.quad_leaves
                                     : !strcmp(a, "--hybrid-tune") ? &topt.hybrid_tune
                                     : !strcmp(a, "--occluder-cache") ? &topt.occluder_cache : &topt.axis_aligned))
        return CLI_USAGE_ERROR;
      continue;
    }
    if (!strcmp(a, "--workload") || !strcmp(a, "--mode") || !strcmp(a, "--tracer") || !strcmp(a, "--threads") ||
        !strcmp(a, "--repeat") || !strcmp(a, "--isa") || !strcmp(a, "--embree-flag") || !strcmp(a, "--embree-packing")) {
      if (i + 1 >= argc) return cli_error(CLI_USAGE_ERROR, "%s needs a value", a);
      const char *val = argv[++i];
      ebr_flag ef;
      ebr_packing ep;
      if (!strcmp(a, "--embree-flag")) {
        if (!strcmp(val, "best")) embree_flag = -1;
        else if (ebr_flag_parse(val, &ef)) embree_flag = (int)ef;
        else return cli_error(CLI_USAGE_ERROR, "--embree-flag is best, hint, coherent or incoherent, not '%s'", val);
      } else if (!strcmp(a, "--embree-packing")) {
        if (!strcmp(val, "best")) embree_packing = -1;
        else if (ebr_packing_parse(val, &ep)) embree_packing = (int)ep;
        else return cli_error(CLI_USAGE_ERROR, "--embree-packing is best, rays or samples, not '%s'", val);
      } else if (!strcmp(a, "--workload")) workload = val;
      else if (!strcmp(a, "--mode")) mode = val;
      else if (!strcmp(a, "--tracer")) tracer = val;
      else if (!strcmp(a, "--isa")) { if (cli_set_isa(val)) return 1; }
      else if (!strcmp(a, "--threads")) { if (!cli_parse_int(val, 1, 1024, &threads)) return cli_error(CLI_USAGE_ERROR, "--threads wants 1..1024, got '%s'", val); }
      else if (!cli_parse_int(val, 1, 64, &repeat)) return cli_error(CLI_USAGE_ERROR, "--repeat wants 1..64, got '%s'", val);
    } else if (cli_is_builtin(a) || a[0] != '-') {
      if (scene) return cli_error(CLI_USAGE_ERROR, "bench takes one scene");
      scene = a;
    } else return cli_error(CLI_USAGE_ERROR, "bench: unknown option '%s'", a);
  }
  if (!scene || !workload || !mode)
    return cli_error(CLI_USAGE_ERROR, "usage: frusta bench SCENE --workload W|all --mode M|all [--tracer frusta|embree|both] ...");
  int use_frusta = !strcmp(tracer, "frusta") || !strcmp(tracer, "both");
  int use_embree = !strcmp(tracer, "embree") || !strcmp(tracer, "both");
  if (!use_frusta && !use_embree) return cli_error(CLI_USAGE_ERROR, "--tracer is frusta, embree or both, not '%s'", tracer);
  fr_workload_kind wk = FR_WL_PRIMARY;
  int all_wl = !strcmp(workload, "all");
  if (!all_wl && !fr_workload_parse(workload, &wk))
    return cli_error(CLI_USAGE_ERROR, "unknown workload '%s' (primary, shadow, soft16, ao16, diffuse8, specular8, whitted, all)", workload);
  int all_modes = !strcmp(mode, "all");
  unsigned fsel, esel;
  if (parse_modes(mode, use_frusta, use_embree, &fsel, &esel)) return CLI_USAGE_ERROR;
  const int want_mft = (fsel >> MODE_MFT) & 1;

  omp_set_num_threads(threads);
  fr_scene *s;
  fr_workload w;
  memset(&w, 0, sizeof w);
  int rc = cli_workload_setup(scene, &v, threads, &s, &w);
  if (rc) return rc;
  w.seed = 7;
  w.light_sets_kind = light_sets;
  w.mft_no_fallback = mft_no_fallback;
  w.mft_no_shaft = mft_no_shaft;
  size_t tris = fr_scene_triangle_count(s);
  /* the BVH4 is built on demand: now, before any run, when a 4-wide mode wants it */
  if ((topt.packet_bvh_width == 4 || ((fsel >> 1) & 1)) && fr_scene_need_bvh4(s) != FR_OK) {
    fr_scene_release(s);
    return cli_error(1, "%s", fr_last_error());
  }
  fr_bvh_stats st;
  fr_scene_stats(s, &st);
  const fr_wide_stats *ws = st.single_width == 4 ? &st.bvh4 : &st.bvh8;
  /* packets traverse the packet BVH and test its Shevtsov records */
  const fr_wide_stats *wp = topt.packet_bvh_width == 4 ? &st.bvh4 : &st.bvh8;
  /* the prefetch switches as the scene applies them (fr_scene_apply_prefetch) */
  if (fr_scene_set_trace_options(s, &topt) != FR_OK) {
    fr_scene_release(s);
    return cli_error(1, "%s", fr_last_error());
  }
  const int prefetch = (st.single_width == 4 ? &s->bvh4 : &s->bvh8)->prefetch;
  const int packet_prefetch = (topt.packet_bvh_width == 4 ? &s->bvh4 : &s->bvh8)->packet_prefetch;
  printf("build_seconds=%.3f tracer=frusta scene=%s tris=%zu threads=%d isa=%s bvh_width=%d sah=%.2f bytes_per_tri=%.1f "
         "prefetch=%s packet_bvh_width=%d packet_bytes_per_tri=%.1f packet_prefetch=%s\n",
         st.build_seconds, s->name, tris, threads, fr_isa_name(fr_get_isa()), st.single_width, ws->sah,
         (double)(ws->node_bytes + ws->tri_bytes) / (double)tris, prefetch ? "on" : "off", topt.packet_bvh_width,
         (double)(wp->node_bytes + wp->tri_bytes + wp->packet_tri_bytes) / (double)tris, packet_prefetch ? "on" : "off");
  if (want_mft && !all_modes && fr_scene_sphere_count(s)) {
    size_t ns = fr_scene_sphere_count(s);
    fr_scene_release(s);
    return cli_error(CLI_USAGE_ERROR, "--mode mft: multi-frusta tracing does not trace spheres (this scene has %zu)", ns);
  }
  /* multi-frusta tracing: the scene's binary BVH, or a shallower one */
  fr_bvh2 shallow;
  memset(&shallow, 0, sizeof shallow);
  fr_mft_tracer mctx = fr_mft_tracer_of(s, mopt);
  if (want_mft && mft_leaf_set) { /* --mft-leaf: one tree of that leaf size for camera and shadow frusta */
    if (fr_scene_build_bvh2(s, mft_leaf, &shallow)) { fr_scene_release(s); return cli_error(1, "%s", fr_last_error()); }
    mctx.bvh = mctx.shadow_bvh = &shallow;
  }
  if (want_mft)
    printf("mft_bvh leaf=%d shadow_leaf=%d inner=%zu leaves=%zu sah=%.2f corner_rays=%s corner_cost=%g shrink=%s fallback=%s shaft=%s\n",
           mctx.bvh->max_leaf, mctx.shadow_bvh->max_leaf, mctx.bvh->nnodes, mctx.bvh->nleaves, fr_bvh2_sah(mctx.bvh), mopt.corner_rays ? "on" : "off",
           (double)mopt.corner_cost, mopt.shrink == FR_MFT_SHRINK_ALL ? "on" : mopt.shrink == FR_MFT_SHRINK_CORNERS ? "corners" : "off", mft_no_fallback ? "off" : "on", mft_no_shaft ? "off" : "on");
  fr_whitted_mats mats = {0};
  if ((all_wl || wk == FR_WL_WHITTED) && (rc = cli_whitted_setup(s, &wo, &mats, &w))) {
    fr_bvh2_free(&shallow);
    fr_scene_release(s);
    return rc;
  }
  ebr_scene *e = NULL;
  if (esel) {
    ebr_options o = {.threads = threads, .quality = 2}; /* high quality, not robust: Embree's fastest tracing */
    if (ebr_create(s, o, &e)) {
      fr_bvh2_free(&shallow);
      fr_whitted_mats_free(&mats);
      fr_scene_release(s);
      return cli_error(1, "embree: cannot build the scene");
    }
    printf("build_seconds=%.3f tracer=embree scene=%s tris=%zu threads=%d quality=high bytes_per_tri=%.1f\n",
           ebr_build_seconds(e), s->name, tris, threads, (double)ebr_bytes(e) / (double)tris);
  }
  bench_run runs[N_FRUSTA_MODES + EBR_MODE_COUNT];
  const int width = st.single_width;
  for (int k = all_wl ? 0 : (int)wk; k < (all_wl ? FR_WL_COUNT : (int)wk + 1); k++) {
    w.kind = (fr_workload_kind)k;
    int nruns = 0;
    for (int m = 0; m < N_FRUSTA_MODES; m++) {
      if (!((fsel >> m) & 1) || (m == MODE_MFT && fr_scene_sphere_count(s))) continue;
      bench_run *r = &runs[nruns++];
      memset(r, 0, sizeof *r);
      r->tracer = "frusta";
      r->mode = m;
      if (m >= MODE_LARGE)
        snprintf(r->name, sizeof r->name, "%s/%s/%s", frusta_modes[m], fr_lp_traversal_name(wo.lp.traversal),
                 fr_cull_name(wo.lp.cull));
      else
        snprintf(r->name, sizeof r->name, "%s", frusta_modes[m]);
      r->lpc = (fr_lp_tracer){s, cli_lp_scene(s), wo.lp, m >= MODE_LARGE ? 2 << (m - MODE_LARGE) : 0};
      r->t = m == MODE_MFT ? fr_tracer_mft(&mctx) : m >= MODE_LARGE ? fr_tracer_lp(&r->lpc) : fr_tracer_frusta(s);
    }
    for (int m = 0; e && m < EBR_MODE_COUNT; m++) {
      if (!((esel >> m) & 1)) continue;
      bench_run *r = &runs[nruns++];
      memset(r, 0, sizeof *r);
      r->tracer = "embree";
      r->mode = m;
      snprintf(r->name, sizeof r->name, "%s", ebr_mode_name((ebr_mode)m));
      choose_embree_variant(&w, e, r, embree_flag, embree_packing);
    }
    for (int rep = 0; rep < repeat; rep++)
      for (int i = 0; i < nruns; i++) {
        bench_run *r = &runs[i];
        if (r->tracer[0] == 'f') set_frusta_mode(s, r->mode, &topt, width);
        fr_counters_reset();
        fr_workload_result res = fr_workload_run(&w, &r->t);
        fr_counters c = fr_counters_read();
        fr_counters_add(&r->c, &c);
        r->secs[rep] = res.seconds;
        memcpy(r->stage[rep], res.stage, sizeof res.stage);
        r->rays = res.rays;
      }
    fr_scene_set_bvh_width(s, width);
    fr_scene_set_trace_options(s, &topt);
    for (int i = 0; i < nruns; i++) report(&w, &runs[i], s->name, tris, repeat);
  }
  ebr_release(e);
  fr_bvh2_free(&shallow);
  fr_whitted_mats_free(&mats);
  fr_scene_release(s);
  return 0;
}
