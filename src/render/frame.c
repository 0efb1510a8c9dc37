/*
 * A workload's frame: its tiles handed to the threads in Morton order, each
 * traced by the tile driver of its workload (tile.c, or whitted.c).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/timer.h"
#include "render/tile.h"
#include "render/path.h"
#include "render/whitted.h"
#include "trace/counters.h"

fr_workload_result fr_workload_run(const fr_workload *w0, const fr_tracer *t) {
  /* the ray sets of this frame, shared by every tile */
  fr_workload run = *w0, *w = &run;
  fr_mft_sets *sets = fr_alloc_aligned(2 * sizeof(fr_mft_sets), 64);
  if (!sets) { fr_workload_result none = {0, 0.0, {0}, 0}; return none; }
  float e1[3] = {w->view.area_e1.x, w->view.area_e1.y, w->view.area_e1.z};
  float e2[3] = {w->view.area_e2.x, w->view.area_e2.y, w->view.area_e2.z};
  fr_mft_sets_light(&sets[0], e1, e2, w->seed, w->light_sets_kind);
  fr_mft_sets_camera(&sets[1], &w->cam);
  run.light_sets = &sets[0];
  run.camera_set = &sets[1];
  const int whitted = w->kind == FR_WL_WHITTED, tile = whitted ? FR_WHITTED_TILE : TILE;
  const int tiles_x = (w->cam.width + tile - 1) / tile, tiles_y = (w->cam.height + tile - 1) / tile;
  const int ntiles = tiles_x * tiles_y;
  uint64_t total = 0;
  double stage[FR_STAGES] = {0};
  int done = 0, last_pct = -1, cancelled = 0;
  double t0 = fr_seconds();
  uint32_t *order = fr_tile_order(tiles_x, tiles_y);
#pragma omp parallel num_threads(w->threads) reduction(+ : total)
  {
    const int path = w->kind == FR_WL_PATH;
    fr_tile_buffers *B = whitted || path ? NULL : malloc(sizeof(fr_tile_buffers));
    fr_whitted_scratch *WS = whitted ? fr_whitted_scratch_new() : NULL;
    fr_path_scratch *PS = path ? fr_path_scratch_new() : NULL;
#pragma omp for schedule(dynamic, 1)
    for (int i = 0; i < ntiles; i++) {
      if (w->cancel && __atomic_load_n(w->cancel, __ATOMIC_RELAXED)) {
        __atomic_store_n(&cancelled, 1, __ATOMIC_RELAXED);
        continue;
      }
      const int k = order ? (int)order[i] : i;
      const int tx = (k % tiles_x) * tile, ty = (k / tiles_x) * tile;
      if (WS) total += fr_whitted_tile(w, t, WS, tx, ty);
      else if (PS) total += fr_path_tile(w, t, PS, tx, ty);
      else if (B) total += fr_tile_run(w, t, B, tx, ty);
      if (w->progress) {
        int d, pct;
#pragma omp atomic capture
        d = ++done;
        pct = (int)(100.0 * d / ntiles);
        if (pct / 10 != last_pct / 10 && fr_seconds() - t0 > 1.0) {
#pragma omp critical
          {
            if (pct / 10 != last_pct / 10) { last_pct = pct; fprintf(stderr, "\rrender: %3d%%", pct); fflush(stderr); }
          }
        }
      }
    }
    free(B);
#pragma omp critical
    {
      fr_whitted_scratch_stages(WS, stage);
      fr_path_scratch_stages(PS, stage);
    }
    fr_path_scratch_free(PS);
    fr_whitted_scratch_free(WS);
#ifdef FRUSTA_COUNTERS
    fr_counters_flush();
#endif
  }
  fr_workload_result r = {total, fr_seconds() - t0, {0}, cancelled};
  free(order);
  memcpy(r.stage, stage, sizeof stage);
  if (w->progress && last_pct >= 0) fprintf(stderr, "\n");
  fr_free_aligned(sets);
  return r;
}
