#ifndef FR_TOOL_COMMANDS_H
#define FR_TOOL_COMMANDS_H
int cmd_render(int argc, char **argv);
int cmd_view(int argc, char **argv);
int cmd_bench(int argc, char **argv);
int cmd_trace(int argc, char **argv);
int cmd_stats(int argc, char **argv);
#endif
