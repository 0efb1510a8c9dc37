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
. bench/display.sh
with_display "$T" always
"$F" view "$K" --shade path --size "$SIZE" --threads 2 --frames "$FRAMES" --turntable 1 --screenshot "$T/f#.pfm" >/dev/null
python3 - "$T" "$FRAMES" docs/view_turntable.png <<'PY'
import sys
sys.path.insert(0, "bench")
from pfm_images import pfm, write_apng
T, n, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
write_apng(out, [pfm(f"{T}/f{i:04d}.pfm") for i in range(n)])
PY
echo "-> docs/view_turntable.png ($FRAMES frames)"
