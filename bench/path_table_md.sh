#!/usr/bin/env bash
# The markdown table of bench/path_table.sh's raw lines: frames per second
# per mode, frusta's best over Embree's best, and the share of frusta's
# best run spent outside tracing (sampling, shading, lights).
# usage: bench/path_table_md.sh bench/results/path.txt
set -euo pipefail
awk '
function val(k,   i) { for (i = 1; i <= NF; i++) if (index($i, k "=") == 1) return substr($i, length(k) + 2); return "" }
/^case=/ {
  key = val("case") " " val("light")
  if (!(key in seen)) { seen[key] = 1; order[n++] = key }
  t = val("tracer"); m = val("mode")
  if ($3 ~ /^scene=/) {
    fps = 1.0 / val("seconds"); mr = val("mrays")
    F[key, t, m] = fps; M[key, t, m] = mr
    if (t == "frusta" && fps > bestf[key]) { bestf[key] = fps; bestfm[key] = m; bestmr[key] = mr }
    if (t == "embree" && fps > beste[key]) { beste[key] = fps; bestem[key] = m; bestemr[key] = mr }
  } else {
    O[key, t, m] = val("outside_tracing")
  }
}
END {
  print "| scene, light | single | packet16 | hybrid16 | auto | raystream | Embree best | frusta / Embree | outside tracing |"
  print "|---|---|---|---|---|---|---|---|---|"
  for (i = 0; i < n; i++) {
    k = order[i]
    printf "| %s |", k
    split("single packet16 hybrid16 auto raystream", ms, " ")
    for (j = 1; j <= 5; j++) printf " %.2f |", F[k, "frusta", ms[j]]
    printf " %.2f (%s) | **%.2f** (%s %.1f / %.1f Mrays/s) | %s |\n", beste[k], bestem[k], bestf[k] / beste[k], bestfm[k], bestmr[k], bestemr[k], O[k, "frusta", bestfm[k]]
  }
}' "$1"
