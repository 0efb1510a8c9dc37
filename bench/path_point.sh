#!/usr/bin/env bash
# The path tracer under a point light, direct light only (one segment), as
# streams (auto) and with the camera hits' shadow rays as multi-frusta (mft),
# beside Embree at its best; kitchen, conference, sibenik.
# usage: bench/path_point.sh [SIZE] [SPP]   (raw lines: bench/results/path-point.txt)
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${1:-512x512}
SPP=${2:-8}
RAW=bench/results/path-point.txt
F=${FRUSTA:-./build/frusta}
mkdir -p bench/results
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tools include || echo '+changes')"
  echo "# bench/path_point.sh $SIZE $SPP"
} >"$RAW"
for scene in kitchen/kitchen.obj.zst conference/conference.ply.zst sibenik/sibenik.ply.zst; do
  "$F" bench "../shared/scenes/$scene" --workload path --tracer both --mode auto,mft,packet8,packet16,stream \
    --threads 2 --size "$SIZE" --spp "$SPP" --max-depth 1 --lights point --repeat 5 | grep -E '^(scene|stages)' >>"$RAW"
done
cat "$RAW"
