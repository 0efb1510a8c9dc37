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
import sys
sys.path.insert(0, "bench")
from pfm_images import pfm, rel_rmse
T = sys.argv[1]
ref = pfm(f'{T}/ref.pfm')[2]
for spp in (1, 4, 16):
    print(f"spp={spp} rel_rmse_noisy={rel_rmse(pfm(f'{T}/n{spp}.pfm')[2], ref):.4f} "
          f"rel_rmse_denoised={rel_rmse(pfm(f'{T}/d{spp}.pfm')[2], ref):.4f}")
PY
} | tee "$RAW"
# the picture: 1 spp, 1 spp denoised / 16 spp denoised, the reference,
# through the same filmic curve and sRGB as the command's PNGs
python3 - "$T" docs/denoise_kitchen.png <<'PY'
import sys
sys.path.insert(0, "bench")
from pfm_images import pfm, write_png
T, out = sys.argv[1:3]
write_png(out, [pfm(f"{T}/{n}.pfm") for n in ("n1", "d1", "d16", "ref")], 2)
PY
echo "-> docs/denoise_kitchen.png"
