#!/usr/bin/env bash
# One command for the whole test suite: install, build, run ctest; then the
# same suite built with AddressSanitizer and UBSan (every report an error),
# its slowest tests on smaller inputs; then the threaded paths under
# ThreadSanitizer; then a minute of fuzzing the readers from the kept
# corpus. FRUSTA_SANITIZE_TESTS=0, FRUSTA_TSAN_TESTS=0 and
# FRUSTA_FUZZ_SECONDS=0 skip the last three.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
(cd "${FRUSTA_BUILD_DIR:-build}" && ctest --output-on-failure -j "$(nproc)" --timeout 900)
# The Python module: pytest on the build's copy (checked against the C
# library's own answers through FRUSTA_LIB), then Debian's python3 importing
# the installed one from anywhere.
B="$(cd "${FRUSTA_BUILD_DIR:-build}" && pwd)"
[ -e "$B/python/frusta/__init__.py" ] || { echo "the Python module was not built (python3-numpy missing?)"; exit 1; }
SH="${FRUSTA_SHARED:-../shared}"; case "$SH" in /*) ;; *) SH="$(pwd)/$SH" ;; esac
FRUSTA_LIB="$B/libfrusta.so" FRUSTA_BIN="$B/frusta" FRUSTA_SHARED="$SH" PYTHONPATH="$B/python" \
  /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/python
(cd / && /usr/bin/python3 -c "import frusta; print('python3: frusta', frusta.__version__, 'from', frusta.__file__)")
if [ "${FRUSTA_SANITIZE_TESTS:-1}" != 0 ]; then
  SAN="${FRUSTA_SANITIZE_DIR:-build-sanitize}"
  cmake -S . -B "$SAN" -DCMAKE_BUILD_TYPE=Release -DFRUSTA_SANITIZE=ON >/dev/null
  cmake --build "$SAN" -j "$(nproc)" >/dev/null
  (cd "$SAN" && ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 ctest --output-on-failure -j "$(nproc)" --timeout 1200)
fi
if [ "${FRUSTA_TSAN_TESTS:-1}" != 0 ]; then
  # ThreadSanitizer over the threaded paths: many threads calling one
  # scene, the same answers after different rays on every thread, and the
  # command's render, bench and view on worker threads; any report fails
  # the run. Built with clang,
  # whose OpenMP runtime tells the sanitizer of its barriers through the
  # Archer tool (GCC's libgomp does not, and its joins read as races).
  # This build leaves MPI out: the command must work without it.
  TSAN="${FRUSTA_TSAN_DIR:-build-tsan}"
  CC=clang CXX=clang++ cmake -S . -B "$TSAN" -DCMAKE_BUILD_TYPE=Release -DFRUSTA_TSAN=ON \
    -DCMAKE_DISABLE_FIND_PACKAGE_MPI=ON >/dev/null
  cmake --build "$TSAN" -j "$(nproc)" --target test_threads test_same_answers frusta >/dev/null
  export TSAN_OPTIONS=halt_on_error=1:exitcode=66:ignore_noninstrumented_modules=1
  export OMP_TOOL_LIBRARIES=/usr/lib/llvm-14/lib/libarcher.so
  "$TSAN/tests/test_threads" >/dev/null
  "$TSAN/tests/test_same_answers" >/dev/null
  out=$(mktemp -d)
  for shade in eyelight softshadow whitted; do
    "$TSAN/frusta" render --builtin --shade "$shade" --size 96x96 --threads 4 --out "$out/$shade.png" >/dev/null
  done
  "$TSAN/frusta" render "${FRUSTA_SHARED:-../shared}/scenes/kitchen/kitchen.ply.zst" --shade softshadow --size 64x64 \
    --threads 4 --out "$out/kitchen.png" >/dev/null
  "$TSAN/frusta" render --builtin=materials --shade path --spp 2 --size 64x32 --threads 4 --out "$out/path.png" >/dev/null
  "$TSAN/frusta" bench --builtin --workload all --mode all --threads 4 --size 64x64 --repeat 1 >/dev/null
  "$TSAN/frusta" bench --builtin=materials --workload path --mode all --threads 4 --size 32x32 --spp 2 --repeat 1 >/dev/null
  if "$TSAN/frusta" --version | grep -q mpi; then echo "the build without MPI has MPI"; exit 1; fi
  # the viewer: its worker and the main thread, with keys typed into the
  # window switching modes and abandoning passes
  D=$((100 + $$ % 800))
  Xvfb ":$D" -screen 0 800x600x24 -nolisten tcp >/dev/null 2>&1 &
  XPID=$!
  for _ in $(seq 100); do [ -e "/tmp/.X11-unix/X$D" ] && break; sleep 0.1; done
  mkdir -m 700 "$out/xdg"
  DISPLAY=":$D" XDG_RUNTIME_DIR="$out/xdg" "$TSAN/frusta" view --builtin --size 96x64 --threads 4 --shade path >/dev/null &
  VP=$!
  sleep 3
  for k in 2 w 7 m m 4 6 n 1 5; do DISPLAY=":$D" xdotool search --sync --name frusta key $k >/dev/null 2>&1; sleep 0.3; done
  kill -TERM $VP
  vstatus=0; wait $VP || vstatus=$?
  [ "$vstatus" -eq 0 ] || { kill $XPID; echo "ThreadSanitizer: the viewer exited $vstatus"; exit 1; }
  # scripted frames: the worker renders the next frame while the main thread shows one
  DISPLAY=":$D" XDG_RUNTIME_DIR="$out/xdg" "$TSAN/frusta" view --builtin --size 96x64 --threads 4 --shade path \
    --frames 4 --turntable 5 --screenshot "$out/frame_#.png" >/dev/null || vstatus=$?
  kill $XPID
  [ "$vstatus" -eq 0 ] || { echo "ThreadSanitizer: the scripted viewer exited $vstatus"; exit 1; }
  rm -rf "$out"
  unset TSAN_OPTIONS OMP_TOOL_LIBRARIES
  echo "ThreadSanitizer: threads, same answers, render, bench and view on 4 threads (built without MPI): no report"
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
