#!/usr/bin/env bash
# The denoiser alone on the viewer's frame (bench/denoise_time.c): kitchen
# with its materials at 1 spp, 1024x768, 2 threads, 20 calls on one
# denoiser; best and median. Needs build/libfrusta.a (bash
# scripts/setup.sh). Raw lines go to bench/results/denoise_time.txt
# (commit and command at the top).
# usage: bench/denoise_time.sh [REPEAT]
set -euo pipefail
cd "$(dirname "$0")/.."
REPEAT=${1:-20}
RAW=bench/results/denoise_time.txt
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
gcc -O2 -std=c11 -D_DEFAULT_SOURCE -fopenmp -Iinclude -Isrc bench/denoise_time.c build/libfrusta.a \
  $(pkg-config --libs libzstd assimp OpenEXR libcjson) -lstb -lstdc++ -lm -o "$T/denoise_time"
mkdir -p bench/results
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src include || echo '+changes')"
  echo "# bash bench/denoise_time.sh $REPEAT"
} >"$RAW"
"$T/denoise_time" ../shared/scenes/kitchen/kitchen.obj.zst 1024 768 "$REPEAT" | tee -a "$RAW"
