#!/usr/bin/env bash
# The multi-frusta paper's Table 2: soft16 shadow frusta with no shrinking,
# corner rays shrunk to the active rays (the paper's "CR"), and corner rays
# and direction intervals shrunk (frusta's default), per scene and light-set
# kind. Timing: ROUNDS rounds, the three variants one after another in each
# (this VM drifts between processes, so they alternate), 2 threads,
# 1024x1024, best of REPEAT per process; the line gives the best and the mean
# over rounds. With a counters build in build-count/ it also records, per
# variant, the frusta's box tests and triangle tests per batch.
# env: SIZE (1024x1024) REPEAT (3) THREADS (2) ROUNDS (5)
#      SCENES ("conference kitchen sibenik dragon") SETS ("spread cells")
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${SIZE:-1024x1024}; REPEAT=${REPEAT:-3}; THREADS=${THREADS:-2}; ROUNDS=${ROUNDS:-5}
SCENES=${SCENES:-conference kitchen sibenik dragon}; SETS=${SETS:-spread cells}
RAW=bench/results/mft-table2-shrink.txt
mkdir -p bench/results
printf "# commit %s\n# %s\n" "$(git rev-parse --short HEAD)" "bench/$(basename "$0") $*" >"$RAW"
run() { # binary scene sets shrink repeat: the bench's result and counters lines
  "$1" bench "../shared/scenes/$2/$2.ply.zst" --workload soft16 --mode mft --light-sets "$3" --shrink "$4" \
    --threads "$THREADS" --size "$SIZE" --repeat "$5" | grep -E '^(scene=|counters)' | sed "s/^/sets=$3 shrink=$4 /; s/^\(.*\)counters /scene=$2 \1/"
}
for s in $SCENES; do
  for ls in $SETS; do
    for r in $(seq "$ROUNDS"); do
      for sh in off corners on; do run ./build/frusta "$s" "$ls" "$sh" "$REPEAT" | grep '^sets=.*scene=' >>"$RAW"; done
    done
    if [ -x build-count/frusta ]; then
      for sh in off corners on; do run ./build-count/frusta "$s" "$ls" "$sh" 1 | grep 'per_batch' >>"$RAW"; done
    fi
  done
done
# one line per scene, sets and variant: best and mean Mrays/s over the rounds
awk '/ scene=/ {
  for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
  k = v["scene"] " " $1 " " $2; n[k]++; sum[k] += v["mrays"]; if (v["mrays"] > best[k]) best[k] = v["mrays"]
  if (!(k in seen)) { seen[k] = 1; order[++m] = k }
}
END { for (j = 1; j <= m; j++) { k = order[j]; printf "%s best=%.2f mean=%.2f rounds=%d\n", k, best[k], sum[k] / n[k], n[k] } }' "$RAW"
grep per_batch "$RAW" | sed 's/tracer=frusta mode=mft workload=soft16 //' || true
echo "raw lines in $RAW"
