/* Scene files on the command line: their settings become the defaults of
 * the flags (a flag given wins), their materials the path tracer's. */
#ifndef FR_TOOL_CLI_SCENE_FILE_H
#define FR_TOOL_CLI_SCENE_FILE_H
#include "flags.h"
#include "io/scene_file.h"

/* If a->pos[0] is a .json scene file: reads it and fills the flags it sets
 * and a does not (their text lives in static storage until
 * cli_scene_file_done); 0, or the exit code after reporting. */
int cli_scene_file_defaults(cli_args *a);
/* The scene file read by cli_scene_file_defaults, or NULL. */
const fr_scene_file *cli_scene_file(void);
/* --scene-root, or NULL. */
const char *cli_scene_root(void);
void cli_scene_file_done(void);
#endif
