#!/usr/bin/env bash
# Frames across processes on one machine: `frusta render` at 1024x1024 on
# 2 ranks of 1 thread (mpirun) against 1 rank of 2 threads, for soft
# shadows, Whitted and path tracing on kitchen and conference. Each
# render's own time (its frame: tiles dealt, traced, pixels gathered on
# rank 0; not the scene's load and build), the best of REPEAT runs taken
# alternately; then bytes sent per frame, and the tiles' render times from
# `frusta bench` (one process, one thread). Raw lines go to
# bench/results/cluster_scaling.txt (commit and command at the top), a
# markdown table to stdout.
# usage: bench/cluster_scaling.sh [REPEAT]
set -euo pipefail
cd "$(dirname "$0")/.."
REPEAT=${1:-3}
RAW=bench/results/cluster_scaling.txt
F=${FRUSTA:-./build/frusta}
S=../shared/scenes
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
mkdir -p bench/results
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tools include || echo '+changes')"
  echo "# bench/cluster_scaling.sh $REPEAT"
} >"$RAW"
secs() { sed -n 's/.* seconds=\([0-9.]*\) .*/\1/p' "$1" | head -1; }
best() { printf '%s\n' "$@" | sort -g | head -1; }
echo "| scene | shade | 1 rank x 2 threads (s) | 2 ranks x 1 thread (s) | efficiency | bytes to rank 0 per frame |"
echo "|---|---|---|---|---|---|"
for scene in kitchen conference; do
  P="$S/$scene/$scene.ply.zst"
  for shade in softshadow whitted path; do
    args="--shade $shade --size 1024x1024"
    [ "$shade" = path ] && args="$args --spp 4"
    one=(); two=()
    for _ in $(seq "$REPEAT"); do
      "$F" render "$P" $args --threads 2 --out "$T/one.exr" >"$T/one.txt" 2>/dev/null
      mpirun --oversubscribe -np 2 "$F" render "$P" $args --threads 1 --out "$T/two.exr" >"$T/two.txt" 2>/dev/null
      cmp -s "$T/one.exr" "$T/two.exr" || { echo "$scene $shade: the images differ" >&2; exit 1; }
      one+=("$(secs "$T/one.txt")"); two+=("$(secs "$T/two.txt")")
      { echo "## $scene $shade 1x2"; cat "$T/one.txt"; echo "## $scene $shade 2x1"; cat "$T/two.txt"; } >>"$RAW"
    done
    b1=$(best "${one[@]}"); b2=$(best "${two[@]}")
    bytes=$(sed -n 's/.*bytes_sent=\([0-9]*\).*/\1/p' "$T/two.txt")
    eff=$(awk -v a="$b1" -v b="$b2" 'BEGIN { printf "%.0f%%", 100 * a / b }')
    echo "| $scene | $shade | $b1 | $b2 | $eff | $bytes |"
  done
  # the tiles' times: one thread, the frame's cost per tile and its spread
  echo "## $scene tiles, 1 thread" >>"$RAW"
  "$F" bench "$P" --workload soft16,whitted,path --mode mft --size 1024x1024 --spp 4 --threads 1 --repeat 1 2>/dev/null |
    grep '^tiles\|^scene' >>"$RAW"
done
