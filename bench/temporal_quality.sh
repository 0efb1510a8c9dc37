#!/usr/bin/env bash
# Temporal blending in the viewer: kitchen path traced at 1 spp per frame
# along a turntable (the camera turns every frame), the last frame against
# a many-sample reference of its view (another seed): relative RMSE over
# the pixels, with the denoiser and the blending on and off, and the
# blend's share of reused pixels and its time per frame. Starts its own
# Xvfb when there is no DISPLAY. Raw lines go to
# bench/results/temporal.txt (commit and command at the top).
# usage: bench/temporal_quality.sh [FRAMES] [SIZE] [REF_SPP]
set -euo pipefail
cd "$(dirname "$0")/.."
FRAMES=${1:-8}
SIZE=${2:-256x192}
REF=${3:-4096}
F=${FRUSTA:-./build/frusta}
K=../shared/scenes/kitchen/kitchen.ply.zst
RAW=bench/results/temporal.txt
T=$(mktemp -d)
. bench/display.sh
with_display "$T"
mkdir -p bench/results
V="--shade path --size $SIZE --threads 2 --frames $FRAMES --turntable 0.5"
for dn in off on; do
  for tp in off on; do
    "$F" view "$K" $V --denoise $dn --temporal $tp --record "$T/cam.path" --screenshot "$T/v_${dn}_$tp.pfm" >"$T/v_${dn}_$tp.log"
  done
done
set -- $(tail -1 "$T/cam.path")
"$F" render "$K" --shade path --sampler sobol --size "$SIZE" --threads 2 --seed 99 --spp "$REF" \
  --eye "$1" --at "$2" --up "$3" --fov "$4" --out "$T/ref.pfm" >/dev/null
{
  echo "# commit $(git rev-parse --short HEAD)$(git diff --quiet HEAD -- src tools include || echo '+changes')"
  echo "# bench/temporal_quality.sh $FRAMES $SIZE $REF"
  for f in "$T"/v_*.log; do echo "## $(basename "$f" .log)"; tail -2 "$f"; done
  python3 - "$T" <<'PY'
import sys
sys.path.insert(0, "bench")
from pfm_images import pfm, rel_rmse
T = sys.argv[1]
ref = pfm(f'{T}/ref.pfm')[2]
for dn in ('off', 'on'):
    print(f"denoise={dn} rel_rmse_temporal_off={rel_rmse(pfm(f'{T}/v_{dn}_off.pfm')[2], ref):.4f} "
          f"rel_rmse_temporal_on={rel_rmse(pfm(f'{T}/v_{dn}_on.pfm')[2], ref):.4f}")
PY
} | tee "$RAW"
