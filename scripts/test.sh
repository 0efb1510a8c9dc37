#!/usr/bin/env bash
# One command for the whole test suite: install, build, run ctest; then the
# same suite built with AddressSanitizer and UBSan (every report an error),
# its slowest tests on smaller inputs. FRUSTA_SANITIZE_TESTS=0 skips that
# second run.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
(cd "${FRUSTA_BUILD_DIR:-build}" && ctest --output-on-failure -j "$(nproc)" --timeout 900)
if [ "${FRUSTA_SANITIZE_TESTS:-1}" != 0 ]; then
  SAN="${FRUSTA_SANITIZE_DIR:-build-sanitize}"
  cmake -S . -B "$SAN" -DCMAKE_BUILD_TYPE=Release -DFRUSTA_SANITIZE=ON >/dev/null
  cmake --build "$SAN" -j "$(nproc)" >/dev/null
  (cd "$SAN" && ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 ctest --output-on-failure -j "$(nproc)" --timeout 1200)
fi
