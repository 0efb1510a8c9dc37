/* The cluster of a frusta built without MPI: this one process. */
#include <stdio.h>
#include <stdlib.h>
#include "base/error.h"
#include "cluster/cluster.h"

/* Started by an MPI launcher with other ranks, each would render the
 * whole frame and write the same file: refuse. */
int fr_cluster_start(int *argc, char ***argv) {
  const char *n = getenv("OMPI_COMM_WORLD_SIZE");
  if (!n) n = getenv("PMI_SIZE");
  if (n && atoi(n) > 1) {
    fr_fail(FR_ERR_ARG, "this frusta was built without MPI and cannot share a frame over %s processes "
                        "(build it where CMake finds MPI: Debian's libopenmpi-dev)", n);
    return 1;
  }
  return 0;
}

void fr_cluster_stop(int rc) {}
void fr_cluster_told(int rc) {}
int fr_cluster_rank(void) { return 0; }
int fr_cluster_size(void) { return 1; }
int fr_cluster_built(void) { return 0; }

int fr_cluster_agree(int rc, const char *msg, int *rank, char *msg_out, size_t n) {
  if (rank) *rank = rc ? 0 : -1;
  if (msg_out && n) snprintf(msg_out, n, "%s", rc && msg ? msg : "");
  return rc;
}

/* one process never deals tiles: its frames take no feed */
fr_cluster_feed *fr_cluster_feed_new(void) { return NULL; }
void fr_cluster_feed_free(fr_cluster_feed *f) {}
const fr_tile_feed *fr_cluster_feed_of(fr_cluster_feed *f) { return NULL; }
fr_cluster_share fr_cluster_feed_share(const fr_cluster_feed *f, int r) { return (fr_cluster_share){0, 0, 0}; }
