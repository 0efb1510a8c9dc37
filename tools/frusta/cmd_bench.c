/*
 * frusta bench: the workloads of docs/workloads.md, frusta and Embree side by
 * side in one process, on the same scene, rays and threads. Each (tracer,
 * mode) run is repeated K times; the line reports the best and the median.
 * The repetitions are interleaved, round-robin over every run selected for
 * a workload, so that every run samples the same stretches of a host whose
 * speed drifts.
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "cli.h"
#include "cli_cluster.h"
#include "cli_scene_file.h"
#include "commands.h"
#include "cli_path.h"
#include "embree_tracer.h"
#include "render/whitted.h"
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

static void set_frusta_mode(fr_scene *s, int m, const fr_tuning *base, int single_width) {
  static const fr_trace_mode modes[] = {FR_TRACE_SINGLE, FR_TRACE_SINGLE, FR_TRACE_PACKET8, FR_TRACE_PACKET16,
                                        FR_TRACE_HYBRID16, FR_TRACE_AUTO, FR_TRACE_AUTO, FR_TRACE_RAYSTREAM};
  fr_tuning o = *base;
  o.mode = m < MODE_LARGE ? modes[m] : FR_TRACE_AUTO;
  fr_scene_set_tuning(s, &o);
  fr_scene_set_bvh_width(s, m == 0 ? 8 : m == 1 ? 4 : single_width);
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
  fr_cluster_share *shares; /* a cluster's ranks' shares of the last repetition (NULL: one process) */
  double tile_ms[6];  /* the fastest repetition's tiles rendered here: count, mean, sd, median, p99, max (ms) */
} bench_run;

/* The tiles' render times of a frame (ms): count, mean, standard
 * deviation, median, 99th percentile and maximum over those rendered here. */
static void tile_stats(const double *secs, int n, double out[6]) {
  double *v = malloc((size_t)(n > 0 ? n : 1) * sizeof *v), sum = 0.0, sq = 0.0;
  int k = 0;
  memset(out, 0, 6 * sizeof *out);
  if (!v) return;
  for (int i = 0; i < n; i++)
    if (secs[i] > 0.0) v[k++] = secs[i] * 1e3;
  if (k) {
    qsort(v, (size_t)k, sizeof *v, cmp_double);
    for (int i = 0; i < k; i++) sum += v[i], sq += v[i] * v[i];
    const double mean = sum / k;
    out[0] = k, out[1] = mean, out[2] = sqrt(fmax(0.0, sq / k - mean * mean));
    out[3] = v[k / 2], out[4] = v[(int)(0.99 * (k - 1))], out[5] = v[k - 1];
  }
  free(v);
}

/* A cluster run: each rank's share of the rays and tiles, and the pixel
 * bytes the others sent rank 0. */
static void report_shares(const fr_workload *w, const bench_run *r) {
  const int n = fr_cluster_size();
  uint64_t rays = 0, bytes = 0;
  for (int k = 0; k < n; k++) rays += r->shares[k].rays, bytes += r->shares[k].bytes;
  printf("cluster tracer=%s mode=%s workload=%s ranks=%d threads_per_rank=%d bytes_sent=%llu rank_rays=", r->tracer,
         r->name, fr_workload_name(w->kind), n, w->threads, (unsigned long long)bytes);
  for (int k = 0; k < n; k++) printf("%s%.1f%%", k ? "," : "", rays ? 100.0 * (double)r->shares[k].rays / (double)rays : 0.0);
  printf(" rank_tiles=");
  for (int k = 0; k < n; k++) printf("%s%d", k ? "," : "", r->shares[k].tiles);
  printf("\n");
}

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
  if (r->shares) report_shares(w0, r);
  if (r->tile_ms[0] > 0)
    printf("tiles tracer=%s mode=%s workload=%s tile=%d count=%.0f mean_ms=%.4f sd_ms=%.4f median_ms=%.4f p99_ms=%.4f "
           "max_ms=%.4f\n",
           r->tracer, r->name, fr_workload_name(w0->kind), fr_workload_tile_side(w0),
           r->tile_ms[0], r->tile_ms[1], r->tile_ms[2], r->tile_ms[3], r->tile_ms[4], r->tile_ms[5]);
  printf("scene=%s tris=%zu workload=%s tracer=%s mode=%s threads=%d rays=%llu seconds=%.4f mrays=%.2f median_seconds=%.4f median_mrays=%.2f%s\n",
         scene, tris, fr_workload_name(w0->kind), tracer, mode, w0->threads, (unsigned long long)rays, best,
         (double)rays / best * 1e-6, med, (double)rays / med * 1e-6, embree);
  if (w0->kind == FR_WL_WHITTED || w0->kind == FR_WL_PATH) {
    /* the stages of the fastest repetition, in thread-seconds: which part of
     * a Whitted or path-traced frame the tracer speeds up, and how much is
     * the renderer's (shading, sampling, lights) */
    int b = 0;
    for (int i = 1; i < repeat; i++)
      if (r->secs[i] < r->secs[b]) b = i;
    const double *st = r->stage[b];
    const double all = st[FR_STAGE_CAMERA] + st[FR_STAGE_SHADOW] + st[FR_STAGE_SECONDARY] + st[FR_STAGE_SHADE];
    printf("stages tracer=%s mode=%s workload=%s camera_s=%.4f shadow_s=%.4f secondary_s=%.4f shade_s=%.4f "
           "outside_tracing=%.1f%%\n",
           tracer, mode, fr_workload_name(w0->kind), st[FR_STAGE_CAMERA], st[FR_STAGE_SHADOW], st[FR_STAGE_SECONDARY],
           st[FR_STAGE_SHADE], all > 0.0 ? 100.0 * st[FR_STAGE_SHADE] / all : 0.0);
  }
  fr_counters c = r->c;
  if (fr_counters_enabled() && c.rays)
    printf("counters tracer=%s mode=%s workload=%s per_ray nodes=%.2f box_tests=%.2f leaves=%.2f tri_tests=%.2f "
           "tri_hit_tests=%.3f tri_plane_t=%.4f cache_tries=%llu cache_hits=%llu\n",
           tracer, mode, fr_workload_name(w0->kind), (double)c.nodes / c.rays, (double)c.box_tests / c.rays,
           (double)c.leaves / c.rays, (double)c.tri_tests / c.rays, (double)c.tri_hit_tests / c.rays,
           (double)c.tri_plane_t / c.rays, (unsigned long long)c.cache_tries, (unsigned long long)c.cache_hits);
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
  r->flag = flag < 0 ? EBR_FLAG_HINT : (ebr_flag)flag;
  r->packing = packing < 0 ? EBR_PACK_RAYS : (ebr_packing)packing;
  double best = INFINITY;
  const int choices = (flag < 0 ? EBR_FLAG_COUNT : 1) * (packing < 0 && runs16 && grouped ? EBR_PACK_COUNT : 1);
  for (int rep = 0; choices > 1 && rep < 2; rep++)
    for (int f = 0; f < EBR_FLAG_COUNT; f++)
      for (int p = 0; p < EBR_PACK_COUNT; p++) {
        const int use = (flag < 0 || flag == f) && (packing < 0 ? p == EBR_PACK_RAYS || (runs16 && grouped) : packing == p);
        if (!use) continue;
        fr_tracer t = ebr_tracer(e, (ebr_mode)r->mode, (ebr_flag)f, (ebr_packing)p);
        const double secs = fr_workload_run(w, &t).seconds;
        if (secs < best) { best = secs; r->flag = (ebr_flag)f; r->packing = (ebr_packing)p; }
      }
  r->t = ebr_tracer(e, (ebr_mode)r->mode, r->flag, r->packing);
}

/* Everything the flags decide. */
typedef struct bench_opts {
  const char *scene;
  unsigned workloads;   /* bit k: fr_workload_kind k */
  unsigned fsel, esel;  /* frusta's modes (bits of frusta_modes) and Embree's (bits of ebr_mode) */
  int all_modes;
  int threads, repeat, embree_flag, embree_packing;
  fr_tuning tuning;
  fr_mft_opts mopt;
  int mft_leaf;         /* 0: the scene's own trees */
  int mft_no_fallback, mft_no_shaft;
  fr_light_sets light_sets;
  cli_view view;
  cli_whitted whitted;
  cli_path path;
} bench_opts;

/* --workload: all, or a comma-separated list */
static int parse_workloads(const char *list, unsigned *sel) {
  *sel = 0;
  if (!strcmp(list, "all")) { *sel = ((1u << FR_WL_COUNT) - 1) & ~(1u << FR_WL_PATH); return 0; } /* path: by name */
  char buf[256];
  if (strlen(list) >= sizeof buf) return cli_error(CLI_USAGE_ERROR, "--workload: list too long");
  memcpy(buf, list, strlen(list) + 1);
  for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
    fr_workload_kind k;
    if (!fr_workload_parse(tok, &k))
      return cli_error(CLI_USAGE_ERROR, "unknown workload '%s' (primary, shadow, soft16, ao16, diffuse8, specular8, "
                                        "whitted, path, all)", tok);
    *sel |= 1u << k;
  }
  return *sel ? 0 : cli_error(CLI_USAGE_ERROR, "--workload: none given");
}

/* The kernel switches (fr_tuning) and the multi-frusta ones. */
static int kernel_options(const cli_args *a, bench_opts *o) {
  fr_tuning *t = &o->tuning;
  static const char *const prefetch[] = {"auto", "off", "on"}, *const order[] = {"auto", "rank", "nearest"};
  static const char *const shrink[] = {"off", "corners", "on"}; /* FR_MFT_SHRINK_* order */
  static const char *const sets[] = {"spread", "cells"};
  int pf = t->prefetch + 1, ao = t->anyhit_order + 1, sets_i = 0, fallback = 1, shaft = 1, rc;
  if ((rc = cli_arg_int(a, F_THRESHOLD, 0, 16, &t->hybrid_threshold)) ||
      (rc = cli_arg_int(a, F_COHERENT_THRESHOLD, 0, 16, &t->coherent_threshold)) ||
      (rc = cli_arg_int(a, F_PACKET_WIDTH, 4, 8, &t->packet_bvh_width)) ||
      (rc = cli_arg_onoff(a, F_MAILBOX, &t->mailbox)) || (rc = cli_arg_onoff(a, F_AXIS_ALIGNED, &t->axis_aligned)) ||
      (rc = cli_arg_onoff(a, F_IA, &t->ia_cull)) || (rc = cli_arg_onoff(a, F_QUAD, &t->quad_leaves)) ||
      (rc = cli_arg_onoff(a, F_OCCLUDER_CACHE, &t->occluder_cache)) ||
      (rc = cli_arg_float(a, F_STREAM_SPREAD, 0.0f, 2.0f, &t->stream_spread)) ||
      (rc = cli_arg_choice(a, F_PREFETCH, prefetch, 3, &pf)) || (rc = cli_arg_choice(a, F_ANYHIT_ORDER, order, 3, &ao)) ||
      (rc = cli_arg_onoff(a, F_CORNER_RAYS, &o->mopt.corner_rays)) ||
      (rc = cli_arg_float(a, F_CORNER_COST, 0.0f, 16.0f, &o->mopt.corner_cost)) ||
      (rc = cli_arg_choice(a, F_SHRINK, shrink, 3, &o->mopt.shrink)) ||
      (rc = cli_arg_int(a, F_MFT_LEAF, 1, FR_BVH2_MAX_LEAF, &o->mft_leaf)) ||
      (rc = cli_arg_onoff(a, F_MFT_FALLBACK, &fallback)) || (rc = cli_arg_onoff(a, F_MFT_SHAFT, &shaft)) ||
      (rc = cli_arg_choice(a, F_LIGHT_SETS, sets, 2, &sets_i)))
    return rc;
  if (t->packet_bvh_width != 4 && t->packet_bvh_width != 8)
    return cli_error(CLI_USAGE_ERROR, "--packet-width is 4 or 8, not '%s'", a->val[F_PACKET_WIDTH]);
  t->prefetch = pf == 0 ? -1 : pf == 2;
  t->anyhit_order = ao == 0 ? -1 : ao == 2;
  o->mft_no_fallback = !fallback;
  o->mft_no_shaft = !shaft;
  o->light_sets = sets_i ? FR_LIGHT_SETS_CELLS : FR_LIGHT_SETS_SPREAD;
  return 0;
}

static int bench_options(const cli_args *a, bench_opts *o) {
  memset(o, 0, sizeof *o);
  o->scene = a->pos[0];
  o->threads = omp_get_num_procs();
  o->repeat = 3;
  fr_tuning_default(&o->tuning);
  o->mopt = fr_mft_opts_default();
  static const char *const flags[] = {"best", "hint", "coherent", "incoherent"}; /* best, then ebr_flag order */
  static const char *const packings[] = {"best", "rays", "samples"};            /* best, then ebr_packing order */
  static const char *const tracers[] = {"frusta", "embree", "both"};
  int ef = 0, ep = 0, tracer = 0, rc;
  if ((rc = cli_view_from_args(a, &o->view)) || (rc = cli_whitted_from_args(a, &o->whitted)) ||
      (rc = cli_path_from_args(a, &o->path)) ||
      (rc = cli_common_from_args(a, &o->threads)) || (rc = cli_arg_int(a, F_REPEAT, 1, 64, &o->repeat)) ||
      (rc = cli_arg_choice(a, F_EMBREE_FLAG, flags, 4, &ef)) ||
      (rc = cli_arg_choice(a, F_EMBREE_PACKING, packings, 3, &ep)) ||
      (rc = cli_arg_choice(a, F_TRACER, tracers, 3, &tracer)) || (rc = kernel_options(a, o)))
    return rc;
  o->embree_flag = ef - 1;
  o->embree_packing = ep - 1;
  if (!o->scene || !a->val[F_WORKLOAD] || !a->val[F_MODE])
    return cli_error(CLI_USAGE_ERROR, "usage: frusta bench SCENE --workload W|all --mode M|all [flags] "
                                      "(see frusta bench --help)");
  if ((rc = parse_workloads(a->val[F_WORKLOAD], &o->workloads))) return rc;
  o->all_modes = !strcmp(a->val[F_MODE], "all");
  return parse_modes(a->val[F_MODE], tracer != 1, tracer != 0, &o->fsel, &o->esel);
}

/* What every workload of a call traces on. */
typedef struct bench_setup {
  fr_scene *s;
  fr_workload w;
  fr_bvh2 shallow;        /* --mft-leaf's tree */
  fr_mft_tracer mctx;
  fr_whitted_mats mats;
  cli_path_run path;
  ebr_scene *e;
  int width;              /* the single-ray BVH width */
  fr_cluster_feed *feed;  /* a cluster's frames */
} bench_setup;

static void setup_free(bench_setup *b) {
  fr_cluster_feed_free(b->feed);
  free(b->w.tile_seconds);
  ebr_release(b->e);
  fr_bvh2_free(&b->shallow);
  fr_whitted_mats_free(&b->mats);
  cli_path_free(&b->path);
  fr_scene_release(b->s);
}

static void print_frusta_build(const bench_opts *o, const fr_scene *s) {
  fr_bvh_stats st;
  fr_scene_stats(s, &st);
  const fr_wide_stats *ws = st.single_width == 4 ? &st.bvh4 : &st.bvh8;
  /* packets traverse the packet BVH and test its Shevtsov records */
  const int pw = o->tuning.packet_bvh_width;
  const fr_wide_stats *wp = pw == 4 ? &st.bvh4 : &st.bvh8;
  /* the prefetch switches as the scene applies them (fr_scene_apply_prefetch) */
  const int prefetch = (st.single_width == 4 ? &s->bvh4 : &s->bvh8)->prefetch;
  const int packet_prefetch = (pw == 4 ? &s->bvh4 : &s->bvh8)->packet_prefetch;
  const size_t tris = fr_scene_triangle_count(s);
  printf("build_seconds=%.3f tracer=frusta scene=%s tris=%zu threads=%d isa=%s bvh_width=%d sah=%.2f bytes_per_tri=%.1f "
         "prefetch=%s packet_bvh_width=%d packet_bytes_per_tri=%.1f packet_prefetch=%s\n",
         st.build_seconds, s->name, tris, o->threads, fr_isa_name(fr_get_isa()), st.single_width, ws->sah,
         (double)(ws->node_bytes + ws->tri_bytes) / (double)tris, prefetch ? "on" : "off", pw,
         (double)(wp->node_bytes + wp->tri_bytes + wp->packet_tri_bytes) / (double)tris, packet_prefetch ? "on" : "off");
}

/* Loads and commits the scene, builds what the modes need and prints the
 * build lines; 0, or an exit code after reporting. */
static int bench_prepare(const bench_opts *o, bench_setup *b) {
  memset(b, 0, sizeof *b);
  omp_set_num_threads(o->threads);
  cli_view view = o->view;
  if (!(o->workloads & (1u << FR_WL_PATH | 1u << FR_WL_WHITTED))) view.smooth = 0.0f; /* only they shade */
  int rc = cli_workload_setup(o->scene, &view, o->threads, &b->s, &b->w);
  if (rc) return rc;
  fr_scene *s = b->s;
  b->w.seed = 7;
  b->w.tile_seconds = calloc(((size_t)view.width + 15) / 16 * (((size_t)view.height + 15) / 16), sizeof(double));
  if (!b->w.tile_seconds) return cli_error(1, "out of memory");
  b->w.light_sets_kind = o->light_sets;
  b->w.mft_no_fallback = o->mft_no_fallback;
  b->w.mft_no_shaft = o->mft_no_shaft;
  /* the BVH4 is built on demand: now, before any run, when a 4-wide mode wants it */
  if ((o->tuning.packet_bvh_width == 4 || ((o->fsel >> 1) & 1)) && fr_scene_need_bvh4(s) != FR_OK)
    return cli_error(1, "%s", fr_last_error());
  if (fr_scene_set_tuning(s, &o->tuning) != FR_OK) return cli_error(1, "%s", fr_last_error());
  b->width = s->single_width;
  print_frusta_build(o, s);
  const int want_mft = (o->fsel >> MODE_MFT) & 1;
  if (want_mft && !o->all_modes && fr_scene_sphere_count(s))
    return cli_error(CLI_USAGE_ERROR, "--mode mft: multi-frusta tracing does not trace spheres (this scene has %zu)",
                     fr_scene_sphere_count(s));
  /* multi-frusta tracing: the scene's binary BVH, or a shallower one */
  b->mctx = fr_mft_tracer_of(s, o->mopt);
  if (want_mft && o->mft_leaf) { /* --mft-leaf: one tree of that leaf size for camera and shadow frusta */
    if (fr_scene_build_bvh2(s, o->mft_leaf, &b->shallow)) return cli_error(1, "%s", fr_last_error());
    b->mctx.bvh = b->mctx.shadow_bvh = &b->shallow;
  }
  const fr_mft_opts *m = &o->mopt;
  if (want_mft)
    printf("mft_bvh leaf=%d shadow_leaf=%d inner=%zu leaves=%zu sah=%.2f corner_rays=%s corner_cost=%g shrink=%s "
           "fallback=%s shaft=%s\n",
           b->mctx.bvh->max_leaf, b->mctx.shadow_bvh->max_leaf, b->mctx.bvh->nnodes, b->mctx.bvh->nleaves,
           fr_bvh2_sah(b->mctx.bvh), m->corner_rays ? "on" : "off", (double)m->corner_cost,
           m->shrink == FR_MFT_SHRINK_ALL ? "on" : m->shrink == FR_MFT_SHRINK_CORNERS ? "corners" : "off",
           o->mft_no_fallback ? "off" : "on", o->mft_no_shaft ? "off" : "on");
  if (((o->workloads >> FR_WL_WHITTED) & 1) && (rc = cli_whitted_setup(s, &o->whitted, &b->mats, &b->w))) return rc;
  if (((o->workloads >> FR_WL_PATH) & 1) && (rc = cli_path_setup(&o->path, &b->w, &b->path))) return rc;
  if (o->esel) {
    ebr_options eo = {.threads = o->threads, .quality = 2}; /* high quality, not robust: Embree's fastest tracing */
    if (ebr_create(s, eo, &b->e)) return cli_error(1, "embree: cannot build the scene");
    const size_t tris = fr_scene_triangle_count(s);
    printf("build_seconds=%.3f tracer=embree scene=%s tris=%zu threads=%d quality=high bytes_per_tri=%.1f\n",
           ebr_build_seconds(b->e), s->name, tris, o->threads, (double)ebr_bytes(b->e) / (double)tris);
  }
  return 0;
}

/* One workload: every selected run, their repetitions interleaved, then one
 * line each. */
static int bench_workload(const bench_opts *o, bench_setup *b, fr_workload_kind k) {
  fr_scene *s = b->s;
  fr_workload *w = &b->w;
  w->kind = k;
  bench_run runs[N_FRUSTA_MODES + EBR_MODE_COUNT];
  int nruns = 0;
  const fr_lp_opts *lp = &o->whitted.lp;
  for (int m = 0; m < N_FRUSTA_MODES; m++) {
    if (!((o->fsel >> m) & 1) || (m == MODE_MFT && fr_scene_sphere_count(s))) continue;
    bench_run *r = &runs[nruns++];
    memset(r, 0, sizeof *r);
    r->tracer = "frusta";
    r->mode = m;
    if (m >= MODE_LARGE)
      snprintf(r->name, sizeof r->name, "%s/%s/%s", frusta_modes[m], fr_lp_traversal_name(lp->traversal),
               fr_cull_name(lp->cull));
    else
      snprintf(r->name, sizeof r->name, "%s", frusta_modes[m]);
    r->lpc = (fr_lp_tracer){s, cli_lp_scene(s), *lp, m >= MODE_LARGE ? 2 << (m - MODE_LARGE) : 0};
    r->t = m == MODE_MFT ? fr_tracer_mft(&b->mctx) : m >= MODE_LARGE ? fr_tracer_lp(&r->lpc) : fr_tracer_frusta(s);
  }
  for (int m = 0; b->e && m < EBR_MODE_COUNT; m++) {
    if (!((o->esel >> m) & 1)) continue;
    bench_run *r = &runs[nruns++];
    memset(r, 0, sizeof *r);
    r->tracer = "embree";
    r->mode = m;
    snprintf(r->name, sizeof r->name, "%s", ebr_mode_name((ebr_mode)m));
    choose_embree_variant(w, b->e, r, o->embree_flag, o->embree_packing);
  }
  for (int rep = 0; rep < o->repeat; rep++)
    for (int i = 0; i < nruns; i++) {
      bench_run *r = &runs[i];
      if (r->tracer[0] == 'f') set_frusta_mode(s, r->mode, &o->tuning, b->width);
      fr_counters_reset();
      fr_workload_result res = fr_workload_run(w, &r->t);
      if (res.failed) {
        for (int j = 0; j < nruns; j++) free(runs[j].shares);
        return cli_error(1, "%s", fr_last_error());
      }
      if (b->feed && (r->shares || (r->shares = calloc((size_t)fr_cluster_size(), sizeof *r->shares))))
        for (int rk = 0; rk < fr_cluster_size(); rk++) r->shares[rk] = fr_cluster_feed_share(b->feed, rk);
      fr_counters c = fr_counters_read();
      fr_counters_add(&r->c, &c);
      int fastest = 1;
      for (int j = 0; j < rep; j++) fastest &= res.seconds < r->secs[j];
      r->secs[rep] = res.seconds;
      if (w->tile_seconds && fastest) {
        const int tile = k == FR_WL_WHITTED ? FR_WHITTED_TILE : 16;
        tile_stats(w->tile_seconds, ((w->cam.width + tile - 1) / tile) * ((w->cam.height + tile - 1) / tile), r->tile_ms);
      }
      memcpy(r->stage[rep], res.stage, sizeof res.stage);
      r->rays = res.rays;
    }
  fr_scene_set_bvh_width(s, b->width);
  fr_scene_set_tuning(s, &o->tuning);
  for (int i = 0; i < nruns; i++) report(w, &runs[i], s->name, fr_scene_triangle_count(s), o->repeat);
  for (int i = 0; i < nruns; i++) free(runs[i].shares);
  return 0;
}

int cmd_bench(int argc, char **argv) {
  cli_args a;
  int rc = cli_args_parse(CLI_BENCH, argc, argv, 1, &a);
  if (rc) return rc == CLI_HELP_SHOWN ? 0 : rc;
  if ((rc = cli_scene_file_defaults(&a))) return rc;
  bench_opts o;
  if ((rc = bench_options(&a, &o))) return rc;
  bench_setup b;
  rc = cli_cluster_join(bench_prepare(&o, &b), &b.w, &b.feed);
  for (int k = 0; !rc && k < FR_WL_COUNT; k++)
    if ((o.workloads >> k) & 1) rc = bench_workload(&o, &b, (fr_workload_kind)k);
  setup_free(&b);
  return rc;
}
