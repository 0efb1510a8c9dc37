#!/usr/bin/env bash
# The MIC paper's Table VIII made again: the path tracer (16 paths per
# pixel, paths of up to 13 segments, 2 threads; 512x512 by default,
# 1024x1024 as the paper's with SIZE) in frames per second for frusta's
# single, packet16, hybrid16, auto and raystream modes,
# and the same path tracer on Embree at its best (its modes, each with the
# faster context flag and packing chosen in the run), on an interior
# (kitchen, its MTL materials mapped, the scene's lamp) and the exterior
# material showcase, under constant ambient light (a white sky) and under
# an importance-sampled HDRI; plus conference and hairball under the white
# sky and their lamps. Raw lines go to bench/results/path.txt (commit and
# command at the top), the markdown table to stdout.
# usage: bench/path_table.sh [SIZE] [SPP]
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${1:-512x512}
SPP=${2:-16}
RAW=bench/results/path.txt
F=${FRUSTA:-./build/frusta}
MODES=single,packet16,hybrid16,auto,raystream,packet8,packet16,stream
HDRI=../shared/hdri/courtyard.exr
mkdir -p bench/results
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tools include || echo '+changes')"
  echo "# bench/path_table.sh $SIZE $SPP"
} >"$RAW"
run() { # run LABEL LIGHTING SCENE [flags]
  local label=$1 light=$2 scene=$3; shift 3
  "$F" bench "$scene" --workload path --tracer both --mode "$MODES" --threads 2 --size "$SIZE" --spp "$SPP" \
    --max-depth 13 --repeat 1 "$@" | grep -E '^(scene|stages)' | sed "s/^/case=$label light=$light /" >>"$RAW"
}
run kitchen ambient ../shared/scenes/kitchen/kitchen.obj.zst --env-color 1,1,1 --lights env,area
run kitchen hdri ../shared/scenes/kitchen/kitchen.obj.zst --env "$HDRI" --lights env,area
run showcase ambient --builtin=materials --env-color 1,1,1 --lights env
run showcase hdri --builtin=materials --env "$HDRI" --lights env
run conference ambient ../shared/scenes/conference/conference.ply.zst --env-color 1,1,1 --lights env,area
run hairball ambient ../shared/scenes/hairball/hairball.ply.zst --env-color 1,1,1 --lights env,area
bash bench/path_table_md.sh "$RAW"
