#!/usr/bin/env bash
# The denoiser's quality: kitchen path traced at 1, 4 and 16 spp, with
# and without the denoiser, against a many-sample reference of the same
# view (a different seed): relative RMSE over the pixels, and pictures
# docs/denoise_kitchen.png (top: 1 spp, 1 spp denoised; bottom: 16 spp
# denoised, the reference). Raw lines go to bench/results/denoise.txt.
# usage: bench/denoise_quality.sh [SIZE] [REF_SPP]
set -euo pipefail
cd "$(dirname "$0")/.."
SIZE=${1:-256x192}
REF=${2:-4096}
F=${FRUSTA:-./build/frusta}
K=../shared/scenes/kitchen/kitchen.ply.zst
RAW=bench/results/denoise.txt
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
mkdir -p bench/results
P="--shade path --sampler sobol --size $SIZE --threads 2"
"$F" render "$K" $P --seed 99 --spp "$REF" --out "$T/ref.pfm" >/dev/null
for spp in 1 4 16; do
  "$F" render "$K" $P --spp $spp --out "$T/n$spp.pfm" >/dev/null
  "$F" render "$K" $P --spp $spp --denoise on --out "$T/d$spp.pfm" >"$T/d$spp.log"
done
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tools include || echo '+changes')"
  echo "# bench/denoise_quality.sh $SIZE $REF"
  python3 - "$T" <<'PY'
import struct, sys, math
T = sys.argv[1]
def pfm(path):
    with open(path, 'rb') as f:
        assert f.readline().strip() == b'PF'
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = f.read()
    return struct.unpack(('<' if scale < 0 else '>') + 'f' * (w * h * 3), data)
ref = pfm(f'{T}/ref.pfm')
def rel_rmse(img):  # per value, relative to the reference's value (+0.01)
    s = sum(((a - b) / (b + 0.01)) ** 2 for a, b in zip(img, ref))
    return math.sqrt(s / len(ref))
for spp in (1, 4, 16):
    print(f"spp={spp} rel_rmse_noisy={rel_rmse(pfm(f'{T}/n{spp}.pfm')):.4f} rel_rmse_denoised={rel_rmse(pfm(f'{T}/d{spp}.pfm')):.4f}")
PY
} | tee "$RAW"
# the picture: 1 spp, 1 spp denoised / 16 spp denoised, the reference,
# through the same filmic curve and sRGB as the command's PNGs
python3 - "$T" docs/denoise_kitchen.png <<'PY'
import struct, sys, zlib
T, out = sys.argv[1:3]
def pfm(path):
    with open(path, 'rb') as f:
        assert f.readline().strip() == b'PF'
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        v = struct.unpack(('<' if scale < 0 else '>') + 'f' * (w * h * 3), f.read())
    return w, h, v
def code(x):
    x = max(x, 0.0)
    x = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)
    if x >= 1.0: return 255
    s = 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055
    return int(s * 255 + 0.5)
panels = [pfm(f"{T}/{n}.pfm") for n in ("n1", "d1", "d16", "ref")]
w, h = panels[0][0], panels[0][1]
rows = []
for gy in range(2):
    for y in range(h):  # PFM rows run bottom to top
        row = bytearray([0])
        for gx in range(2):
            v = panels[2 * gy + gx][2]
            base = (h - 1 - y) * w * 3
            row += bytes(code(c) for c in v[base:base + 3 * w])
        rows.append(bytes(row))
def chunk(t, d): return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2 * w, 2 * h, 8, 2, 0, 0, 0))
png += chunk(b"IDAT", zlib.compress(b"".join(rows), 9)) + chunk(b"IEND", b"")
open(out, "wb").write(png)
PY
echo "-> docs/denoise_kitchen.png"
