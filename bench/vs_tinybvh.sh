#!/usr/bin/env bash
# frusta's single rays against tinybvh's BVH8_CPU (Bikker), the fastest
# single-ray CPU tracer, on identical rays (bench/vs_tinybvh.c): camera,
# shadow, ao and diffuse rays on conference, dragon and hairball, 2
# threads; tinybvh's BVH from its high-quality build, and from its quick
# build refined by 50 rounds of its optimizer, as its speed test makes
# them. tinybvh is not a Debian package: point TINYBVH at a checkout
# (https://github.com/jbikker/tinybvh); it is compiled here for the
# comparison only. Needs build/libfrusta.a (bash scripts/setup.sh). Raw
# lines go to bench/results/vs-tinybvh.txt (commit and command at the top).
# usage: TINYBVH=DIR bash bench/vs_tinybvh.sh [REPEAT]
set -euo pipefail
cd "$(dirname "$0")/.."
: "${TINYBVH:?set TINYBVH to a tinybvh checkout (https://github.com/jbikker/tinybvh)}"
REPEAT=${1:-5}
RAW=bench/results/vs-tinybvh.txt
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
# tinybvh at its best on this CPU (its BVH8_CPU needs AVX2 and FMA); frusta
# picks its ISA at run time
g++ -O3 -march=native -fopenmp -I"$TINYBVH" -c bench/tinybvh_side.cpp -o "$T/tinybvh_side.o"
gcc -O3 -std=c11 -D_DEFAULT_SOURCE -fopenmp -Iinclude -Isrc -c bench/vs_tinybvh.c -o "$T/vs_tinybvh.o"
g++ -fopenmp "$T/vs_tinybvh.o" "$T/tinybvh_side.o" build/libfrusta.a \
  $(pkg-config --libs libzstd assimp OpenEXR libcjson) -lstb -lm -o "$T/vs_tinybvh"
mkdir -p bench/results
{
  v=$(awk '/define TINY_BVH_VERSION_(MAJOR|MINOR|SUB)/ { printf "%s%s", sep, $3; sep = "." }' "$TINYBVH/tiny_bvh.h")
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src include || echo '+changes') tinybvh $v"
  echo "# TINYBVH=DIR bash bench/vs_tinybvh.sh $REPEAT"
} >"$RAW"
for s in conference dragon hairball; do
  for optimize in 0 50; do
    "$T/vs_tinybvh" "../shared/scenes/$s/$s.ply.zst" "$REPEAT" "$optimize" | tee -a "$RAW"
  done
done
