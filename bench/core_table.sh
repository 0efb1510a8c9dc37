#!/usr/bin/env bash
# The core benchmark table (issue 2): frusta and Embree side by side, one run
# per scene, every workload, every mode, 2 threads. Prints the raw lines to
# bench/results/core-raw.txt and a markdown table on stdout.
# usage: bench/core_table.sh [SIZE] [REPEAT] [SCENES...]
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${1:-1024x1024}; REPEAT=${2:-3}; shift 2 || true
SCENES=${*:-conference/conference kitchen/kitchen dragon/dragon hairball/hairball}
mkdir -p bench/results
RAW=bench/results/core-raw.txt
: >"$RAW"
for s in $SCENES; do
  ./build/frusta bench "../shared/scenes/$s.ply.zst" --workload all --mode all --tracer both \
    --threads 2 --size "$SIZE" --repeat "$REPEAT" >>"$RAW"
done
awk '
  /^build_seconds=/ { split($0, f, " "); for (i in f) { split(f[i], kv, "="); v[kv[1]] = kv[2] }
                      b[v["scene"] "," v["tracer"]] = v["build_seconds"]; m[v["scene"] "," v["tracer"]] = v["bytes_per_tri"] }
  /^scene=/ { delete v; n = split($0, f, " "); for (i = 1; i <= n; i++) { split(f[i], kv, "="); v[kv[1]] = kv[2] }
              key = v["scene"] "," v["workload"]; r = v["mrays"] + 0
              if (!(key in seen)) { seen[key] = 1; order[++nk] = key }
              if (v["tracer"] == "frusta" && v["mode"] == "single") fs[key] = r
              if (v["tracer"] == "frusta" && v["mode"] == "single4") f4[key] = r
              if (v["tracer"] == "embree" && v["mode"] == "single") es[key] = r
              if (v["tracer"] == "embree" && r > eb[key]) { eb[key] = r; ebm[key] = v["mode"] } }
  END {
    print "| scene | workload | frusta single (BVH8) | frusta single4 (BVH4) | Embree single | frusta / Embree single | Embree best (mode) | frusta best / Embree best |"
    print "|---|---|---:|---:|---:|---:|---:|---:|"
    for (i = 1; i <= nk; i++) { k = order[i]; split(k, p, ",")
      best = fs[k] > f4[k] ? fs[k] : f4[k]
      printf "| %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f (%s) | %.2f |\n", p[1], p[2], fs[k], f4[k], es[k], fs[k] / es[k], eb[k], ebm[k], best / eb[k] }
    print ""
    print "| scene | frusta build s | Embree build s (high quality) | frusta bytes/tri (BVH8 + triangles) | Embree bytes/tri |"
    print "|---|---:|---:|---:|---:|"
    for (k in b) { split(k, p, ","); if (p[2] == "frusta") sc[p[1]] = 1 }
    for (s in sc) printf "| %s | %s | %s | %s | %s |\n", s, b[s ",frusta"], b[s ",embree"], m[s ",frusta"], m[s ",embree"]
  }' "$RAW"
