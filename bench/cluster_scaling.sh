#!/usr/bin/env bash
# Frames across processes on one machine: 2 ranks of 1 thread (mpirun)
# against 1 rank of 2 threads, kitchen and conference at 1024x1024.
#  - bench: the soft16, whitted and path workloads' frames (rays traced
#    and shaded, tiles dealt; no pixels gathered), best of REPEAT;
#  - render: the command's whole frame (tiles dealt, pixels gathered on
#    rank 0, then rank 0's filter and shading), best of REPEAT, alternating,
#    the images compared byte for byte; and the bytes sent to rank 0;
#  - the tiles' render times on one thread (bench), for the model of
#    docs/scaling.md.
# Raw lines go to bench/results/cluster_scaling.txt (commit and command at
# the top), markdown tables to stdout.
# usage: bench/cluster_scaling.sh [REPEAT]
set -euo pipefail
cd "$(dirname "$0")/.."
REPEAT=${1:-3}
RAW=bench/results/cluster_scaling.txt
F=${FRUSTA:-./build/frusta}
S=../shared/scenes
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
MPI="mpirun --oversubscribe -np 2"
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
mkdir -p bench/results
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tools include || echo '+changes')"
  echo "# bench/cluster_scaling.sh $REPEAT"
} >"$RAW"
best() { printf '%s\n' "$@" | sort -g | head -1; }
eff() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.0f%%", 100 * a / b }'; }
bench_secs() { grep "^scene=.*workload=$2 " "$1" | sed 's/.* seconds=\([0-9.]*\) .*/\1/'; }

echo "bench workloads (frames of rays, no pixels gathered):"
echo
echo "| scene | workload | 1 rank x 2 threads (s) | 2 ranks x 1 thread (s) | efficiency |"
echo "|---|---|---|---|---|"
for scene in kitchen conference; do
  P="$S/$scene/$scene.ply.zst"
  B1="--workload soft16,whitted --mode mft --size 1024x1024 --repeat $REPEAT"
  B2="--workload path --mode auto --size 1024x1024 --spp 4 --repeat $REPEAT"
  "$F" bench "$P" $B1 --threads 2 >"$T/a1" 2>/dev/null; $MPI "$F" bench "$P" $B1 --threads 1 >"$T/a2" 2>/dev/null
  "$F" bench "$P" $B2 --threads 2 >>"$T/a1" 2>/dev/null; $MPI "$F" bench "$P" $B2 --threads 1 >>"$T/a2" 2>/dev/null
  { echo "## $scene bench 1x2"; cat "$T/a1"; echo "## $scene bench 2x1"; cat "$T/a2"; } >>"$RAW"
  for wl in soft16 whitted path; do
    s1=$(bench_secs "$T/a1" $wl); s2=$(bench_secs "$T/a2" $wl)
    echo "| $scene | $wl | $s1 | $s2 | $(eff "$s1" "$s2") |"
  done
done

echo
echo "render (the whole frame: pixels gathered, then rank 0's post-processing):"
echo
echo "| scene | shade | 1 rank x 2 threads (s) | 2 ranks x 1 thread (s) | efficiency | bytes to rank 0 |"
echo "|---|---|---|---|---|---|"
secs() { sed -n 's/.* seconds=\([0-9.]*\) .*/\1/p' "$1" | head -1; }
for scene in kitchen conference; do
  P="$S/$scene/$scene.ply.zst"
  for shade in softshadow whitted path; do
    args="--shade $shade --size 1024x1024"
    [ "$shade" = path ] && args="$args --spp 4"
    one=(); two=()
    for _ in $(seq "$REPEAT"); do
      "$F" render "$P" $args --threads 2 --out "$T/one.exr" >"$T/one.txt" 2>/dev/null
      $MPI "$F" render "$P" $args --threads 1 --out "$T/two.exr" >"$T/two.txt" 2>/dev/null
      cmp -s "$T/one.exr" "$T/two.exr" || { echo "$scene $shade: the images differ" >&2; exit 1; }
      one+=("$(secs "$T/one.txt")"); two+=("$(secs "$T/two.txt")")
      { echo "## $scene render $shade 1x2"; cat "$T/one.txt"; echo "## $scene render $shade 2x1"; cat "$T/two.txt"; } >>"$RAW"
    done
    b1=$(best "${one[@]}"); b2=$(best "${two[@]}")
    bytes=$(sed -n 's/.*bytes_sent=\([0-9]*\).*/\1/p' "$T/two.txt")
    echo "| $scene | $shade | $b1 | $b2 | $(eff "$b1" "$b2") | $bytes |"
  done
  echo "## $scene render softshadow 1x1" >>"$RAW" # rank 0's post-processing, one thread: this less the bench frame
  "$F" render "$P" --shade softshadow --size 1024x1024 --threads 1 --out "$T/one.exr" 2>/dev/null >>"$RAW"
  echo "## $scene tiles, 1 thread" >>"$RAW"
  "$F" bench "$P" --workload soft16,whitted --mode mft --size 1024x1024 --threads 1 --repeat 1 2>/dev/null | grep '^tiles\|^scene' >>"$RAW"
  "$F" bench "$P" --workload path --mode auto --size 1024x1024 --spp 4 --threads 1 --repeat 1 2>/dev/null | grep '^tiles\|^scene' >>"$RAW"
done
