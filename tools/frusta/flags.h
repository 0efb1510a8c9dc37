/*
 * The command's flags: one table for every subcommand, from which the
 * parser, `frusta SUBCOMMAND --help` and the manual page (docs/frusta.1,
 * `frusta help --man`) are all made.
 */
#ifndef FR_TOOL_FLAGS_H
#define FR_TOOL_FLAGS_H
#include <stdio.h>

/* The subcommands, as bits of cli_flag.cmds. */
typedef enum cli_cmd { CLI_RENDER = 1, CLI_BENCH = 2, CLI_TRACE = 4, CLI_STATS = 8, CLI_VIEW = 16 } cli_cmd;

typedef enum cli_flag_id {
  /* scene and view */
  F_SIZE, F_EYE, F_AT, F_UP, F_FOV, F_LIGHT, F_AREA, F_THREADS, F_ISA, F_SCENE_ROOT, F_SMOOTH,
  /* render */
  F_OUT, F_SHADE, F_LIGHT_SAMPLES, F_FILTER, F_LIGHT_SETS, F_MFT, F_REFERENCE_OUT,
  /* path tracing */
  F_SPP, F_MAX_DEPTH, F_ENV, F_ENV_COLOR, F_ENV_INTENSITY, F_ENV_ROTATE, F_LIGHTS, F_APERTURE, F_FOCUS, F_SAMPLER,
  F_SEED, F_AOV, F_EXPOSURE, F_DENOISE,
  /* view */
  F_FRAMES, F_CAMERA_PATH, F_TURNTABLE, F_SCREENSHOT, F_RECORD, F_TEMPORAL,
  /* Whitted and large packets */
  F_MIRROR, F_GLASS, F_DEPTH, F_PACKET, F_TRAVERSAL, F_CULL,
  /* bench, trace and stats */
  F_WORKLOAD, F_MODE, F_TRACER, F_QUERY, F_REPEAT, F_EMBREE, F_EMBREE_FLAG, F_EMBREE_PACKING,
  /* kernel switches, for measurements */
  F_THRESHOLD, F_COHERENT_THRESHOLD, F_PACKET_WIDTH, F_MAILBOX, F_AXIS_ALIGNED, F_IA, F_QUAD,
  F_STREAM_SPREAD, F_PREFETCH, F_OCCLUDER_CACHE, F_ANYHIT_ORDER,
  F_CORNER_RAYS, F_CORNER_COST, F_SHRINK, F_MFT_LEAF, F_MFT_FALLBACK, F_MFT_SHAFT,
  F_COUNT
} cli_flag_id;

typedef struct cli_flag {
  const char *name;  /* "--threads" */
  const char *value; /* what it takes ("N", "on|off"), NULL for a switch */
  unsigned cmds;     /* the subcommands that take it */
  const char *help;  /* its meaning and default */
} cli_flag;

extern const cli_flag cli_flags[F_COUNT];

/* One subcommand's arguments: each flag's value as given (NULL if not
 * given; "" for a given switch), and the positional arguments (a scene,
 * --builtin or --builtin=NAME, a ray file). */
typedef struct cli_args {
  const char *val[F_COUNT];
  const char *pos[2];
  int npos;
} cli_args;

/* Sorts argv into a. Returns 0; or an exit code after reporting (2: an
 * unknown flag, a missing value, too many positional arguments); or
 * CLI_HELP_SHOWN after printing --help, for the caller to exit 0. */
#define CLI_HELP_SHOWN (-1)
int cli_args_parse(cli_cmd cmd, int argc, char **argv, int max_pos, cli_args *a);

/* The typed values: each returns 0 (and leaves *out alone where the flag
 * was not given) or 2 after reporting a one-line usage error. */
int cli_arg_int(const cli_args *a, cli_flag_id f, int lo, int hi, int *out);
int cli_arg_float(const cli_args *a, cli_flag_id f, float lo, float hi, float *out);
int cli_arg_onoff(const cli_args *a, cli_flag_id f, int *out);
/* *out = the index of the value in names[0..n) */
int cli_arg_choice(const cli_args *a, cli_flag_id f, const char *const *names, int n, int *out);

/* `frusta CMD --help`, `frusta help`, and the manual page in roff. */
void cli_help(FILE *out, cli_cmd cmd);
void cli_usage(FILE *out);
void cli_man(FILE *out);
#endif
