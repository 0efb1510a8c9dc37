#!/usr/bin/env bash
# One command for a newcomer: install, build, render the built-in scene.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
./build/frusta render --builtin --size 1024x768 --shade shadows --out builtin.png
echo "wrote $(pwd)/builtin.png"
