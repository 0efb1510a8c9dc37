#!/usr/bin/env bash
# The multi-frusta benchmark: mft next to frusta's packet modes and
# Embree's modes, one process per scene and workload, 2 threads, 1024x1024;
# soft16 with the light's samples dealt out "spread" (the workload's per-pixel
# stratification) and by "cells" (the paper's narrow frusta); shallow BVHs
# (leaves of 8 and 12); shrinking off. Raw lines go to bench/results/mft-vs-embree.txt.
# With a counters build in build-count/ (cmake -DFRUSTA_COUNTERS=ON) it also
# records the counters for the paper's Table 1 in bench/results/mft-table1-counters.txt.
# Table 1's multi-frusta rows trace every ray as frusta (--mft-fallback off)
# and cull every triangle with the corner rays (--corner-cost 0), as the
# paper's do.
# env: SIZE (1024x1024) REPEAT (3) THREADS (2) SCENES ("conference kitchen sibenik dragon")
#      COUNTERS_ONLY=1: only the counters
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${SIZE:-1024x1024}; REPEAT=${REPEAT:-3}; THREADS=${THREADS:-2}
SCENES=${SCENES:-conference kitchen sibenik dragon}
RAW=bench/results/mft-vs-embree.txt
bench() { # binary tag scene args...
  local bin=$1 tag=$2 s=$3; shift 3
  "$bin" bench "../shared/scenes/$s/$s.ply.zst" --threads "$THREADS" --size "$SIZE" --repeat "$REPEAT" "$@" |
    grep -E '^(scene=|counters|mft_bvh)' | sed "s/^/$tag /"
}
mkdir -p bench/results
[ "${COUNTERS_ONLY:-0}" = 1 ] || printf "# commit %s\n# %s\n" "$(git rev-parse --short HEAD)" "bench/$(basename "$0") $*" >"$RAW"
for s in $SCENES; do
  [ "${COUNTERS_ONLY:-0}" = 1 ] && break
  bench ./build/frusta main "$s" --workload primary --mode all --tracer both >>"$RAW"
  for ls in spread cells; do
    bench ./build/frusta "main sets=$ls" "$s" --workload soft16 --mode all --tracer both --light-sets "$ls" >>"$RAW"
    bench ./build/frusta "noshrink sets=$ls" "$s" --workload soft16 --mode mft --shrink off --light-sets "$ls" >>"$RAW"
    for leaf in 8 12; do
      bench ./build/frusta "leaf=$leaf sets=$ls" "$s" --workload soft16 --mode mft --mft-leaf "$leaf" --light-sets "$ls" >>"$RAW"
    done
  done
  for leaf in 8 12; do bench ./build/frusta "leaf=$leaf" "$s" --workload primary --mode mft --mft-leaf "$leaf" >>"$RAW"; done
done
if [ -x build-count/frusta ]; then
  CNT=bench/results/mft-table1-counters.txt
  printf "# commit %s\n# COUNTERS_ONLY=1 bench/%s\n" "$(git rev-parse --short HEAD)" "$(basename "$0")" >"$CNT"
  for s in $SCENES; do
    for m in mft packet16; do
      cc=(); [ "$m" = mft ] && cc=(--corner-cost 0)
      REPEAT=1 bench ./build-count/frusta "$m" "$s" --workload primary --mode "$m" "${cc[@]}" >>"$CNT"
      fb=(); [ "$m" = mft ] && fb=(--mft-fallback off --corner-cost 0)
      for ls in spread cells; do
        REPEAT=1 bench ./build-count/frusta "$m sets=$ls" "$s" --workload soft16 --mode "$m" --light-sets "$ls" "${fb[@]}" >>"$CNT"
      done
    done
  done
fi
[ "${COUNTERS_ONLY:-0}" = 1 ] || echo "raw lines in $RAW"
