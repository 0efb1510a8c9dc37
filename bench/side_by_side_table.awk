# The issue 2/3 side-by-side table from the raw lines of
#   frusta bench SCENE --workload all --mode single,packet16,hybrid16,auto,raystream,stream --tracer both
# usage: awk -f bench/side_by_side_table.awk RAW > table.md
# frusta best is the best of single, packet16, hybrid16, auto and raystream
# (a mode the run left out reads 0); Embree best of its single, packet16 and
# stream. Whitted rows are left out (their own table).
/^scene=/ {
  delete v
  for (i = 1; i <= NF; i++) { split($i, a, "="); v[a[1]] = a[2] }
  k = v["scene"] SUBSEP v["workload"]
  if (!(k in seen)) { seen[k] = 1; order[n++] = k }
  val[k, v["tracer"], v["mode"]] = v["mrays"]
}
function g(k, t, m) { return ((k, t, m) in val) ? val[k, t, m] + 0 : 0 }
function mx(a, b) { return a > b ? a : b }
END {
  print "| scene | workload | single | packet16 | hybrid16 | auto | raystream | Embree single | Embree packet16 | Embree stream | single / Embree single | frusta best / Embree best | hybrid16 / max(single, packet16) |"
  print "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
  for (i = 0; i < n; i++) {
    k = order[i]; split(k, p, SUBSEP)
    if (p[2] == "whitted") continue
    fs = g(k, "frusta", "single"); fp = g(k, "frusta", "packet16"); fh = g(k, "frusta", "hybrid16"); fa = g(k, "frusta", "auto")
    fr = g(k, "frusta", "raystream")
    es = g(k, "embree", "single"); ep = g(k, "embree", "packet16"); et = g(k, "embree", "stream")
    fb = mx(mx(mx(fs, fp), mx(fh, fa)), fr); eb = mx(es, mx(ep, et))
    printf "| %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |\n", p[1], p[2], fs, fp, fh, fa, fr, es, ep, et, fs / es, fb / eb, fh / mx(fs, fp)
  }
}
