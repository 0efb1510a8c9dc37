#!/usr/bin/env bash
# Interleaved A/B of two frusta builds or two flag sets on one workload. This
# VM's speed drifts by up to +-30% between processes, so single runs decide
# nothing: A and B run alternately, ROUNDS pairs, and the line reports the
# mean of each, B/A and how many pairs B won. A and B are a frusta binary,
# optionally followed by bench flags of their own.
# usage: bench/ab.sh "A command" "B command" SCENE WORKLOAD ROUNDS [bench flags...]
# e.g.:  bench/ab.sh "build/frusta --prefetch off" "build/frusta --prefetch on" \
#          ../shared/scenes/hairball/hairball.ply.zst shadow 5 --mode single
# env:   SIZE (512x512) REPEAT (3) THREADS (1)
#        CONCURRENT=1: A and B run at the same time, pinned one per core
#        (cores swapped every pair), so both see the same slow and fast
#        moments of the host; for single-threaded runs on a 2-core machine.
set -euo pipefail
[ $# -ge 5 ] || { sed -n '2,10p' "$0" >&2; exit 2; }
A=$1; B=$2; SCENE=$3; WL=$4; ROUNDS=$5; shift 5
SIZE=${SIZE:-512x512}; REPEAT=${REPEAT:-3}; THREADS=${THREADS:-1}; CONCURRENT=${CONCURRENT:-0}
one() { # "binary [flags]" bench-flags...: Mrays/s (best of REPEAT) of its first result line
  local cmd pin=()
  read -r -a cmd <<<"$1"
  [ -n "${CORE:-}" ] && pin=(taskset -c "$CORE")
  "${pin[@]}" "${cmd[0]}" bench "$SCENE" --workload "$WL" --threads "$THREADS" --size "$SIZE" --repeat "$REPEAT" "${cmd[@]:1}" "${@:2}" |
    awk '/^scene=/ { for (i = 1; i <= NF; i++) if ($i ~ /^mrays=/) { sub("mrays=", "", $i); print $i; exit } }'
}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
for r in $(seq "$ROUNDS"); do
  if [ "$CONCURRENT" = 1 ]; then
    CORE=$((r % 2)) one "$A" "$@" >"$tmp/a" & CORE=$(((r + 1) % 2)) one "$B" "$@" >"$tmp/b"; wait
    a=$(cat "$tmp/a"); b=$(cat "$tmp/b")
  else
    a=$(one "$A" "$@"); b=$(one "$B" "$@")
  fi
  [ -n "$a" ] && [ -n "$b" ] || { echo "ab.sh: a run printed no result" >&2; exit 1; }
  echo "$a $b"
done | awk -v s="$(basename -- "$SCENE")" -v w="$WL" '
  { a += $1; b += $2; won += ($2 > $1); n++; pairs = pairs " " $1 "/" $2 }
  END { if (!n) exit 1; printf "%s %s pairs(A/B):%s meanA=%.3f meanB=%.3f B/A=%.3f B_won=%d/%d\n", s, w, pairs, a / n, b / n, b / a, won, n }'
