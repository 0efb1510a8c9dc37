#!/usr/bin/env bash
# The packet benchmark (issue 3): frusta's single, packet and hybrid modes next
# to Embree's, one process per scene, 2 threads, every workload; the hybrid
# threshold sweep (the MIC paper's Fig. 4); mailboxing and the axis-aligned
# path on and off (Shevtsov's Tables 2-3); BVH4 against BVH8 packets. Raw lines
# go to bench/results/packet-raw.txt, markdown tables to stdout.
# usage: bench/packet_table.sh [--report]   (--report: tables from the raw file only)
# env:   SIZE (1024x1024) REPEAT (3) THREADS (2) SCENES ("conference kitchen dragon hairball")
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${SIZE:-1024x1024}; REPEAT=${REPEAT:-3}; THREADS=${THREADS:-2}
SCENES=${SCENES:-conference kitchen dragon hairball}
RAW=bench/results/packet-raw.txt
F=./build/frusta
bench() { # tag scene args...: one bench run, lines tagged
  local tag=$1 s=$2; shift 2
  "$F" bench "../shared/scenes/$s/$s.ply.zst" --threads "$THREADS" --size "$SIZE" --repeat "$REPEAT" "$@" |
    grep '^scene=' | sed "s/^/$tag /" >>"$RAW"
}
if [ "${1:-}" != "--report" ]; then
  mkdir -p bench/results
  : >"$RAW"
  for s in $SCENES; do
    bench main "$s" --workload all --mode all --tracer both
    bench bvh4 "$s" --workload all --mode packet16 --packet-width 4
    bench bvh4 "$s" --workload all --mode hybrid16 --packet-width 4
  done
  for s in kitchen conference; do
    for wl in ao16 diffuse8; do
      for t in $(seq 1 16); do bench "sweep t=$t" "$s" --workload "$wl" --mode hybrid16 --threshold "$t" --hybrid-tune off; done
    done
    for wl in primary shadow ao16; do
      bench "switch mailbox=off aa=on" "$s" --workload "$wl" --mode packet16
      bench "switch mailbox=on aa=on" "$s" --workload "$wl" --mode packet16 --mailbox on
      bench "switch mailbox=off aa=off" "$s" --workload "$wl" --mode packet16 --axis-aligned off
    done
  done
fi

awk -v size="$SIZE" -v threads="$THREADS" '
  function kv(line,   n, f, i, p) { delete v; n = split(line, f, " "); for (i = 1; i <= n; i++) { split(f[i], p, "="); v[p[1]] = p[2] } }
  $1 == "main" { kv($0); k = v["scene"] "," v["workload"]; r = v["mrays"] + 0
    if (!(k in seen)) { seen[k] = 1; order[++nk] = k }
    if (v["tracer"] == "frusta") fr[k "," v["mode"]] = r
    else { if (v["mode"] == "single") es[k] = r; if (r > eb[k]) { eb[k] = r; ebm[k] = v["mode"] } } }
  $1 == "bvh4" { kv($0); b4[v["scene"] "," v["workload"] "," v["mode"]] = v["mrays"] + 0 }
  $1 == "sweep" { t = $2; sub("t=", "", t); kv($0); c = v["scene"] "," v["workload"]; sw[t "," c] = v["mrays"] + 0
                  if (!(c in swc)) { swc[c] = 1; swcols[++nsw] = c } }
  $1 == "switch" { kv($0); c = v["scene"] "," v["workload"]; sx[c "," $2 "," $3] = v["mrays"] + 0
                   if (!(c in sxk)) { sxk[c] = 1; sxcols[++nsx] = c } }
  END {
    print "### Mrays/s, " threads " threads, " size " (one process per scene)"
    print ""
    print "| scene | workload | frusta single | packet8 | packet16 | hybrid16 | auto | Embree single | Embree best (mode) | frusta best / Embree best | hybrid16 / max(single, packet16) |"
    print "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    for (i = 1; i <= nk; i++) { k = order[i]; split(k, p, ",")
      s = fr[k ",single"]; p16 = fr[k ",packet16"]; h = fr[k ",hybrid16"]; a = fr[k ",auto"]
      best = s; if (fr[k ",packet8"] > best) best = fr[k ",packet8"]; if (p16 > best) best = p16; if (h > best) best = h; if (a > best) best = a
      m = s > p16 ? s : p16
      printf "| %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f (%s) | %.2f | %.2f |\n", p[1], p[2], s, fr[k ",packet8"], p16, h, a, es[k], eb[k], ebm[k], best / eb[k], h / m }
    print ""
    print "### The MIC paper'"'"'s ratios (their Tables IV, VI, VII) from the table above"
    print ""
    print "| scene | P/S primary | S/P primary | P/S diffuse8 | S/P diffuse8 | H/P ao16 | H/S ao16 | H/P diffuse8 | H/S diffuse8 |"
    print "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    for (i = 1; i <= nk; i++) { k = order[i]; split(k, p, ","); if (p[2] != "primary") continue; sc = p[1]
      pp = sc ",primary"; pd = sc ",diffuse8"; pa = sc ",ao16"
      printf "| %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |\n", sc,
        fr[pp ",packet16"] / fr[pp ",single"], fr[pp ",single"] / fr[pp ",packet16"],
        fr[pd ",packet16"] / fr[pd ",single"], fr[pd ",single"] / fr[pd ",packet16"],
        fr[pa ",hybrid16"] / fr[pa ",packet16"], fr[pa ",hybrid16"] / fr[pa ",single"],
        fr[pd ",hybrid16"] / fr[pd ",packet16"], fr[pd ",hybrid16"] / fr[pd ",single"] }
    print ""
    print "### Packets on the BVH4 (the MIC paper'"'"'s) against the BVH8 (default), Mrays/s"
    print ""
    print "| scene | workload | packet16 BVH4 | packet16 BVH8 | hybrid16 BVH4 | hybrid16 BVH8 |"
    print "|---|---|---:|---:|---:|---:|"
    for (i = 1; i <= nk; i++) { k = order[i]; split(k, p, ",")
      printf "| %s | %s | %.2f | %.2f | %.2f | %.2f |\n", p[1], p[2], b4[k ",packet16"], fr[k ",packet16"], b4[k ",hybrid16"], fr[k ",hybrid16"] }
    print ""
    print "### Hybrid threshold sweep (the MIC paper'"'"'s Fig. 4), hybrid16, Mrays/s"
    print ""
    hdr = "| threshold |"; sep = "|---:|"
    for (j = 1; j <= nsw; j++) { split(swcols[j], p, ","); hdr = hdr " " p[1] " " p[2] " |"; sep = sep "---:|" }
    print hdr; print sep
    for (t = 1; t <= 16; t++) { line = "| " t " |"; for (j = 1; j <= nsw; j++) line = line sprintf(" %.2f |", sw[t "," swcols[j]]); print line }
    print ""
    print "### Shevtsov'"'"'s switches, packet16, Mrays/s"
    print ""
    print "| scene | workload | default (mailbox off, axis-aligned path on) | mailbox on | axis-aligned path off |"
    print "|---|---|---:|---:|---:|"
    for (j = 1; j <= nsx; j++) { c = sxcols[j]; split(c, p, ",")
      printf "| %s | %s | %.2f | %.2f | %.2f |\n", p[1], p[2], sx[c ",mailbox=off,aa=on"], sx[c ",mailbox=on,aa=on"], sx[c ",mailbox=off,aa=off"] }
  }' "$RAW"
