/* The command's side of a cluster run (src/cluster): the ranks agree that
 * each could set up, then share their frames. */
#ifndef FR_TOOL_CLI_CLUSTER_H
#define FR_TOOL_CLI_CLUSTER_H
#include "cluster/cluster.h"
#include "render/workload.h"

/* rc is this rank's outcome of its setup so far (0, or an exit code after
 * cli_error). Every rank learns the first failure; rank 0 tells one that
 * was another rank's. Then, with more than one rank, *feed deals w's
 * frames over the ranks. Returns the exit code every rank should give
 * (0: go on). */
int cli_cluster_join(int rc, fr_workload *w, fr_cluster_feed **feed);

/* Whether this process writes the output and prints (rank 0). */
static inline int cli_cluster_leader(void) { return fr_cluster_rank() == 0; }
#endif
