#!/usr/bin/env bash
# What the viewer shows while the camera moves: `frusta view` along a
# turntable of kitchen (FRAMES frames, 1 degree apart; 1 sample per pixel
# per frame, denoised and blended with the frames before), each frame's
# screenshot kept, then made into an animated PNG, docs/view_turntable.png
# (browsers play it; other viewers show its first frame), through the
# same filmic curve and sRGB as the command's PNGs. Starts its own Xvfb.
# usage: bench/view_sequence.sh [FRAMES] [SIZE]
set -euo pipefail
cd "$(dirname "$0")/.."
FRAMES=${1:-20}
SIZE=${2:-320x240}
F=${FRUSTA:-./build/frusta}
K=../shared/scenes/kitchen/kitchen.ply.zst
T=$(mktemp -d)
D=$((100 + $$ % 800))
Xvfb ":$D" -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
XPID=$!
trap 'kill $XPID; rm -rf "$T"' EXIT
export DISPLAY=":$D" XDG_RUNTIME_DIR="$T"
for _ in $(seq 100); do [ -e "/tmp/.X11-unix/X$D" ] && break; sleep 0.1; done
"$F" view "$K" --shade path --size "$SIZE" --threads 2 --frames "$FRAMES" --turntable 1 --screenshot "$T/f#.pfm" >/dev/null
python3 - "$T" "$FRAMES" docs/view_turntable.png <<'PY'
import struct, sys, zlib
T, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
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
def rows(w, h, v):  # PFM rows run bottom to top
    return b"".join(b"\0" + bytes(code(c) for c in v[(h - 1 - y) * w * 3:(h - y) * w * 3]) for y in range(h))
def chunk(t, d): return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
frames = [pfm(f"{T}/f{i:04d}.pfm") for i in range(n)]
w, h = frames[0][0], frames[0][1]
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
png += chunk(b"acTL", struct.pack(">II", n, 0))  # n frames, looping
seq = 0
for i, (fw, fh, v) in enumerate(frames):
    png += chunk(b"fcTL", struct.pack(">IIIIIHHBB", seq, w, h, 0, 0, 1, 10, 0, 0))  # 1/10 s per frame
    seq += 1
    data = zlib.compress(rows(fw, fh, v), 9)
    if i == 0:
        png += chunk(b"IDAT", data)
    else:
        png += chunk(b"fdAT", struct.pack(">I", seq) + data)
        seq += 1
png += chunk(b"IEND", b"")
open(out, "wb").write(png)
PY
echo "-> docs/view_turntable.png ($FRAMES frames)"
