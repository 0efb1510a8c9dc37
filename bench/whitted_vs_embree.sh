#!/usr/bin/env bash
# Whitted frames, frusta against Embree at its best: kitchen and museum with
# their MTL mirrors and glass, every mode of both tracers on the same rays,
# 2 threads, 1024x1024, interleaved repetitions in one process. Raw lines go
# to bench/results/whitted-vs-embree.txt (commit and command at the top), the
# markdown table to stdout.
# usage: bench/whitted_vs_embree.sh [REPEAT] [SCENES...]
set -euo pipefail
cd "$(dirname "$0")/.."
REPEAT=${1:-4}; shift || true
SCENES=${*:-kitchen museum}
RAW=bench/results/whitted-vs-embree.txt
mkdir -p bench/results
printf "# commit %s\n# bench/whitted_vs_embree.sh %s %s\n" "$(git rev-parse --short HEAD)" "$REPEAT" "$SCENES" >"$RAW"
for s in $SCENES; do
  ${FRUSTA:-./build/frusta} bench "../shared/scenes/$s/$s.obj.zst" --workload whitted --tracer both \
    --mode mft,hybrid16,auto,packet16x16,single,packet4,packet8,packet16,stream \
    --threads 2 --size 1024x1024 --repeat "$REPEAT" | grep '^scene=' >>"$RAW"
done
awk '
  /^scene=/ { delete v; for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
    s = v["scene"]; r = v["mrays"] + 0
    if (!(s in seen)) { seen[s] = 1; order[++n] = s }
    if (v["tracer"] == "frusta" && r > f[s]) { f[s] = r; fm[s] = v["mode"] }
    if (v["tracer"] == "embree" && r > e[s]) { e[s] = r; em[s] = v["mode"] " " v["flag"] " " v["packing"] } }
  END {
    print "| scene | frusta best (mode) | Embree best (mode, flag, packing) | frusta / Embree |"
    print "|---|---:|---:|---:|"
    for (i = 1; i <= n; i++) { s = order[i]
      printf "| %s | %.1f (%s) | %.1f (%s) | %.2f |\n", s, f[s], fm[s], e[s], em[s], f[s] / e[s] } }' "$RAW"
