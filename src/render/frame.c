/*
 * A workload's frame: its tiles handed to the threads in Morton order, each
 * traced by the tile driver of its workload (tile.c, or whitted.c). With a
 * feed (workload.h), the tiles are those the feed hands out, in ranges.
 */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"
#include "base/timer.h"
#include "render/tile.h"
#include "render/path.h"
#include "render/whitted.h"
#include "trace/counters.h"

/* A range the feed handed out, and how many of its tiles are not yet rendered. */
typedef struct tile_range { int first, count, left; } tile_range;

/* The tiles still to hand out: first..end-1 of the order. Without a feed
 * it is the whole frame, taken by an atomic counter; with one, the lock
 * guards the ranges and every call into the feed. */
typedef struct tile_queue {
  const fr_tile_feed *feed;
  int next, end, exhausted;
  omp_lock_t lock;
  tile_range *ranges; /* in flight: the one being handed out and those whose tiles are rendering */
  int nranges, current;
} tile_queue;

/* The next tile's place in the order and its range's slot, or -1 when the
 * frame has no more tiles for this process. */
static int take_tile(tile_queue *q, int *slot) {
  if (!q->feed) {
    const int i = __atomic_fetch_add(&q->next, 1, __ATOMIC_RELAXED);
    return i < q->end ? i : -1;
  }
  int i = -1;
  omp_set_lock(&q->lock);
  if (q->next == q->end && !q->exhausted) {
    int first = 0, count = 0, s = 0;
    while (s < q->nranges && q->ranges[s].left) s++; /* a free slot: at most one range per thread is in flight */
    if (s < q->nranges && q->feed->next(q->feed->ctx, &first, &count) && count > 0) {
      q->ranges[s] = (tile_range){first, count, count};
      q->current = s, q->next = first, q->end = first + count;
    } else {
      q->exhausted = 1;
    }
  }
  if (q->next < q->end) i = q->next++, *slot = q->current;
  omp_unset_lock(&q->lock);
  return i;
}

/* A tile of the range in slot is rendered; the range's last one tells the feed. */
static void finish_tile(tile_queue *q, int slot) {
  if (!q->feed) return;
  omp_set_lock(&q->lock);
  tile_range *r = &q->ranges[slot];
  if (--r->left == 0) q->feed->done(q->feed->ctx, r->first, r->count);
  omp_unset_lock(&q->lock);
}

int fr_workload_tile_side(const fr_workload *w) {
  if (w->kind == FR_WL_WHITTED) return FR_WHITTED_TILE;
  return w->kind == FR_WL_PATH && w->path ? fr_path_tile_side(w->path) : TILE;
}

fr_workload_result fr_workload_run(const fr_workload *w0, const fr_tracer *t) {
  fr_workload_result res = {0, 0.0, {0}, 0, 0};
  /* the ray sets of this frame, shared by every tile */
  fr_workload run = *w0, *w = &run;
  fr_mft_sets *sets = fr_alloc_aligned(2 * sizeof(fr_mft_sets), 64);
  if (!sets) { fr_fail(FR_ERR_NOMEM, "out of memory for a frame's ray sets"); res.failed = 1; return res; }
  float e1[3] = {w->view.area_e1.x, w->view.area_e1.y, w->view.area_e1.z};
  float e2[3] = {w->view.area_e2.x, w->view.area_e2.y, w->view.area_e2.z};
  fr_mft_sets_light(&sets[0], e1, e2, w->seed, w->light_sets_kind);
  fr_mft_sets_camera(&sets[1], &w->cam);
  run.light_sets = &sets[0];
  run.camera_set = &sets[1];
  const int whitted = w->kind == FR_WL_WHITTED;
  const int tile = fr_workload_tile_side(w);
  const int tiles_x = (w->cam.width + tile - 1) / tile, tiles_y = (w->cam.height + tile - 1) / tile;
  const int ntiles = tiles_x * tiles_y;
  uint64_t total = 0;
  double stage[FR_STAGES] = {0};
  int done = 0, last_pct = -1, cancelled = 0;
  const int progress = w->progress && !w->feed; /* a feed's frame is shared: the feed tells its progress */
  double t0 = fr_seconds();
  uint32_t *order = fr_tile_order(tiles_x, tiles_y);
  if (w->tile_seconds) memset(w->tile_seconds, 0, (size_t)ntiles * sizeof *w->tile_seconds);
  tile_queue q;
  memset(&q, 0, sizeof q);
  q.feed = w->feed, q.end = ntiles;
  if (w->feed) {
    const fr_tile_grid g = {tile, tiles_x, tiles_y, ntiles, order};
    q.nranges = w->threads + 2;
    q.ranges = calloc((size_t)q.nranges, sizeof *q.ranges);
    q.end = 0;
    if (!order || !q.ranges) fr_fail(FR_ERR_NOMEM, "out of memory for a frame's tile order");
    if (!order || !q.ranges || w->feed->begin(w->feed->ctx, w, &g)) {
      free(q.ranges); free(order); fr_free_aligned(sets);
      res.failed = 1;
      return res;
    }
    omp_init_lock(&q.lock);
  }
#pragma omp parallel num_threads(w->threads) reduction(+ : total)
  {
    const int path = w->kind == FR_WL_PATH;
    fr_tile_buffers *B = whitted || path ? NULL : malloc(sizeof(fr_tile_buffers));
    fr_whitted_scratch *WS = whitted ? fr_whitted_scratch_new() : NULL;
    fr_path_scratch *PS = path ? fr_path_scratch_new() : NULL;
    for (;;) {
      if (w->cancel && __atomic_load_n(w->cancel, __ATOMIC_RELAXED)) {
        __atomic_store_n(&cancelled, 1, __ATOMIC_RELAXED);
        break;
      }
      int slot = 0;
      const int i = take_tile(&q, &slot);
      if (i < 0) break;
      const int k = order ? (int)order[i] : i;
      const int tx = (k % tiles_x) * tile, ty = (k / tiles_x) * tile;
      const double tile_t0 = w->tile_seconds ? fr_seconds() : 0.0;
      if (WS) total += fr_whitted_tile(w, t, WS, tx, ty);
      else if (PS) total += fr_path_tile(w, t, PS, tx, ty);
      else if (B) total += fr_tile_run(w, t, B, tx, ty);
      if (w->tile_seconds) w->tile_seconds[i] = fr_seconds() - tile_t0;
      finish_tile(&q, slot);
      if (progress) {
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
  if (w->feed) {
    omp_destroy_lock(&q.lock);
    free(q.ranges);
    if (w->feed->end(w->feed->ctx, total, &total)) res.failed = 1;
  }
  res.rays = total;
  res.seconds = fr_seconds() - t0;
  res.cancelled = cancelled;
  free(order);
  memcpy(res.stage, stage, sizeof stage);
  if (progress && last_pct >= 0) fprintf(stderr, "\n");
  fr_free_aligned(sets);
  return res;
}
