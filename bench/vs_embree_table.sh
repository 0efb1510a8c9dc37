#!/usr/bin/env bash
# The markdown table of bench/vs_embree.sh from its raw lines: per scene and
# workload, frusta's best mode against Embree's best mode (Mrays/s, best of
# the repetitions), the ratio, and ** where frusta is behind.
# usage: bench/vs_embree_table.sh [bench/results/vs-embree.txt]
set -euo pipefail
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
