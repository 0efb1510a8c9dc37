#!/usr/bin/env bash
# One command for the whole test suite: install, build, run ctest; then the
# same suite built with AddressSanitizer and UBSan (every report an error),
# its slowest tests on smaller inputs; then a minute of fuzzing the readers
# from the kept corpus. FRUSTA_SANITIZE_TESTS=0 and FRUSTA_FUZZ_SECONDS=0
# skip the last two.
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
FUZZ_SECONDS="${FRUSTA_FUZZ_SECONDS:-60}"
if [ "$FUZZ_SECONDS" != 0 ]; then
  FUZZ="${FRUSTA_FUZZ_DIR:-build-fuzz}"
  CC=clang CXX=clang++ cmake -S . -B "$FUZZ" -DCMAKE_BUILD_TYPE=Release -DFRUSTA_FUZZ=ON >/dev/null
  cmake --build "$FUZZ" -j "$(nproc)" --target fuzz_readers >/dev/null
  found=$(mktemp -d)
  trap 'rm -rf "$found" "$found.log"' EXIT
  status=0
  "$FUZZ/tests/fuzz_readers" -max_total_time="$FUZZ_SECONDS" -timeout=5 -rss_limit_mb=2048 -print_final_stats=1 \
    "$found" tests/fuzz/corpus >"$found.log" 2>&1 || status=$?
  grep -E '^stat::number_of_executed_units|^Done' "$found.log" || true
  if [ "$status" -ne 0 ]; then tail -40 "$found.log"; echo "fuzz_readers: a crash (the input is in the log above)"; exit "$status"; fi
fi
