/*
 * One frame rendered by many processes over MPI (image-parallel, as
 * OSPRay's offload device): every rank loads and builds the same scene,
 * rank 0 hands out tiles from a queue in the renderer's tile order and
 * renders too, the other ranks send their tiles' pixels back, and rank 0
 * writes the image. A tile's pixels depend only on the tile, so the image
 * is the same bits however the tiles are dealt.
 *
 * A frame is a collective call: every rank makes the same sequence of
 * fr_workload_run calls with the feed (fr_cluster_feed_of) in its
 * workload. Without MPI at build time, or when the process was not
 * started by an MPI launcher, the cluster is this one process.
 */
#ifndef FR_CLUSTER_H
#define FR_CLUSTER_H
#include <stddef.h>
#include <stdint.h>
#include "render/workload.h"

/* Joins the launcher's job when there is one (MPI_Init, one thread at a
 * time in MPI); 0, or 1 with fr_last_error set. Call once, first. */
int fr_cluster_start(int *argc, char ***argv);
/* Leaves the job (MPI_Finalize); rc is the process's exit code. */
void fr_cluster_stop(int rc);
/* This process has told the user why it fails (exit code rc): when the
 * launcher stops the job because other ranks ended, it ends quietly. */
void fr_cluster_told(int rc);
int fr_cluster_rank(void);
int fr_cluster_size(void);
/* Whether this frusta was built with MPI. */
int fr_cluster_built(void);

/* Every rank's outcome of a step (rc 0: fine, else its exit code and msg)
 * gathered on rank 0; returns, on every rank, the exit code of the first
 * rank that failed (0 when none did) and, on rank 0, that rank in *rank
 * and its message in msg_out. */
int fr_cluster_agree(int rc, const char *msg, int *rank, char *msg_out, size_t n);

/* A rank's share of the last frame (rank 0 knows every rank's). */
typedef struct fr_cluster_share {
  uint64_t rays;
  int tiles;
  uint64_t bytes; /* pixel bytes it sent to rank 0 */
} fr_cluster_share;

typedef struct fr_cluster_feed fr_cluster_feed;
/* NULL without memory. */
fr_cluster_feed *fr_cluster_feed_new(void);
void fr_cluster_feed_free(fr_cluster_feed *f);
const fr_tile_feed *fr_cluster_feed_of(fr_cluster_feed *f);
/* Rank 0: rank r's share of the last frame, r in 0..size-1. */
fr_cluster_share fr_cluster_feed_share(const fr_cluster_feed *f, int r);
#endif
