#!/usr/bin/env bash
# The markdown table of bench/vs_embree.sh from its raw lines: per scene and
# workload, frusta's best mode against Embree's best mode (Mrays/s, best of
# the repetitions), the ratio, and ** where frusta is behind. With --modes:
# Mrays/s of every mode, each tracer's fastest in bold.
# usage: bench/vs_embree_table.sh [--modes] [bench/results/vs-embree.txt]
set -euo pipefail
if [ "${1:-}" = --modes ]; then
  shift
  awk '
    /^scene=/ { delete v; for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
      if (!(v["scene"] in sseen)) { sseen[v["scene"]] = 1; scenes[++ns] = v["scene"] }
      k = v["scene"] SUBSEP v["workload"] SUBSEP v["tracer"] SUBSEP v["mode"]
      if (v["mrays"] + 0 > r[k]) r[k] = v["mrays"] + 0 }
    END {
      nw = split("primary shadow soft16 ao16 diffuse8 specular8", wl, " ")
      nf = split("single packet16 hybrid16 auto mft raystream", fmode, " ")
      ne = split("single packet4 packet8 packet16 stream", emode, " ")
      printf "| scene | workload |"; for (j = 1; j <= nf; j++) printf " %s |", fmode[j]
      for (j = 1; j <= ne; j++) printf " Embree %s |", emode[j]
      printf "\n|---|---|"; for (j = 1; j <= nf + ne; j++) printf "---:|"; printf "\n"
      for (i = 1; i <= ns; i++) for (w = 1; w <= nw; w++) {
        bf = 0; be = 0
        for (j = 1; j <= nf; j++) { x = r[scenes[i] SUBSEP wl[w] SUBSEP "frusta" SUBSEP fmode[j]]; if (x > bf) bf = x }
        for (j = 1; j <= ne; j++) { x = r[scenes[i] SUBSEP wl[w] SUBSEP "embree" SUBSEP emode[j]]; if (x > be) be = x }
        if (bf == 0 && be == 0) continue
        printf "| %s | %s |", scenes[i], wl[w]
        for (j = 1; j <= nf; j++) { x = r[scenes[i] SUBSEP wl[w] SUBSEP "frusta" SUBSEP fmode[j]]
          printf (x == bf ? " **%.1f** |" : " %.1f |"), x }
        for (j = 1; j <= ne; j++) { x = r[scenes[i] SUBSEP wl[w] SUBSEP "embree" SUBSEP emode[j]]
          printf (x == be ? " **%.1f** |" : " %.1f |"), x }
        printf "\n" } }' "${1:-bench/results/vs-embree.txt}"
  exit 0
fi
awk '
  /^scene=/ { delete v; for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
    key = v["scene"] SUBSEP v["workload"]; r = v["mrays"] + 0
    if (!(v["scene"] in sseen)) { sseen[v["scene"]] = 1; scenes[++ns] = v["scene"] }
    if (v["tracer"] == "frusta" && r > f[key]) { f[key] = r; fm[key] = v["mode"] }
    if (v["tracer"] == "embree" && r > e[key]) { e[key] = r; em[key] = v["mode"] " " v["flag"] " " v["packing"] } }
  END {
    n = split("primary shadow soft16 ao16 diffuse8 specular8", wl, " ")
    printf "| scene |"; for (j = 1; j <= n; j++) printf " %s |", wl[j]; printf "\n|---|"
    for (j = 1; j <= n; j++) printf "---|"; printf "\n"
    for (i = 1; i <= ns; i++) { printf "| %s |", scenes[i]
      for (j = 1; j <= n; j++) { k = scenes[i] SUBSEP wl[j]
        if (!(k in f) || !(k in e)) { printf " |"; continue }
        q = f[k] / e[k]; m = q < 1 ? "**" : ""
        printf " %s%.2f%s (%.0f %s / %.0f %s) |", m, q, m, f[k], fm[k], e[k], em[k] }
      printf "\n" } }' "${1:-bench/results/vs-embree.txt}"
