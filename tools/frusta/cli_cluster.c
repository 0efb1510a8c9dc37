#include "cli_cluster.h"
#include "cli.h"

int cli_cluster_join(int rc, fr_workload *w, fr_cluster_feed **feed) {
  *feed = NULL;
  if (fr_cluster_size() == 1) return rc;
  int rank = -1;
  char msg[600];
  const int all = fr_cluster_agree(rc, cli_last_error(), &rank, msg, sizeof msg);
  if (all) {
    if (cli_cluster_leader() && rank > 0) cli_error(all, "rank %d: %s", rank, msg);
    return all;
  }
  if (!(*feed = fr_cluster_feed_new())) return cli_error(1, "out of memory");
  w->feed = fr_cluster_feed_of(*feed);
  return 0;
}
