#!/usr/bin/env bash
# How the path tracer converges: the material showcase under an HDRI at
# 256x128, rendered at 1, 4, 16, 64 and 256 samples per pixel (seed 1)
# against a 4096-sample reference (seed 2), with both samplers; the root
# mean square error of each, which should fall as 1/sqrt(spp) (a slope of
# -0.5 in log-log) or faster. Raw lines go to bench/results/path-convergence.txt,
# the plot to docs/path_convergence.svg, the table to stdout.
# usage: bench/path_convergence.sh [SIZE]
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${1:-256x128}
F=${FRUSTA:-./build/frusta}
RAW=bench/results/path-convergence.txt
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
ARGS=(--builtin=materials --shade path --size "$SIZE" --env ../shared/hdri/courtyard.exr --lights env --threads 2)
"$F" render "${ARGS[@]}" --spp 4096 --seed 2 --out "$T/ref.pfm" >/dev/null 2>&1
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tools include || echo '+changes')"
  echo "# bench/path_convergence.sh $SIZE"
} >"$RAW"
for sampler in hammersley sobol; do
  for spp in 1 4 16 64 256; do
    "$F" render "${ARGS[@]}" --spp "$spp" --seed 1 --sampler "$sampler" --out "$T/$sampler-$spp.pfm" >/dev/null 2>&1
    python3 - "$T/ref.pfm" "$T/$sampler-$spp.pfm" "$sampler" "$spp" >>"$RAW" <<'PY'
import struct, sys, math
def pfm(path):
    with open(path, 'rb') as f:
        assert f.readline().strip() == b'PF'
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        n = w * h * 3
        return struct.unpack(('<' if scale < 0 else '>') + 'f' * n, f.read(4 * n))
a, b = pfm(sys.argv[1]), pfm(sys.argv[2])
rmse = math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)) / len(a))
print(f"sampler={sys.argv[3]} spp={sys.argv[4]} rmse={rmse:.6f}")
PY
  done
done
python3 - "$RAW" <<'PY'
import sys, math, re
rows = {}
for line in open(sys.argv[1]):
    m = re.match(r'sampler=(\w+) spp=(\d+) rmse=([\d.]+)', line)
    if m: rows.setdefault(m.group(1), []).append((int(m.group(2)), float(m.group(3))))
print("| spp | " + " | ".join(rows) + " |")
print("|---|" + "---|" * len(rows))
for i, (spp, _) in enumerate(next(iter(rows.values()))):
    print(f"| {spp} | " + " | ".join(f"{rows[k][i][1]:.4f}" for k in rows) + " |")
slopes = {}
for k, pts in rows.items():
    xs = [math.log(s) for s, _ in pts]; ys = [math.log(e) for _, e in pts]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    slopes[k] = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
print("| log-log slope | " + " | ".join(f"{slopes[k]:.2f}" for k in rows) + " |")
# the plot: log-log axes, one polyline per sampler and the 1/sqrt(spp) guide
W, H, L, B = 480, 320, 60, 40
allx = [s for pts in rows.values() for s, _ in pts]; ally = [e for pts in rows.values() for _, e in pts]
x0, x1 = math.log10(min(allx)), math.log10(max(allx))
y0, y1 = math.floor(math.log10(min(ally)) * 2) / 2, math.ceil(math.log10(max(ally)) * 2) / 2
X = lambda s: L + (math.log10(s) - x0) / (x1 - x0) * (W - L - 20)
Y = lambda e: H - B - (math.log10(e) - y0) / (y1 - y0) * (H - B - 20)
out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
       f'<rect width="{W}" height="{H}" fill="white"/>',
       f'<line x1="{L}" y1="{H-B}" x2="{W-20}" y2="{H-B}" stroke="black"/><line x1="{L}" y1="20" x2="{L}" y2="{H-B}" stroke="black"/>']
for s in sorted(set(allx)):
    out.append(f'<text x="{X(s):.1f}" y="{H-B+16}" text-anchor="middle">{s}</text>')
e = 10 ** y0
while e <= 10 ** y1 * 1.0001:
    out.append(f'<text x="{L-6}" y="{Y(e)+4:.1f}" text-anchor="end">{e:.3g}</text>'); e *= 10 ** 0.5
out.append(f'<text x="{(L+W-20)/2}" y="{H-6}" text-anchor="middle">samples per pixel</text>')
out.append(f'<text x="14" y="{(H-B)/2}" transform="rotate(-90 14 {(H-B)/2})" text-anchor="middle">RMSE against 4096 spp</text>')
colors = ["#c0392b", "#2471a3"]
first = next(iter(rows.values()))
s0, e0 = first[0]
out.append(f'<polyline fill="none" stroke="#999" stroke-dasharray="4 3" points="' +
           " ".join(f"{X(s):.1f},{Y(e0 * math.sqrt(s0 / s)):.1f}" for s, _ in first) + '"/>')
for (k, pts), c in zip(rows.items(), colors):
    out.append(f'<polyline fill="none" stroke="{c}" stroke-width="2" points="' + " ".join(f"{X(s):.1f},{Y(e):.1f}" for s, e in pts) + '"/>')
    out.append(f'<text x="{W-150}" y="{30 + 16 * list(rows).index(k)}" fill="{c}">{k} (slope {slopes[k]:.2f})</text>')
out.append(f'<text x="{W-150}" y="{30 + 16 * len(rows)}" fill="#999">1/sqrt(spp)</text></svg>')
open("docs/path_convergence.svg", "w").write("\n".join(out))
PY
