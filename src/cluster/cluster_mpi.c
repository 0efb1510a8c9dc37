/* The job: MPI started only under a launcher (see cluster.h). */
#include <mpi.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "base/error.h"
#include "cluster/cluster.h"

static int started, rank, size = 1;
static volatile sig_atomic_t told; /* the exit code of a failure already told, or 0 */
/* set once the ranks agreed to go on together (fr_cluster_agree): from
 * then on a rank that fails alone leaves the others waiting on it */
static int lockstep;

/* Open MPI's launchers set the first, PMIx-based ones the second, the
 * others the third: a process without any is not part of a job. */
static int launched(void) {
  return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMIX_RANK") || getenv("PMI_RANK");
}

/* A launcher stops the job when a rank dies or fails: rank 0, the one
 * whose output a user reads, says so in one line before it goes. */
static void on_stop(int sig) {
  if (told) _exit(told);
  static const char msg[] = "frusta: stopped by the MPI launcher: another rank failed or the job was interrupted\n";
  ssize_t w = write(2, msg, sizeof msg - 1);
  (void)w;
  _exit(1);
}

void fr_cluster_told(int rc) { told = rc ? rc : 1; }

int fr_cluster_start(int *argc, char ***argv) {
  if (!launched()) return 0;
  int provided = 0;
  if (MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) {
    fr_fail(FR_ERR_ARG, "MPI: cannot join the job");
    return 1;
  }
  started = 1;
  /* errors come back as codes, so a failure is reported, not aborted on */
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (provided < MPI_THREAD_SERIALIZED) {
    fr_fail(FR_ERR_ARG, "MPI: this MPI cannot be called from more than one thread (thread level %d)", provided);
    return 1;
  }
  if (size > 1 && rank == 0) {
    signal(SIGTERM, on_stop);
    signal(SIGINT, on_stop);
  }
  return 0;
}

void fr_cluster_stop(int rc) {
  if (!started) return;
  started = 0;
  if (rc && lockstep && size > 1) MPI_Abort(MPI_COMM_WORLD, rc);
  MPI_Finalize();
}

int fr_cluster_rank(void) { return rank; }
int fr_cluster_size(void) { return size; }
int fr_cluster_built(void) { return 1; }

typedef struct outcome {
  int rc;
  char msg[500];
} outcome;

int fr_cluster_agree(int rc, const char *msg, int *failed_rank, char *msg_out, size_t n) {
  if (failed_rank) *failed_rank = -1;
  if (msg_out && n) msg_out[0] = '\0';
  if (size == 1) {
    if (rc && failed_rank) *failed_rank = 0;
    if (rc && msg_out) snprintf(msg_out, n, "%s", msg ? msg : "");
    return rc;
  }
  outcome mine, *all = rank == 0 ? calloc((size_t)size, sizeof *all) : NULL;
  memset(&mine, 0, sizeof mine);
  mine.rc = rc;
  snprintf(mine.msg, sizeof mine.msg, "%s", rc && msg ? msg : "");
  if (rank == 0 && !all) {
    fr_fail(FR_ERR_NOMEM, "out of memory");
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  int first = 0;
  if (MPI_Gather(&mine, (int)sizeof mine, MPI_BYTE, all, (int)sizeof mine, MPI_BYTE, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
    MPI_Abort(MPI_COMM_WORLD, 1);
  int verdict[2] = {0, -1};
  if (rank == 0) {
    for (int r = 0; r < size; r++)
      if (all[r].rc) { verdict[0] = all[r].rc, verdict[1] = r, first = r; break; }
    if (verdict[0] && msg_out) snprintf(msg_out, n, "%s", all[first].msg);
    free(all);
  }
  if (MPI_Bcast(verdict, 2, MPI_INT, 0, MPI_COMM_WORLD) != MPI_SUCCESS) MPI_Abort(MPI_COMM_WORLD, 1);
  if (failed_rank) *failed_rank = verdict[1];
  lockstep = verdict[0] == 0;
  return verdict[0];
}
