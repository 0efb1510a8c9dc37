/*
 * The tile feed of a cluster frame (cluster.h).
 *
 * Rank 0 holds the queue: the frame's tiles in the renderer's order,
 * handed to the other ranks in ranges that shrink as the queue empties
 * (guided scheduling: large ranges while there is much left, one tile per
 * thread at the end, so that the ranks finish together). Rank 0's own
 * threads take one tile per thread at a time, and whichever takes them
 * answers the other ranks' messages first and copies the pixels they sent
 * into the frame's buffers: rank 0 has no thread of its own for MPI,
 * which on a loaded machine waits milliseconds for a core. So rank 0
 * answers within about one tile's time; a worker keeps one request ahead
 * of the range it renders, at least as long, so that it never waits for
 * rank 0 between ranges, and sends each finished range's pixels without
 * waiting for them to arrive. Once its own tiles are done, rank 0 only
 * answers, until every worker has sent its last message.
 *
 * Messages (MPI_COMM_WORLD; every one carries the frame's number, and
 * the tags alternate with the frame's parity, so that a worker's request
 * for the next frame waits in MPI until rank 0 gets there):
 *   ASK     worker -> 0  int32 {frame, threads}: one more range, please
 *   RANGE   0 -> worker  int32 {frame, first, count}: count 0: no more
 *   PIXELS  worker -> 0  int32 {frame, first, count, 0}, then the range's
 *                        tiles, tile by tile, each plane's rows in turn
 *   FINISH  worker -> 0  {frame, tiles, rays, bytes}: its last message
 * Nothing waits in a blocking MPI call: a wait polls and sleeps, so that
 * a waiting rank leaves its core to the renderers (Open MPI's blocking
 * calls spin).
 */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "base/error.h"
#include "base/timer.h"
#include "cluster/cluster.h"

/* A worker's range is the queue's tiles left / (GUIDED x ranks). It holds
 * two ranges at a time, and a tile's cost varies tenfold over an image,
 * so the ranges it holds when the queue runs dry must be a small share of
 * the frame. */
#define GUIDED 16
#define POLL_EVERY 100e-6 /* seconds: rank 0's threads look for messages at most this often */

enum { TAG_ASK, TAG_RANGE, TAG_PIXELS, TAG_FINISH, TAGS };

/* A message kind's tag in a frame. */
static int tag(int frame, int kind) { return 100 + TAGS * (frame & 1) + kind; }

typedef struct finish_msg {
  int32_t frame, tiles;
  uint64_t rays, bytes;
} finish_msg;

/* a per-pixel buffer of the frame the ranks send back */
typedef struct plane {
  float *base;
  int channels;
} plane;

typedef struct pending_send {
  MPI_Request req;
  void *buf;
} pending_send;

struct fr_cluster_feed {
  fr_tile_feed feed;
  int rank, size, frame;
  /* the frame */
  fr_tile_grid grid;
  int width, height, threads;
  plane planes[5];
  int nplanes;
  char error[300];
  int failed;
  /* rank 0: every call comes with frame.c's lock held, or after its threads */
  int next, tiles_done, progress, shown_pct, workers_left;
  int *last_tiles; /* per worker: the tiles its last message counts, -1 before it came */
  double t0, polled;
  fr_cluster_share *shares;
  void *rbuf;
  size_t rcap;
  /* a worker */
  int asked, no_more;
  pending_send *sends;
  int nsends, scap;
  fr_cluster_share mine;
};

static void nap(void) {
  const struct timespec ts = {0, 30000}; /* 30 us: far below a range's time, and the core is free meanwhile */
  nanosleep(&ts, NULL);
}

static int mpi_failed(fr_cluster_feed *f, int code, const char *what) {
  if (code == MPI_SUCCESS) return 0;
  if (!f->failed) {
    char s[MPI_MAX_ERROR_STRING];
    int n = 0;
    MPI_Error_string(code, s, &n);
    snprintf(f->error, sizeof f->error, "rank %d: MPI %s failed: %s", f->rank, what, s);
    f->failed = 1;
  }
  return 1;
}

static void fail(fr_cluster_feed *f, const char *msg, int from) {
  if (f->failed) return;
  snprintf(f->error, sizeof f->error, "rank %d: %s (from rank %d)", f->rank, msg, from);
  f->failed = 1;
}

/* Waits for a request by polling; 0, or 1 on an MPI error. */
static int wait_for(fr_cluster_feed *f, MPI_Request *req, const char *what) {
  for (;;) {
    int flag = 0;
    if (mpi_failed(f, MPI_Test(req, &flag, MPI_STATUS_IGNORE), what)) return 1;
    if (flag) return 0;
    nap();
  }
}

/* Copies the tiles first..first+count-1 of the order between the frame's
 * planes and msg (to_msg: from the planes); returns the floats copied, or
 * counts them when msg is NULL. */
static size_t copy_tiles(const fr_cluster_feed *f, int first, int count, float *msg, int to_msg) {
  const fr_tile_grid *g = &f->grid;
  size_t n = 0;
  for (int i = first; i < first + count; i++) {
    const int k = g->order ? (int)g->order[i] : i;
    const int x0 = (k % g->tiles_x) * g->size, y0 = (k / g->tiles_x) * g->size;
    const int w = x0 + g->size <= f->width ? g->size : f->width - x0;
    const int h = y0 + g->size <= f->height ? g->size : f->height - y0;
    for (int p = 0; p < f->nplanes; p++) {
      const int ch = f->planes[p].channels;
      const size_t row = (size_t)w * (size_t)ch;
      for (int y = y0; y < y0 + h; y++) {
        float *px = f->planes[p].base + ((size_t)y * (size_t)f->width + (size_t)x0) * (size_t)ch;
        if (msg && to_msg) memcpy(msg + n, px, row * sizeof(float));
        else if (msg) memcpy(px, msg + n, row * sizeof(float));
        n += row;
      }
    }
  }
  return n;
}

/* The next range of the queue for a worker of threads threads: guided, at
 * least one tile per thread. */
static int take_range(fr_cluster_feed *f, int threads, int *first) {
  const int left = f->grid.count - f->next;
  int c = left / (GUIDED * f->size);
  if (c < threads) c = threads;
  if (c > left) c = left;
  *first = f->next;
  f->next += c;
  return c;
}

static void show_progress(fr_cluster_feed *f, int final) {
  if (!f->progress) return;
  const int pct = (int)(100.0 * f->tiles_done / (f->grid.count ? f->grid.count : 1));
  if (final) {
    if (f->shown_pct >= 0) fprintf(stderr, "\rrender: %3d%%\n", pct);
    return;
  }
  if (pct / 10 != f->shown_pct / 10 && fr_seconds() - f->t0 > 1.0) {
    f->shown_pct = pct;
    fprintf(stderr, "\rrender: %3d%%", pct);
    fflush(stderr);
  }
}

/* One message of a kind from worker src (st). */
static void serve(fr_cluster_feed *f, int kind, const MPI_Status *st) {
  const int src = st->MPI_SOURCE, t = tag(f->frame, kind);
  int bytes = 0;
  if (mpi_failed(f, MPI_Get_count(st, MPI_BYTE, &bytes), "get count")) return;
  if (kind == TAG_ASK) {
    int32_t ask[2];
    if (bytes != (int)sizeof ask) { fail(f, "a malformed request", src); return; }
    if (mpi_failed(f, MPI_Recv(ask, 2, MPI_INT32_T, src, t, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "receive")) return;
    if (ask[0] != f->frame || ask[1] < 1) { fail(f, "a request out of step", src); return; }
    int32_t range[3] = {f->frame, 0, 0};
    range[2] = take_range(f, ask[1], &range[1]);
    mpi_failed(f, MPI_Send(range, 3, MPI_INT32_T, src, tag(f->frame, TAG_RANGE), MPI_COMM_WORLD), "send");
  } else if (kind == TAG_PIXELS) {
    if ((size_t)bytes > f->rcap) {
      void *b = realloc(f->rbuf, (size_t)bytes);
      if (!b) { fail(f, "out of memory for the pixels", src); return; }
      f->rbuf = b, f->rcap = (size_t)bytes;
    }
    if (mpi_failed(f, MPI_Recv(f->rbuf, bytes, MPI_BYTE, src, t, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "receive"))
      return;
    const int32_t *h = f->rbuf;
    const int ok = bytes >= 16 && h[0] == f->frame && h[1] >= 0 && h[2] >= 1 && h[1] <= f->grid.count - h[2] &&
                   (size_t)bytes == 16 + copy_tiles(f, h[1], h[2], NULL, 0) * sizeof(float);
    if (!ok) { fail(f, "pixels out of step", src); return; }
    copy_tiles(f, h[1], h[2], (float *)((char *)f->rbuf + 16), 0);
    f->tiles_done += h[2];
    f->shares[src].tiles += h[2];
    f->shares[src].bytes += (uint64_t)bytes;
  } else {
    finish_msg m;
    if (bytes != (int)sizeof m) { fail(f, "a malformed last message", src); return; }
    if (mpi_failed(f, MPI_Recv(&m, (int)sizeof m, MPI_BYTE, src, t, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "receive"))
      return;
    if (m.frame != f->frame || m.tiles < 0 || f->last_tiles[src] >= 0) { fail(f, "a last message out of step", src); return; }
    f->shares[src].rays = m.rays;
    f->last_tiles[src] = m.tiles;
  }
  /* A worker is done when its last message and all the pixels it counts
   * are in. The pixels may come after it: each kind is probed by its own
   * tag, and MPI keeps a sender's order only among messages one probe
   * could match. */
  const int last = f->last_tiles[src];
  if (last >= 0 && f->shares[src].tiles > last) fail(f, "more pixels than its last message counts", src);
  else if (last >= 0 && f->shares[src].tiles == last) f->last_tiles[src] = INT32_MAX, f->workers_left--;
}

/* Rank 0: answers every message that has come; whether there was one. */
static int poll(fr_cluster_feed *f) {
  int served = 0;
  for (int again = 1; again && !f->failed;) {
    again = 0;
    for (int kind = 0; kind < TAGS && !f->failed; kind++) {
      if (kind == TAG_RANGE) continue; /* rank 0 sends those */
      int flag = 0;
      MPI_Status st;
      if (mpi_failed(f, MPI_Iprobe(MPI_ANY_SOURCE, tag(f->frame, kind), MPI_COMM_WORLD, &flag, &st), "probe") || !flag)
        continue;
      serve(f, kind, &st);
      again = served = 1;
    }
  }
  show_progress(f, 0);
  return served;
}

static int feed_begin(void *ctx, const fr_workload *w, const fr_tile_grid *g) {
  fr_cluster_feed *f = ctx;
  f->frame++;
  f->grid = *g;
  f->width = w->cam.width, f->height = w->cam.height, f->threads = w->threads > 0 ? w->threads : 1;
  f->failed = 0;
  f->error[0] = '\0';
  f->nplanes = 0;
  float *const bases[5] = {w->image, w->gbuf_vis, w->gbuf_depth, w->gbuf_normal, w->gbuf_albedo};
  static const int channels[5] = {3, 1, 1, 3, 3};
  for (int p = 0; p < 5; p++)
    if (bases[p]) f->planes[f->nplanes++] = (plane){bases[p], channels[p]};
  if (f->rank == 0) {
    f->next = f->tiles_done = 0;
    f->workers_left = f->size - 1;
    memset(f->shares, 0, (size_t)f->size * sizeof *f->shares);
    for (int r = 0; r < f->size; r++) f->last_tiles[r] = -1;
    f->progress = w->progress;
    f->shown_pct = -1;
    f->t0 = fr_seconds();
    poll(f);
    return 0;
  }
  memset(&f->mine, 0, sizeof f->mine);
  f->no_more = 0;
  f->asked = 0;
  const int32_t ask[2] = {f->frame, f->threads};
  for (int k = 0; k < 2; k++) { /* one range to render, one to come */
    if (mpi_failed(f, MPI_Send(ask, 2, MPI_INT32_T, 0, tag(f->frame, TAG_ASK), MPI_COMM_WORLD), "send")) break;
    f->asked++;
  }
  return 0;
}

/* A worker: the answer to its oldest request. */
static int receive_range(fr_cluster_feed *f, int32_t range[3]) {
  MPI_Request req;
  if (mpi_failed(f, MPI_Irecv(range, 3, MPI_INT32_T, 0, tag(f->frame, TAG_RANGE), MPI_COMM_WORLD, &req), "receive") ||
      wait_for(f, &req, "receive"))
    return 1;
  f->asked--;
  if (range[0] != f->frame || range[1] < 0 || range[2] < 0 || range[1] > f->grid.count - range[2]) {
    fail(f, "a range out of step", 0);
    return 1;
  }
  return 0;
}

static int feed_next(void *ctx, int *first, int *count) {
  fr_cluster_feed *f = ctx;
  if (f->rank == 0) {
    const double now = fr_seconds();
    if (now - f->polled > POLL_EVERY) { /* an MPI probe costs about a microsecond: not after every tile */
      f->polled = now;
      poll(f);
    }
    const int left = f->grid.count - f->next;
    *first = f->next;
    *count = f->threads < left ? f->threads : left;
    f->next += *count;
    return *count > 0;
  }
  int32_t range[3];
  if (f->no_more || f->failed || f->asked == 0 || receive_range(f, range)) return 0;
  if (range[2] == 0) { f->no_more = 1; return 0; }
  const int32_t ask[2] = {f->frame, f->threads};
  if (!mpi_failed(f, MPI_Send(ask, 2, MPI_INT32_T, 0, tag(f->frame, TAG_ASK), MPI_COMM_WORLD), "send")) f->asked++;
  *first = range[1], *count = range[2];
  return 1;
}

/* A worker's sends whose buffers may go. */
static void reap_sends(fr_cluster_feed *f) {
  int k = 0;
  for (int i = 0; i < f->nsends; i++) {
    int flag = 0;
    if (!mpi_failed(f, MPI_Test(&f->sends[i].req, &flag, MPI_STATUS_IGNORE), "send") && !flag) { f->sends[k++] = f->sends[i]; continue; }
    free(f->sends[i].buf);
  }
  f->nsends = k;
}

static void feed_done(void *ctx, int first, int count) {
  fr_cluster_feed *f = ctx;
  if (f->rank == 0) {
    f->tiles_done += count;
    f->shares[0].tiles += count;
    return;
  }
  reap_sends(f);
  if (f->failed) return;
  const size_t bytes = 16 + copy_tiles(f, first, count, NULL, 1) * sizeof(float);
  if (bytes > (size_t)0x7fffffff) { fail(f, "a range too large for one message", f->rank); return; }
  int32_t *msg = malloc(bytes);
  if (f->nsends == f->scap) {
    const int cap = f->scap ? 2 * f->scap : 16;
    pending_send *s = realloc(f->sends, (size_t)cap * sizeof *s);
    if (s) f->sends = s, f->scap = cap;
  }
  if (!msg || f->nsends == f->scap) { free(msg); fail(f, "out of memory for the pixels", f->rank); return; }
  msg[0] = f->frame, msg[1] = first, msg[2] = count, msg[3] = 0;
  copy_tiles(f, first, count, (float *)(msg + 4), 1);
  pending_send *s = &f->sends[f->nsends];
  if (mpi_failed(f, MPI_Isend(msg, (int)bytes, MPI_BYTE, 0, tag(f->frame, TAG_PIXELS), MPI_COMM_WORLD, &s->req), "send")) {
    free(msg);
    return;
  }
  s->buf = msg;
  f->nsends++;
  f->mine.tiles += count;
  f->mine.bytes += bytes;
}

static int feed_end(void *ctx, uint64_t rays, uint64_t *all_rays) {
  fr_cluster_feed *f = ctx;
  *all_rays = rays;
  if (f->rank == 0) {
    while (f->workers_left > 0 && !f->failed)
      if (!poll(f)) nap();
    show_progress(f, 1);
    f->shares[0].rays = rays;
    uint64_t all = 0;
    int tiles = 0;
    for (int r = 0; r < f->size; r++) all += f->shares[r].rays, tiles += f->shares[r].tiles;
    *all_rays = all;
    if (!f->failed && tiles != f->grid.count) fail(f, "a frame with tiles missing", 0);
  } else {
    int32_t range[3];
    while (!f->failed && f->asked > 0) /* answers to the requests still out: ranges of none */
      if (!receive_range(f, range) && range[2] != 0) fail(f, "a range after the last", 0);
    for (int i = 0; i < f->nsends; i++) {
      if (!f->failed) wait_for(f, &f->sends[i].req, "send");
      free(f->sends[i].buf);
    }
    f->nsends = 0;
    finish_msg m = {f->frame, f->mine.tiles, rays, f->mine.bytes};
    f->mine.rays = rays;
    if (!f->failed) mpi_failed(f, MPI_Send(&m, (int)sizeof m, MPI_BYTE, 0, tag(f->frame, TAG_FINISH), MPI_COMM_WORLD), "send");
  }
  if (f->failed) fr_fail(FR_ERR_ARG, "cluster frame: %s", f->error);
  return f->failed;
}

fr_cluster_feed *fr_cluster_feed_new(void) {
  fr_cluster_feed *f = calloc(1, sizeof *f);
  if (!f) return NULL;
  f->rank = fr_cluster_rank(), f->size = fr_cluster_size();
  f->shares = calloc((size_t)f->size, sizeof *f->shares);
  f->last_tiles = calloc((size_t)f->size, sizeof *f->last_tiles);
  if (!f->shares || !f->last_tiles) {
    fr_cluster_feed_free(f);
    return NULL;
  }
  f->feed = (fr_tile_feed){f, feed_begin, feed_next, feed_done, feed_end};
  return f;
}

void fr_cluster_feed_free(fr_cluster_feed *f) {
  if (!f) return;
  free(f->shares);
  free(f->last_tiles);
  free(f->rbuf);
  free(f->sends);
  free(f);
}

const fr_tile_feed *fr_cluster_feed_of(fr_cluster_feed *f) { return &f->feed; }

fr_cluster_share fr_cluster_feed_share(const fr_cluster_feed *f, int r) {
  if (f->rank != 0) return r == f->rank ? f->mine : (fr_cluster_share){0, 0, 0};
  return r >= 0 && r < f->size ? f->shares[r] : (fr_cluster_share){0, 0, 0};
}
