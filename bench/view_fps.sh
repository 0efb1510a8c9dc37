#!/usr/bin/env bash
# The viewer's frame rates: `frusta view --frames` along a turntable (the
# camera turns every frame, so every frame renders afresh), 2 threads,
# 1024x768, the scenes' own views; each frame's time is its whole cost
# (passes, resolve, denoiser, screen pixels, presenting). Starts its own
# Xvfb when there is no DISPLAY. Raw lines go to
# bench/results/view_fps.txt (commit and command at the top), a markdown
# table to stdout.
# usage: bench/view_fps.sh [FRAMES]
set -euo pipefail
cd "$(dirname "$0")/.."
FRAMES=${1:-30}
RAW=bench/results/view_fps.txt
F=${FRUSTA:-./build/frusta}
S=../shared/scenes
. bench/display.sh
with_display "$(mktemp -d)"
mkdir -p bench/results
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tools include || echo '+changes')"
  echo "# bench/view_fps.sh $FRAMES"
} >"$RAW"
echo "| scene | shade | target | frames/s | render ms | denoise ms |"
echo "|---|---|---|---|---|---|"
run() { # LABEL TARGET SCENE [flags]
  local label=$1 target=$2 scene=$3; shift 3
  "$F" view "$scene" --size 1024x768 --threads 2 --frames "$FRAMES" --turntable 0.5 "$@" >"$RAW.tmp"
  grep -E '^(frame|view) ' "$RAW.tmp" | sed "s/^/case=${label// /} /" >>"$RAW"
  # the first frame builds caches and sets up materials: the rest are timed
  awk -v label="$label" -v target="$target" '
    /^frame / { if ($2 != "0:") { n++; t += $3; r += $6; d += $9 } }
    END { printf "| %s | %s | %.1f | %.1f | %.2f |\n", label, target, 1000 * n / t, r / n, d / n }' "$RAW.tmp"
  rm -f "$RAW.tmp"
}
run "conference | eyelight" ">= 60" "$S/conference/conference.ply.zst" --shade eyelight
run "kitchen | softshadow, 16 samples, filter" ">= 12" "$S/kitchen/kitchen.ply.zst" --shade softshadow --denoise off
run "kitchen | whitted" ">= 30" "$S/kitchen/kitchen.ply.zst" --shade whitted
# path: the kitchen with its MTL materials (kitchen.obj.zst), as the path
# tracer's own benchmarks take it; the PLY is its geometry alone, every
# surface the default white Lambert, whose paths run three times as long
run "kitchen | path, 1 spp, denoiser" ">= 3" "$S/kitchen/kitchen.obj.zst" --shade path
run "kitchen | path, 1 spp, 4 segments, denoiser" "" "$S/kitchen/kitchen.obj.zst" --shade path --max-depth 4
run "kitchen, geometry only (PLY) | path, 1 spp, denoiser" "" "$S/kitchen/kitchen.ply.zst" --shade path
run "kitchen | ao, 16 rays, denoiser" "" "$S/kitchen/kitchen.ply.zst" --shade ao
