#!/usr/bin/env bash
# How soon the viewer answers input while heavy frames render: `frusta
# view` in a window (Xvfb), 2 threads, 1024x768, each case's scene and
# mode; once it renders, KEYS presses of W (fly forward, held 0.1 s) half
# a second apart, then Escape. The viewer prints how long each change took from
# the key to the start of the new view's pass (the pass under way
# abandoned). Raw lines go to bench/results/view_latency.txt (commit and
# command at the top), a markdown table to stdout.
# usage: bench/view_latency.sh [KEYS]
set -euo pipefail
cd "$(dirname "$0")/.."
KEYS=${1:-10}
RAW=bench/results/view_latency.txt
F=${FRUSTA:-./build/frusta}
S=../shared/scenes
T=$(mktemp -d)
. bench/display.sh
with_display "$T" always
mkdir -p bench/results
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tools include || echo '+changes')"
  echo "# bench/view_latency.sh $KEYS"
} >"$RAW"
echo "| scene | shade | answered, median (ms) | answered, at most (ms) |"
echo "|---|---|---|---|"
for c in "kitchen path" "kitchen ao" "kitchen softshadow" "conference whitted"; do
  set -- $c
  "$F" view "$S/$1/$1.ply.zst" --shade "$2" --threads 2 >"$T/out" 2>&1 &
  VP=$!
  sleep 4
  X="xdotool search --sync --name frusta"
  for _ in $(seq "$KEYS"); do
    $X keydown w >/dev/null 2>&1 || true; sleep 0.1; $X keyup w >/dev/null 2>&1 || true; sleep 0.4
  done
  $X key Escape >/dev/null 2>&1 || true
  wait $VP || true
  line=$(grep '^view: ' "$T/out" || echo "view: no change answered")
  { echo "## $c"; echo "$line"; } >>"$RAW"
  med=$(echo "$line" | sed 's/.* in \([0-9.]*\) ms median.*/\1/')
  max=$(echo "$line" | sed 's/.*, \([0-9.]*\) ms at most.*/\1/')
  echo "| $1 | $2 | $med | $max |"
done
