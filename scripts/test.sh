#!/usr/bin/env bash
# One command for the whole test suite: install, build, run ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cd "${FRUSTA_BUILD_DIR:-build}"
ctest --output-on-failure -j "$(nproc)" --timeout 900
