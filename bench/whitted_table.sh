#!/usr/bin/env bash
# The Whitted benchmark: large packets of 2x2 .. 32x32 rays with
# each traversal (masked, ranged, partition), the culls (off, ia, planes,
# corners) at 2x2 and 16x16, frusta's hybrid16, auto and mft, and Embree's modes,
# all on the same Whitted rays, 2 threads, 1024x1024. kitchen and museum
# with their MTL mirrors and glass, spd_rings with every surface a mirror,
# and the analytic sphereflake (--builtin=sphereflake: 820 mirror spheres).
# Raw lines go to bench/results/whitted-vs-embree.txt; with a counters build in
# build-count/ the packet counters go to bench/results/whitted-counters.txt.
# env: SIZE (1024x1024) REPEAT (3) THREADS (2) SCENES ("kitchen museum
# spd_rings sphereflake") RAW COUNT (the output files)
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${SIZE:-1024x1024}; REPEAT=${REPEAT:-3}; THREADS=${THREADS:-2}
SCENES=${SCENES:-kitchen museum spd_rings sphereflake}
RAW=${RAW:-bench/results/whitted-vs-embree.txt}
COUNT=${COUNT:-bench/results/whitted-counters.txt}
scene_file() {
  case $1 in
  kitchen|museum) echo "../shared/scenes/$1/$1.obj.zst" ;;
  spd_rings) echo "../shared/scenes/spd_rings/rings.ply.zst" ;;
  sphereflake) echo "--builtin=sphereflake" ;;
  esac
}
scene_args() { case $1 in spd_rings) echo "--mirror all" ;; *) echo "" ;; esac; }
bench() { # binary scene args...
  local bin=$1 s=$2; shift 2
  # shellcheck disable=SC2046
  "$bin" bench "$(scene_file "$s")" --workload whitted --threads "$THREADS" --size "$SIZE" --repeat "$REPEAT" \
    $(scene_args "$s") "$@" | grep -E '^(scene=|counters|whitted)'
}
mkdir -p bench/results
printf "# commit %s\n# %s\n" "$(git rev-parse --short HEAD)" "bench/$(basename "$0") $*" >"$RAW"
[ -x build-count/frusta ] && : >"$COUNT"
for s in $SCENES; do
  bench ./build/frusta "$s" --mode hybrid16 --tracer both >>"$RAW"
  bench ./build/frusta "$s" --mode all --tracer embree >>"$RAW"
  bench ./build/frusta "$s" --mode auto >>"$RAW"
  # camera rays as multi-frusta, the rest as auto (no spheres in frusta)
  if [ "$s" != sphereflake ]; then bench ./build/frusta "$s" --mode mft >>"$RAW"; fi
  for n in 2 4 8 16 32; do
    for t in masked ranged partition; do
      bench ./build/frusta "$s" --mode "packet${n}x${n}" --traversal "$t" --cull off >>"$RAW"
    done
  done
  for n in 2 16; do
    for c in ia planes corners; do
      bench ./build/frusta "$s" --mode "packet${n}x${n}" --traversal ranged --cull "$c" >>"$RAW"
      if [ -x build-count/frusta ]; then
        REPEAT=1 bench ./build-count/frusta "$s" --mode "packet${n}x${n}" --traversal ranged --cull "$c" | grep counters >>"$COUNT"
      fi
    done
    [ -x build-count/frusta ] && REPEAT=1 bench ./build-count/frusta "$s" --mode "packet${n}x${n}" --traversal ranged --cull off | grep counters >>"$COUNT"
  done
done
echo "wrote $RAW"
