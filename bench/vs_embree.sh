#!/usr/bin/env bash
# The main performance table: on every scene and workload, frusta's fastest
# mode against Embree's fastest mode at its best (for each Embree mode the
# faster context flag and packing, chosen by measurement inside the run;
# high-quality build), interleaved repetitions in one process, 2 threads.
# Primary, shadow and soft16 at 1024x1024; ao16, diffuse8 and specular8 at
# 512x512. Raw lines go to bench/results/vs-embree.txt (commit and command
# at the top); the markdown table goes to stdout.
# usage: bench/vs_embree.sh [REPEAT] [SCENES...]
set -euo pipefail
cd "$(dirname "$0")/.."
REPEAT=${1:-4}; shift || true
SCENES=${*:-conference kitchen sibenik dragon hairball}
RAW=bench/results/vs-embree.txt
FRUSTA_MODES=single,packet16,hybrid16,auto,mft,raystream
EMBREE_MODES=single,packet4,packet8,packet16,stream
mkdir -p bench/results
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tools include || echo '+changes')"
  echo "# bench/vs_embree.sh $REPEAT $SCENES"
} >"$RAW"
for s in $SCENES; do
  for wl in primary shadow soft16 ao16 diffuse8 specular8; do
    case $wl in primary|shadow|soft16) size=1024x1024 ;; *) size=512x512 ;; esac
    ${FRUSTA:-./build/frusta} bench "../shared/scenes/$s/$s.ply.zst" --workload "$wl" --tracer both \
      --mode "$FRUSTA_MODES,$EMBREE_MODES" --threads 2 --size "$size" --repeat "$REPEAT" | grep '^scene=' >>"$RAW"
  done
done
bash bench/vs_embree_table.sh "$RAW"
