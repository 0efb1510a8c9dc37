/* frusta stats SCENE: BVH statistics (the MIC paper's Tables I-II), and with
 * --embree Embree's own builder on the same triangles for comparison. */
#include <omp.h>
#include <stdio.h>
#include <string.h>
#include "api/scene.h"
#include "cli.h"
#include "commands.h"
#include "embree_tracer.h"

int cmd_stats(int argc, char **argv) {
  const char *path = NULL;
  int embree = 0, threads = omp_get_num_procs();
  for (int i = 0; i < argc; i++) {
    if (strcmp(argv[i], "--embree") == 0) embree = 1;
    else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      if (!cli_parse_int(argv[++i], 1, 1024, &threads)) return cli_error(CLI_USAGE_ERROR, "--threads wants 1..1024");
    } else if (strcmp(argv[i], "--builtin") == 0 || argv[i][0] != '-') {
      if (path) return cli_error(CLI_USAGE_ERROR, "stats takes one scene");
      path = argv[i];
    } else return cli_error(CLI_USAGE_ERROR, "stats: unknown option '%s'", argv[i]);
  }
  if (!path) return cli_error(CLI_USAGE_ERROR, "usage: frusta stats SCENE|--builtin [--embree] [--threads N]");
  omp_set_num_threads(threads);
  fr_scene *s;
  if (cli_load_scene(path, &s)) return 1;
  fr_bvh_stats st;
  fr_scene_stats(s, &st);
  size_t nt = fr_scene_triangle_count(s);
  printf("scene=%s tris=%zu skipped_degenerate=%zu threads=%d build_seconds=%.3f\n", s->name, nt,
         fr_scene_skipped_triangles(s), threads, st.build_seconds);
  printf("bvh2 inner=%zu leaves=%zu sah=%.2f leaf_fill=%.2f\n", st.bvh2_inner, st.bvh2_leaves, st.bvh2_sah, st.bvh2_leaf_fill);
  const fr_wide_stats *w[2] = {&st.bvh4, &st.bvh8};
  for (int i = 0; i < 2; i++)
    printf("bvh%d inner=%zu leaves=%zu sah=%.2f sah_blocks=%.2f node_fill=%.2f/%d leaf_fill=%.2f/4 depth=%d node_bytes=%zu tri_bytes=%zu bytes_per_tri=%.1f\n",
           4 << i, w[i]->inner, w[i]->leaves, w[i]->sah, w[i]->sah_blocks, w[i]->node_fill, 4 << i, w[i]->leaf_fill, w[i]->depth,
           w[i]->node_bytes, w[i]->tri_bytes, (double)(w[i]->node_bytes + w[i]->tri_bytes) / (double)nt);
  if (embree) {
    for (int q = 1; q <= 2; q++) {
      double sah, sahb, sec;
      if (ebr_builder_sah(s, threads, q, &sah, &sahb, &sec) == FR_OK)
        printf("embree_builder width=4 quality=%s sah=%.2f sah_blocks=%.2f seconds=%.3f frusta_bvh4_over_embree sah=%.3f sah_blocks=%.3f\n",
               q == 2 ? "high" : "medium", sah, sahb, sec, st.bvh4.sah / sah, st.bvh4.sah_blocks / sahb);
    }
    ebr_scene *e;
    ebr_options o = {threads, 2, 0};
    if (ebr_create(s, o, &e) == FR_OK) {
      printf("embree_scene quality=high build_seconds=%.3f bytes=%zu bytes_per_tri=%.1f build_ratio_frusta_over_embree=%.2f\n",
             ebr_build_seconds(e), ebr_bytes(e), (double)ebr_bytes(e) / (double)nt, st.build_seconds / ebr_build_seconds(e));
      ebr_release(e);
    }
  }
  fr_scene_release(s);
  return 0;
}
