#!/usr/bin/env bash
# Installs what frusta needs from Debian's packages (only what is missing),
# then configures and builds a Release tree in build/. Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."

PKGS="build-essential cmake pkg-config zstd libzstd-dev libassimp-dev libembree-dev \
libstb-dev libopenexr-dev libcmocka-dev libcjson-dev assimp-testmodels clang libclang-rt-14-dev libomp-dev \
libsdl2-dev xvfb xauth xdotool libopenmpi-dev openmpi-bin python3-dev python3-numpy python3-pytest"

missing=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "setup: installing$missing"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi

BUILD_DIR="${FRUSTA_BUILD_DIR:-build}"
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD_DIR" -j "$(nproc)"
# The Python module into /usr/local, where Debian's python3 finds it.
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO cmake --install "$BUILD_DIR" --component python >/dev/null
