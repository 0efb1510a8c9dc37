#!/usr/bin/env bash
# Build time, SAH and memory, frusta against Embree: `frusta stats
# SCENE --embree` K times per scene at 2 threads (this VM's speed drifts
# between runs, so the table takes each builder's fastest run). Raw lines go
# to bench/results/build-vs-embree.txt, a markdown table to stdout.
# usage: bench/build_table.sh [K] [SCENES...]
set -euo pipefail
cd "$(dirname "$0")/.."
K=${1:-5}; shift || true
SCENES=${*:-conference kitchen dragon hairball}
mkdir -p bench/results
RAW=bench/results/build-vs-embree.txt
printf "# commit %s\n# %s\n" "$(git rev-parse --short HEAD)" "bench/$(basename "$0") $*" >"$RAW"
for s in $SCENES; do
  for _ in $(seq "$K"); do
    ./build/frusta stats "../shared/scenes/$s/$s.ply.zst" --threads 2 --embree >>"$RAW"
  done
done
awk '
  function kv(line,   n, f, i, p) { delete v; n = split(line, f, " "); for (i = 1; i <= n; i++) { split(f[i], p, "="); v[p[1]] = p[2] } }
  /^scene=/ { kv($0); s = v["scene"]; if (!(s in fb) || v["build_seconds"] + 0 < fb[s]) fb[s] = v["build_seconds"] + 0
              if (!(s in seen)) { seen[s] = 1; order[++ns] = s } }
  /^bvh8 / { kv($0); fm[s] = v["bytes_per_tri"] }
  /^embree_builder width=4 quality=high/ { split($NF, p, "="); sah[s] = p[2] } # the last field: frusta / Embree
  /^embree_tree accel/ { split($NF, p, "="); tree[s] = p[2] } # frusta BVH8 / the BVH8 Embree traces
  /^embree_scene/ { kv($0); if (!(s in eb) || v["build_seconds"] + 0 < eb[s]) eb[s] = v["build_seconds"] + 0; em[s] = v["bytes_per_tri"] }
  END {
    print "| scene | frusta commit s (BVH2, multi-frusta cut, BVH8) | Embree commit s (high quality) | frusta / Embree | frusta BVH4 SAH / Embree high-quality BVH4 SAH (leaf blocks) | frusta BVH8 SAH / SAH of the BVH8 Embree traces | frusta bytes/tri (BVH8 + triangles) | Embree bytes/tri |"
    print "|---|---:|---:|---:|---:|---:|---:|---:|"
    for (i = 1; i <= ns; i++) { s = order[i]
      printf "| %s | %.3f | %.3f | %.2f | %s | %s | %s | %s |\n", s, fb[s], eb[s], fb[s] / eb[s], sah[s], tree[s], fm[s], em[s] }
  }' "$RAW"
