/* frusta: render | bench | trace | stats */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "commands.h"

static void usage(FILE *f) {
  fprintf(f,
          "usage: frusta <command> [options]\n"
          "  render SCENE|--builtin --out FILE.png|.exr|.pfm [--shade eyelight|normals|shadows|softshadow|whitted]\n"
          "         [--size WxH] [--eye x,y,z --at x,y,z --up x,y,z --fov deg] [--light x,y,z] [--threads N]\n"
          "         softshadow: [--light-samples 16|32|..] [--filter on|off] [--light-sets cells|spread]\n"
          "         [--mft on|off] [--reference-out FILE]\n"
          "         whitted: [--mirror NAME,..|all] [--glass NAME,..] [--depth N] [--mft on|off]\n"
          "         --mft off: [--packet 2..32] [--traversal masked|ranged|partition] [--cull off|ia|planes|corners]\n"
          "  bench  SCENE|--builtin --workload W|all --mode M[,M..]|all [--tracer frusta|embree|both] [--threads N]\n"
          "         [--size WxH] [view flags] [--light x,y,z] [--area c,e1,e2] [--repeat K]\n"
          "         (the K repetitions of all runs picked are interleaved round-robin)\n"
          "         frusta modes: single single4 packet8 packet16 hybrid16 auto raystream mft\n"
          "                       packet2x2 packet4x4 packet8x8 packet16x16 packet32x32\n"
          "         embree modes: single packet4 packet8 packet16 stream\n"
          "         packets:      [--threshold N] [--packet-width 4|8] [--mailbox on|off] [--axis-aligned on|off]\n"
          "                       [--ia on|off] [--quad on|off] [--hybrid-tune on|off]\n"
          "         auto:         [--stream-spread S] [--coherent-threshold N] (also hybrid16's one-octant packets)\n"
          "         single rays:  [--prefetch on|off|auto] [--occluder-cache on|off] [--anyhit-order auto|rank|nearest]\n"
          "         multi-frusta: [--light-sets spread|cells] [--corner-rays on|off] [--corner-cost C]\n"
          "                       [--shrink on|corners|off] [--mft-leaf N] [--mft-fallback on|off] [--mft-shaft on|off]\n"
          "         NxN packets:  [--traversal masked|ranged|partition] [--cull off|ia|planes|corners]\n"
          "         whitted:      [--mirror NAME,..|all] [--glass NAME,..] [--depth N]\n"
          "  trace  SCENE RAYS --query closest|any --out FILE [--tracer frusta|embree]\n"
          "         [--mode single|packet8|packet16|hybrid16|auto|raystream]\n"
          "  stats  SCENE|--builtin [--embree] [--workload W [--threshold N] [--coherent-threshold N] [--packet-width 4|8]]\n"
          "Scenes: PLY, OBJ(+MTL) and what Assimp reads, optionally .zst. FRUSTA_ISA=avx512|avx2|scalar forces an ISA.\n");
}

int main(int argc, char **argv) {
  if (argc < 2) return cli_error(CLI_USAGE_ERROR, "no command given (render, bench, trace or stats; see frusta --help)");
  const char *cmd = argv[1];
  if (strcmp(cmd, "-h") == 0 || strcmp(cmd, "--help") == 0 || strcmp(cmd, "help") == 0) { usage(stdout); return 0; }
  const char *isa = getenv("FRUSTA_ISA");
  if (isa && *isa && cli_set_isa(isa) != 0) return 1;
  if (strcmp(cmd, "render") == 0) return cmd_render(argc - 2, argv + 2);
  if (strcmp(cmd, "bench") == 0) return cmd_bench(argc - 2, argv + 2);
  if (strcmp(cmd, "trace") == 0) return cmd_trace(argc - 2, argv + 2);
  if (strcmp(cmd, "stats") == 0) return cmd_stats(argc - 2, argv + 2);
  return cli_error(CLI_USAGE_ERROR, "unknown command '%s' (render, bench, trace or stats)", cmd);
}
