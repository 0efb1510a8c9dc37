# Sourced by the viewer's benchmarks: with_display DIR [always] gives the
# viewer a display, a virtual X server (Xvfb) of its own unless DISPLAY is
# set (always: in any case, so nothing else draws on it), and
# XDG_RUNTIME_DIR (DIR unless set); the server stops and DIR is removed
# on exit.
with_display() {
  bench_dir=$1
  if [ -z "${DISPLAY:-}" ] || [ "${2:-}" = always ]; then
    bench_d=$((100 + $$ % 800))
    Xvfb ":$bench_d" -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
    bench_xpid=$!
    trap 'kill $bench_xpid; rm -rf "$bench_dir"' EXIT
    export DISPLAY=":$bench_d"
    for _ in $(seq 100); do [ -e "/tmp/.X11-unix/X$bench_d" ] && break; sleep 0.1; done
  else
    trap 'rm -rf "$bench_dir"' EXIT
  fi
  export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$bench_dir}
}
