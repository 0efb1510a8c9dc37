/* frusta stats SCENE: BVH statistics (the MIC paper's Tables I-II), and with
 * --embree Embree's own builder on the same triangles for comparison. With
 * --workload W, the MIC paper's Table V for the hybrid on that workload: the
 * share of box and triangle tests made in packet and in single-ray mode, and
 * the switches per packet (needs a build with -DFRUSTA_COUNTERS=ON). */
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include "api/scene.h"
#include "cli.h"
#include "cli_scene_file.h"
#include "commands.h"
#include "embree_tracer.h"
#include "embree_tree.h"
#include "render/whitted.h"
#include "render/workload.h"
#include "trace/counters.h"

/* Table V: runs the workload once in hybrid16 mode with the counters on.
 * coherent < 0: the library's coherent_threshold. */
static int table5(const char *path, const cli_view *v, int threads, const char *wl_name, int threshold, int coherent,
                  int width) {
  fr_workload_kind k;
  if (!fr_workload_parse(wl_name, &k)) return cli_error(CLI_USAGE_ERROR, "unknown workload '%s'", wl_name);
  if (!fr_counters_enabled())
    return cli_error(1, "stats --workload needs the counters: configure with cmake -DFRUSTA_COUNTERS=ON and rebuild");
  fr_scene *s;
  fr_workload w;
  memset(&w, 0, sizeof w);
  cli_view flat = *v;
  flat.smooth = 0.0f; /* nothing is shaded */
  int rc = cli_workload_setup(path, &flat, threads, &s, &w);
  if (rc) return rc;
  w.kind = k;
  w.seed = 7;
  /* Whitted needs its materials (without, the renderer had none to read: a crash) */
  fr_whitted_mats mats = {0};
  cli_whitted wo;
  cli_whitted_default(&wo);
  if (k == FR_WL_WHITTED && (rc = cli_whitted_setup(s, &wo, &mats, &w))) {
    fr_scene_release(s);
    return rc;
  }
  fr_tuning o;
  fr_tuning_default(&o);
  o.mode = FR_TRACE_HYBRID16;
  o.hybrid_threshold = threshold;
  if (coherent >= 0) o.coherent_threshold = coherent;
  o.packet_bvh_width = width;
  fr_scene_set_tuning(s, &o);
  fr_tracer t = fr_tracer_frusta(s);
  fr_counters_reset();
  fr_workload_result r = fr_workload_run(&w, &t);
  fr_counters c = fr_counters_read();
  /* ray-box and ray-triangle tests: a packet test counts its active rays */
  double box_p = (double)c.pk_box_lanes, box_s = (double)c.box_tests;
  double tri_p = (double)c.pk_tri_lanes, tri_s = (double)c.tri_tests;
  double box = box_p + box_s, tri = tri_p + tri_s;
  printf("table5 scene=%s workload=%s threshold=%d coherent_threshold=%d packet_bvh_width=%d rays=%llu packets=%llu "
         "box_tests_packet=%.1f%% box_tests_single=%.1f%% tri_tests_packet=%.1f%% tri_tests_single=%.1f%% "
         "switches_per_packet=%.2f rays_per_switch=%.2f avg_active_box=%.2f avg_active_tri=%.2f ia_culled_per_packet=%.2f "
         "mailbox_hits_per_packet=%.3f\n",
         s->name, wl_name, threshold, o.coherent_threshold, width, (unsigned long long)r.rays, (unsigned long long)c.packets,
         box > 0 ? 100.0 * box_p / box : 0.0, box > 0 ? 100.0 * box_s / box : 0.0, tri > 0 ? 100.0 * tri_p / tri : 0.0,
         tri > 0 ? 100.0 * tri_s / tri : 0.0, c.packets ? (double)c.switches / c.packets : 0.0,
         c.switches ? (double)c.switch_rays / c.switches : 0.0, c.pk_box_tests ? (double)c.pk_box_lanes / c.pk_box_tests : 0.0,
         c.pk_tri_tests ? (double)c.pk_tri_lanes / c.pk_tri_tests : 0.0, c.packets ? (double)c.ia_culled / c.packets : 0.0,
         c.packets ? (double)c.mailbox_hits / c.packets : 0.0);
  fr_whitted_mats_free(&mats);
  fr_scene_release(s);
  return 0;
}

int cmd_stats(int argc, char **argv) {
  cli_args a;
  int rc = cli_args_parse(CLI_STATS, argc, argv, 1, &a);
  if (rc) return rc == CLI_HELP_SHOWN ? 0 : rc;
  if ((rc = cli_scene_file_defaults(&a))) return rc;
  const char *path = a.pos[0], *workload = a.val[F_WORKLOAD];
  const int embree = a.val[F_EMBREE] != NULL;
  int threads = omp_get_num_procs(), threshold = 7, coherent = -1, width = 8;
  cli_view v;
  if ((rc = cli_view_from_args(&a, &v)) || (rc = cli_common_from_args(&a, &threads)) ||
      (rc = cli_arg_int(&a, F_THRESHOLD, 0, 16, &threshold)) ||
      (rc = cli_arg_int(&a, F_COHERENT_THRESHOLD, 0, 16, &coherent)) ||
      (rc = cli_arg_int(&a, F_PACKET_WIDTH, 4, 8, &width)))
    return rc;
  if (width != 4 && width != 8) return cli_error(CLI_USAGE_ERROR, "--packet-width is 4 or 8, not '%s'", a.val[F_PACKET_WIDTH]);
  if (!path)
    return cli_error(CLI_USAGE_ERROR, "usage: frusta stats SCENE|--builtin [--embree] [--workload W] [flags] "
                                      "(see frusta stats --help)");
  omp_set_num_threads(threads);
  if (workload) return table5(path, &v, threads, workload, threshold, coherent, width);
  fr_scene *s;
  int lrc = cli_load_scene(path, &s);
  if (lrc) return lrc;
  /* the BVH4 (the MIC paper's) is built on demand; these tables report it */
  if (fr_scene_need_bvh4(s) != FR_OK) {
    fr_scene_release(s);
    return cli_error(1, "stats: %s", fr_last_error());
  }
  fr_bvh_stats st;
  fr_scene_stats(s, &st);
  size_t nt = fr_scene_triangle_count(s);
  printf("scene=%s tris=%zu skipped_degenerate=%zu references=%zu threads=%d build_seconds=%.3f\n", s->name, nt,
         fr_scene_skipped_triangles(s), st.references, threads, st.build_seconds);
  printf("bvh2 inner=%zu leaves=%zu sah=%.2f leaf_fill=%.2f\n", st.bvh2_inner, st.bvh2_leaves, st.bvh2_sah, st.bvh2_leaf_fill);
  /* the planar occluders occlusion queries test first (accel/plane_occluders.h) */
  size_t ptris = 0;
  double parea = 0.0;
  for (size_t i = 0; i < s->planes.n; i++) { ptris += s->planes.list[i].tris; parea += s->planes.list[i].area; }
  printf("plane_occluders n=%zu tris=%zu area=%.4g\n", s->planes.n, ptris, parea);
  for (size_t i = 0; i < s->planes.n; i++) {
    const fr_plane_occluder *o = &s->planes.list[i];
    printf("plane_occluder axis=%c c=%g tris=%zu edges=%d area=%.4g\n", "xyz"[o->axis], (double)o->c, o->tris, o->nedges, o->area);
  }
  const fr_wide_stats *w[2] = {&st.bvh4, &st.bvh8};
  for (int i = 0; i < 2; i++)
    printf("bvh%d inner=%zu leaves=%zu blocks=%zu sah=%.2f sah_blocks=%.2f node_fill=%.2f/%d leaf_fill=%.2f block_fill=%.2f/4 depth=%d node_bytes=%zu tri_bytes=%zu bytes_per_tri=%.1f packet_tri_bytes=%zu packet_bytes_per_tri=%.1f\n",
           4 << i, w[i]->inner, w[i]->leaves, w[i]->blocks, w[i]->sah, w[i]->sah_blocks, w[i]->node_fill, 4 << i, w[i]->leaf_fill,
           w[i]->block_fill, w[i]->depth,
           w[i]->node_bytes, w[i]->tri_bytes, (double)(w[i]->node_bytes + w[i]->tri_bytes) / (double)nt,
           w[i]->packet_tri_bytes, (double)(w[i]->node_bytes + w[i]->tri_bytes + w[i]->packet_tri_bytes) / (double)nt);
  if (embree) {
    for (int q = 1; q <= 2; q++) {
      double sah, sahb, sec;
      if (ebr_builder_sah(s, threads, q, &sah, &sahb, &sec) == FR_OK)
        printf("embree_builder width=4 quality=%s sah=%.2f sah_blocks=%.2f seconds=%.3f frusta_bvh4_over_embree sah=%.3f sah_blocks=%.3f\n",
               q == 2 ? "high" : "medium", sah, sahb, sec, st.bvh4.sah / sah, st.bvh4.sah_blocks / sahb);
    }
    ebr_scene *e;
    ebr_options o = {.threads = threads, .quality = 2};
    if (ebr_create(s, o, &e) == FR_OK) {
      printf("embree_scene quality=high build_seconds=%.3f bytes=%zu bytes_per_tri=%.1f build_ratio_frusta_over_embree=%.2f\n",
             ebr_build_seconds(e), ebr_bytes(e), (double)ebr_bytes(e) / (double)nt, st.build_seconds / ebr_build_seconds(e));
      ebr_release(e);
    }
    /* Embree's tree, by its own statistics: the same SAH as sah_blocks. A
     * commit of its own: the log's tree walk runs inside rtcCommitScene and
     * would count in the build time above. */
    ebr_tree t;
    if (ebr_tree_stats(s, threads, &t) == FR_OK)
      printf("embree_tree accel=%s builder=%s depth=%d inner=%zu leaves=%zu sah_blocks=%.2f node_sah=%.2f leaf_sah=%.2f "
             "node_fill=%.2f/%d block_fill=%.2f/%d one_block_leaves=%.3f frusta_bvh%d_over_embree sah_blocks=%.3f\n",
             t.accel, t.builder, t.depth, t.inner, t.leaves, t.sah, t.node_sah, t.leaf_sah, t.node_fill, t.width,
             t.block_fill, t.block_size, t.one_block, t.width == 4 ? 4 : 8,
             (t.width == 4 ? st.bvh4.sah_blocks : st.bvh8.sah_blocks) / t.sah);
    else
      printf("embree_tree unavailable\n");
  }
  fr_scene_release(s);
  return 0;
}
