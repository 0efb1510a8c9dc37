/* frusta: render | view | bench | trace | stats */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "cluster/cluster.h"
#include "commands.h"

static int run(int argc, char **argv);

/* Under an MPI launcher every rank runs the same command; the ranks but
 * rank 0 print nothing (rank 0 tells their errors). */
int main(int argc, char **argv) {
  if (fr_cluster_start(&argc, &argv)) return cli_error(1, "%s", fr_last_error());
  if (fr_cluster_rank() != 0) {
    cli_set_quiet(1);
    if (!freopen("/dev/null", "w", stdout)) return 1;
  }
  const int rc = run(argc, argv);
  fr_cluster_stop(rc);
  return rc;
}

static int run(int argc, char **argv) {
  if (argc < 2) return cli_error(CLI_USAGE_ERROR, "no command given (render, view, bench, trace or stats; see frusta --help)");
  const char *cmd = argv[1];
  if (!strcmp(cmd, "--version")) {
    printf("frusta %d.%d (%s%s)\n", FR_VERSION_MAJOR, FR_VERSION_MINOR, fr_isa_name(fr_get_isa()),
           fr_cluster_built() ? ", mpi" : "");
    return 0;
  }
  if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
    const char *topic = argc > 2 ? argv[2] : NULL;
    static const char *const names[] = {"render", "view", "bench", "trace", "stats"};
    static const cli_cmd cmds[] = {CLI_RENDER, CLI_VIEW, CLI_BENCH, CLI_TRACE, CLI_STATS};
    if (!topic) { cli_usage(stdout); return 0; }
    if (!strcmp(topic, "--man")) { cli_man(stdout); return 0; }
    for (int i = 0; i < 5; i++)
      if (!strcmp(topic, names[i])) { cli_help(stdout, cmds[i]); return 0; }
    return cli_error(CLI_USAGE_ERROR, "help: no command '%s' (render, view, bench, trace, stats or --man)", topic);
  }
  const char *isa = getenv("FRUSTA_ISA");
  if (isa && *isa && cli_set_isa(isa) != 0) return 1;
  if (fr_cluster_size() > 1 && strcmp(cmd, "render") && strcmp(cmd, "bench"))
    return cli_error(CLI_USAGE_ERROR, "%s runs as one process; under mpirun, frusta runs render and bench", cmd);
  if (!strcmp(cmd, "render")) return cmd_render(argc - 2, argv + 2);
  if (!strcmp(cmd, "view")) return cmd_view(argc - 2, argv + 2);
  if (!strcmp(cmd, "bench")) return cmd_bench(argc - 2, argv + 2);
  if (!strcmp(cmd, "trace")) return cmd_trace(argc - 2, argv + 2);
  if (!strcmp(cmd, "stats")) return cmd_stats(argc - 2, argv + 2);
  return cli_error(CLI_USAGE_ERROR, "unknown command '%s' (render, view, bench, trace or stats; see frusta --help)", cmd);
}
