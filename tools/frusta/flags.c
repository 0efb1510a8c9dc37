#include "flags.h"
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "frusta.h"

#define R CLI_RENDER
#define B CLI_BENCH
#define T CLI_TRACE
#define S CLI_STATS
#define V CLI_VIEW

const cli_flag cli_flags[F_COUNT] = {
    [F_SIZE] = {"--size", "WxH", R | B | S | V, "image size (default 1024x1024)"},
    [F_EYE] = {"--eye", "x,y,z", R | B | S | V, "camera position (default: the scene's view, or one framing its box)"},
    [F_AT] = {"--at", "x,y,z", R | B | S | V, "point the camera looks at"},
    [F_UP] = {"--up", "x,y,z", R | B | S | V, "camera up direction"},
    [F_FOV] = {"--fov", "DEG", R | B | S | V, "vertical field of view in degrees, in (0, 180)"},
    [F_LIGHT] = {"--light", "x,y,z", R | B | S | V, "point light position (default: the scene's)"},
    [F_AREA] = {"--area", "c,e1,e2", R | B | S | V, "quad area light: corner and two edges, nine numbers (default: the scene's)"},
    [F_THREADS] = {"--threads", "N", R | B | S | V, "threads, 1..1024 (default: every core)"},
    [F_ISA] = {"--isa", "avx512|avx2|scalar", R | B | T | S | V,
               "instruction set of the kernels (default: the best the CPU has; also FRUSTA_ISA)"},
    [F_SCENE_ROOT] = {"--scene-root", "DIR", R | B | T | S | V,
                       "a scene file's meshes and maps may lie anywhere under DIR (default: its own folder only)"},
    [F_SMOOTH] = {"--smooth", "DEG", R | B | V,
                  "smooth shading normals where the file has none, across edges under DEG degrees (default 30; 0: flat)"},
    [F_OUT] = {"--out", "FILE", R | T, "render: the image, .png, .exr or .pfm; trace: the hit or occlusion file"},
    [F_SHADE] = {"--shade", "eyelight|normals|shadows|softshadow|whitted|ao|path", R | V, "what to render (default eyelight)"},
    [F_LIGHT_SAMPLES] = {"--light-samples", "N", R,
                         "softshadow: shadow rays per pixel, a multiple of 16 (default 16, filtered; more: "
                         "unfiltered passes of 16 spread samples)"},
    [F_FILTER] = {"--filter", "on|off", R | V, "softshadow: the 4x4 discontinuity filter (default on at 16 samples)"},
    [F_LIGHT_SETS] = {"--light-sets", "cells|spread", R | B | V,
                      "soft shadows: each pixel's 16 samples in one cell of the light (render's default) or "
                      "stratified over all of it (bench's default)"},
    [F_MFT] = {"--mft", "on|off", R,
               "camera and shadow rays as multi-frusta (path: the camera hits' rays to the point light; default on; "
               "off: streams)"},
    [F_REFERENCE_OUT] = {"--reference-out", "FILE", R,
                         "softshadow: also render the 256-sample reference there and print the error"},
    [F_SPP] = {"--spp", "N", R | B | V,
               "path: samples per pixel, 1..65536 (default 16; view: 1024, one per frame); ao: hemisphere rays per "
               "pixel, a multiple of 16 (default 16; view: 1024)"},
    [F_MAX_DEPTH] = {"--max-depth", "N", R | B | V, "path: segments per path, 1..64 (default 13)"},
    [F_ENV] = {"--env", "FILE", R | B | V, "path: an HDR environment map, EXR or Radiance .hdr, latitude-longitude"},
    [F_ENV_COLOR] = {"--env-color", "r,g,b", R | B | V, "path: a constant environment (default 1,1,1 without --env)"},
    [F_ENV_INTENSITY] = {"--env-intensity", "X", R | B | V, "path: scales the environment (default 1)"},
    [F_ENV_ROTATE] = {"--env-rotate", "DEG", R | B | V, "path: turns the environment about the up vector (default 0)"},
    [F_LIGHTS] = {"--lights", "env,area,point|none", R | B | V,
                  "path: the lights (default env,area; the area and point lights of --area and --light, each "
                  "bright enough to light what the camera looks at)"},
    [F_APERTURE] = {"--aperture", "R", R | B | V, "path: lens radius, depth of field (default 0: a pinhole)"},
    [F_FOCUS] = {"--focus", "D", R | B | V, "path: focus distance (default: from the eye to --at)"},
    [F_SAMPLER] = {"--sampler", "hammersley|sobol", R | B | V,
                   "path: padded scrambled Hammersley (render's default) or Owen-scrambled Sobol (view's: it is good at every count)"},
    [F_SEED] = {"--seed", "N", R | B | V, "path: the sampler's seed (default 1)"},
    [F_AOV] = {"--aov", NULL, R, "path: also write the first hits' albedo and normal, NAME.albedo.exr and NAME.normal.exr"},
    [F_EXPOSURE] = {"--exposure", "EV", R | V, "path: PNG exposure in stops before the filmic tone curve (default 0)"},
    [F_DENOISE] = {"--denoise", "on|off", R | V,
                   "path, ao, softshadow: the edge-aware denoiser guided by albedo, normal and depth (render: off; view: on)"},
    [F_TEMPORAL] = {"--temporal", "on|off", V,
                    "path, ao: while the camera moves, blend each frame with the last one carried to the new view "
                    "through its first hits (default on)"},
    [F_FRAMES] = {"--frames", "N", V, "render N frames, print each one's time and exit (default: until the window closes)"},
    [F_CAMERA_PATH] = {"--camera-path", "FILE", V,
                       "frames along a camera path: lines of eye, at, up (x,y,z each) and fov, as --record writes"},
    [F_TURNTABLE] = {"--turntable", "DEG", V, "with --frames: turn the camera DEG degrees about the scene's up each frame"},
    [F_SCREENSHOT] = {"--screenshot", "FILE", V,
                      "with --frames: write the last frame (.png, .exr or .pfm; a path image's PNG gets its EXR beside "
                      "it); a # in FILE writes every frame, numbered"},
    [F_RECORD] = {"--record", "FILE", V, "write the camera of every frame to FILE, a camera path"},
    [F_MIRROR] = {"--mirror", "NAME,..|all", R | B | V,
                  "whitted and path: materials that mirror (default: the scene's; whitted's all: every surface reflects half)"},
    [F_GLASS] = {"--glass", "NAME,..", R | B | V, "whitted and path: materials that refract (default: the scene's)"},
    [F_DEPTH] = {"--depth", "N", R | B | V, "whitted: recursion depth, 1..8 (default 4)"},
    [F_PACKET] = {"--packet", "2|4|8|16|32", R, "whitted with large packets: packet side (default 16)"},
    [F_TRAVERSAL] = {"--traversal", "masked|ranged|partition", R | B, "large packets: traversal (default ranged)"},
    [F_CULL] = {"--cull", "off|ia|planes|corners", R | B, "large packets: whole-packet cull (default off)"},
    [F_WORKLOAD] = {"--workload", "W[,W..]|all", B | S,
                    "primary, shadow, soft16, ao16, diffuse8, specular8, whitted, path (docs/workloads.md; all: but path)"},
    [F_MODE] = {"--mode", "M[,M..]|all", R | B | T | V,
                "bench: frusta's single single4 packet8 packet16 hybrid16 auto raystream mft packet2x2..packet32x32, "
                "Embree's single packet4 packet8 packet16 stream; trace: single (default) packet8 packet16 hybrid16 "
                "auto raystream; render --shade path: auto (default) single packet8 packet16 hybrid16 raystream; view: mft "
                "(default) auto packet16 single"},
    [F_TRACER] = {"--tracer", "frusta|embree|both", R | B | T,
                  "who traces (default frusta; trace: embree answers in its watertight mode; render --shade path: "
                  "embree traces the same paths, as streams)"},
    [F_QUERY] = {"--query", "closest|any", T, "closest hits (.hits) or occlusion (.occl)"},
    [F_REPEAT] = {"--repeat", "K", B, "repetitions of every run, interleaved; the line gives best and median (default 3)"},
    [F_EMBREE] = {"--embree", NULL, S, "Embree's build time, memory, SAH and tree beside frusta's"},
    [F_EMBREE_FLAG] = {"--embree-flag", "best|hint|coherent|incoherent", B,
                       "Embree's context flag (default best: the fastest, measured in the run)"},
    [F_EMBREE_PACKING] = {"--embree-packing", "best|rays|samples", B,
                          "Embree's packets: consecutive rays, or one sample of 16 pixels (default best)"},
    [F_THRESHOLD] = {"--threshold", "N", B | S, "hybrid16: switch to single rays at N active rays, 0..16 (default 7)"},
    [F_COHERENT_THRESHOLD] = {"--coherent-threshold", "N", B | S,
                              "the same for packets known to be coherent, 0..16 (default 2)"},
    [F_PACKET_WIDTH] = {"--packet-width", "4|8", B | S, "the BVH packets traverse (default 8)"},
    [F_MAILBOX] = {"--mailbox", "on|off", B, "packets: inverse mailboxing (default off)"},
    [F_AXIS_ALIGNED] = {"--axis-aligned", "on|off", B, "packets: Shevtsov's axis-aligned path (default on)"},
    [F_IA] = {"--ia", "on|off", B, "packets: interval-arithmetic culling (default on)"},
    [F_QUAD] = {"--quad", "on|off", B, "packets: leaves reached by few rays tested four by four (default on)"},
    [F_STREAM_SPREAD] = {"--stream-spread", "S", B,
                         "auto: groups of 16 whose directions lie within S of the first go as packets, 0..2 (default 0.1)"},
    [F_PREFETCH] = {"--prefetch", "on|off|auto", B, "prefetch deferred children (default auto: trees over 32 MB)"},
    [F_OCCLUDER_CACHE] = {"--occluder-cache", "on|off", B,
                          "single: shadow rays first test their stream's last occluder (default on)"},
    [F_ANYHIT_ORDER] = {"--anyhit-order", "auto|rank|nearest", B,
                        "single: child order of shadow rays (default auto: measured per thread)"},
    [F_CORNER_RAYS] = {"--corner-rays", "on|off", B, "multi-frusta: corner-ray culling (default on)"},
    [F_CORNER_COST] = {"--corner-cost", "C", B,
                       "multi-frusta: cull a triangle only where it spares more than C ray tests, 0..16 (default 2.5)"},
    [F_SHRINK] = {"--shrink", "on|corners|off", B,
                  "multi-frusta: shrink shadow frusta to their active rays (default on: corners and intervals)"},
    [F_MFT_LEAF] = {"--mft-leaf", "N", B, "multi-frusta: one binary tree of leaf size N for all frusta"},
    [F_MFT_FALLBACK] = {"--mft-fallback", "on|off", B,
                        "soft and point-light shadows: tiles fall back to ray streams (default on)"},
    [F_MFT_SHAFT] = {"--mft-shaft", "on|off", B, "soft shadows: tile shafts (default on)"},
};

static const struct {
  cli_cmd cmd;
  const char *name, *synopsis, *what;
} commands[] = {
    {CLI_RENDER, "render", "SCENE|SCENE.json|--builtin[=sphereflake|materials] --out FILE [flags]",
     "renders an image (a scene file's settings are the defaults of the flags)"},
    {CLI_BENCH, "bench", "SCENE --workload W --mode M [flags]",
     "measures Mrays/s of frusta's and Embree's modes on a workload, side by side"},
    {CLI_TRACE, "trace", "SCENE RAYS --query closest|any --out FILE [flags]",
     "answers a ray file (docs/rayfile.md)"},
    {CLI_STATS, "stats", "SCENE [--embree] [--workload W] [flags]",
     "prints the trees' statistics, build time and memory; --workload: the MIC paper's Table V (counters build)"},
    {CLI_VIEW, "view", "SCENE|SCENE.json|--builtin[=NAME] [flags]",
     "shows the scene in a window, rendering while you move (keys: frusta view --help)"},
};
#define NCMD (int)(sizeof commands / sizeof commands[0])

static int cmd_index(cli_cmd cmd) {
  for (int i = 0; i < NCMD; i++)
    if (commands[i].cmd == cmd) return i;
  return 0;
}

int cli_args_parse(cli_cmd cmd, int argc, char **argv, int max_pos, cli_args *a) {
  memset(a, 0, sizeof *a);
  const char *name = commands[cmd_index(cmd)].name;
  for (int i = 0; i < argc; i++) {
    const char *arg = argv[i];
    if (!strcmp(arg, "--help") || !strcmp(arg, "-h")) {
      cli_help(stdout, cmd);
      return CLI_HELP_SHOWN;
    }
    if (arg[0] != '-' || cli_is_builtin(arg)) {
      if (a->npos == max_pos) return cli_error(CLI_USAGE_ERROR, "%s: unexpected argument '%s'", name, arg);
      a->pos[a->npos++] = arg;
      continue;
    }
    int f = 0;
    while (f < F_COUNT && !((cli_flags[f].cmds & cmd) && !strcmp(arg, cli_flags[f].name))) f++;
    if (f == F_COUNT) return cli_error(CLI_USAGE_ERROR, "%s: unknown option '%s' (see frusta %s --help)", name, arg, name);
    if (!cli_flags[f].value) { a->val[f] = ""; continue; }
    if (i + 1 >= argc) return cli_error(CLI_USAGE_ERROR, "%s needs a value (%s)", arg, cli_flags[f].value);
    a->val[f] = argv[++i];
  }
  return 0;
}

int cli_arg_int(const cli_args *a, cli_flag_id f, int lo, int hi, int *out) {
  const char *s = a->val[f];
  if (!s) return 0;
  char *e;
  errno = 0;
  long v = strtol(s, &e, 10);
  if (e == s || *e || errno || v < lo || v > hi)
    return cli_error(CLI_USAGE_ERROR, "%s wants %d..%d, got '%s'", cli_flags[f].name, lo, hi, s);
  *out = (int)v;
  return 0;
}

int cli_arg_float(const cli_args *a, cli_flag_id f, float lo, float hi, float *out) {
  const char *s = a->val[f];
  if (!s) return 0;
  float v;
  if (!cli_parse_float(s, &v) || !(v >= lo && v <= hi))
    return cli_error(CLI_USAGE_ERROR, "%s wants %g..%g, got '%s'", cli_flags[f].name, (double)lo, (double)hi, s);
  *out = v;
  return 0;
}

int cli_arg_choice(const cli_args *a, cli_flag_id f, const char *const *names, int n, int *out) {
  const char *s = a->val[f];
  if (!s) return 0;
  char list[256] = "";
  for (int i = 0; i < n; i++) {
    if (!strcmp(s, names[i])) { *out = i; return 0; }
    const size_t len = strlen(list);
    snprintf(list + len, sizeof list - len, "%s%s", i == 0 ? "" : i == n - 1 ? " or " : ", ", names[i]);
  }
  return cli_error(CLI_USAGE_ERROR, "%s is %s, not '%s'", cli_flags[f].name, list, s);
}

int cli_arg_onoff(const cli_args *a, cli_flag_id f, int *out) {
  static const char *const names[] = {"off", "on"};
  return cli_arg_choice(a, f, names, 2, out);
}

void cli_help(FILE *out, cli_cmd cmd) {
  const int c = cmd_index(cmd);
  fprintf(out, "usage: frusta %s %s\n%s.\n\nflags:\n", commands[c].name, commands[c].synopsis, commands[c].what);
  for (int f = 0; f < F_COUNT; f++) {
    if (!(cli_flags[f].cmds & cmd)) continue;
    char head[96];
    snprintf(head, sizeof head, "%s%s%s", cli_flags[f].name, cli_flags[f].value ? " " : "",
             cli_flags[f].value ? cli_flags[f].value : "");
    if (strlen(head) <= 28) fprintf(out, "  %-28s %s\n", head, cli_flags[f].help);
    else fprintf(out, "  %s\n  %-28s %s\n", head, "", cli_flags[f].help);
  }
}

void cli_usage(FILE *out) {
  fprintf(out, "usage: frusta COMMAND [flags]   (frusta COMMAND --help: its flags)\n\ncommands:\n");
  for (int c = 0; c < NCMD; c++) fprintf(out, "  %-7s %s\n          %s.\n", commands[c].name, commands[c].synopsis, commands[c].what);
  fprintf(out, "\nScenes: PLY, OBJ(+MTL) and every format Assimp reads, optionally .zst.\n"
               "Environment: FRUSTA_ISA=avx512|avx2|scalar forces an instruction set.\n"
               "frusta --version prints the version.\n");
}

/* Text for roff: a leading '.' or '\'' would be a request, '\' an escape,
 * '-' a hyphen. */
static void roff(FILE *out, const char *s) {
  if (*s == '.' || *s == '\'') fputs("\\&", out);
  for (; *s; s++) {
    if (*s == '\\') fputs("\\e", out);
    else if (*s == '-') fputs("\\-", out);
    else fputc(*s, out);
  }
}

void cli_man(FILE *out) {
  fprintf(out, ".TH FRUSTA 1 \"\" \"frusta %d.%d\" \"User Commands\"\n", FR_VERSION_MAJOR, FR_VERSION_MINOR);
  fputs(".SH NAME\nfrusta \\- real\\-time ray tracing on CPUs: render, benchmark, trace and inspect scenes\n", out);
  fputs(".SH SYNOPSIS\n", out);
  for (int c = 0; c < NCMD; c++) {
    fprintf(out, ".B frusta %s\n", commands[c].name);
    roff(out, commands[c].synopsis);
    fputs("\n.br\n", out);
  }
  fputs(".SH DESCRIPTION\n", out);
  for (int c = 0; c < NCMD; c++) {
    fprintf(out, ".SS %s\n", commands[c].name);
    roff(out, commands[c].what);
    fputs(".\n", out);
    for (int f = 0; f < F_COUNT; f++) {
      if (!(cli_flags[f].cmds & commands[c].cmd)) continue;
      fputs(".TP\n.B ", out);
      roff(out, cli_flags[f].name);
      if (cli_flags[f].value) { fputs(" ", out); roff(out, cli_flags[f].value); }
      fputs("\n", out);
      roff(out, cli_flags[f].help);
      fputs("\n", out);
    }
  }
  fputs(".SH ENVIRONMENT\n.TP\n.B FRUSTA_ISA\navx512, avx2 or scalar: the instruction set of the kernels.\n", out);
  fputs(".SH EXIT STATUS\n0 on success, 1 on an error, 2 on a usage error; errors are one line on standard error.\n", out);
  fputs(".SH SEE ALSO\nREADME.md, docs/workloads.md, docs/rayfile.md, docs/api.md\n", out);
}
