#!/bin/sh
# The viewer without a person: under a virtual X server (Xvfb, started
# here), scripted frames along a camera path and a turntable exit 0, their
# screenshots equal `frusta render` of the same view (byte for byte: the
# deterministic modes after one frame, the progressive ones after as many
# samples), and bad input and a missing display give one-line errors.
# usage: view_test.sh FRUSTA SHARED_DIR SOURCE_DIR
set -u
F="$1"; SHARED="$2"; SRC="$3"
# under the sanitizers: SDL and the X libraries keep small allocations for
# the process's life that LeakSanitizer reports (not frusta's to free), so
# leak checking is off here; address and undefined-behaviour checks stay on
export LSAN_OPTIONS="suppressions=$SRC/tests/lsan_display.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
fails=0; passes=0
ok() { passes=$((passes+1)); }
bad() { echo "FAIL: $*"; fails=$((fails+1)); }
expect() { # CODE CMD...: the exit code, and one "frusta: " line on stderr on failure
  want=$1; shift
  "$@" >"$T/out" 2>"$T/err"; got=$?
  if [ "$got" -ne "$want" ]; then bad "exit $got, wanted $want: $*"; cat "$T/err" "$T/out" | tail -5; return; fi
  if [ "$want" -ne 0 ]; then
    lines=$(wc -l <"$T/err")
    if [ "$lines" -ne 1 ] || ! grep -q '^frusta: ' "$T/err"; then bad "not a one-line error ($lines lines): $*"; cat "$T/err"; return; fi
  fi
  ok
}
same() { cmp -s "$1" "$2" && ok || bad "$3: $1 and $2 differ"; }

# no display at all
(unset DISPLAY WAYLAND_DISPLAY; expect 1 "$F" view --builtin --frames 1)
(DISPLAY=:99; unset WAYLAND_DISPLAY; export DISPLAY; expect 1 "$F" view --builtin --frames 1)

# a display of our own
unset WAYLAND_DISPLAY
export XDG_RUNTIME_DIR="$T/xdg"; mkdir -m 700 "$XDG_RUNTIME_DIR"
D=$((100 + $$ % 800))
Xvfb :$D -screen 0 1024x768x24 -nolisten tcp >"$T/xvfb.log" 2>&1 &
XPID=$!
trap 'kill $XPID 2>/dev/null; rm -rf "$T"' EXIT
export DISPLAY=:$D
i=0; while [ ! -e /tmp/.X11-unix/X$D ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i+1)); done

# interactive: the window opens and renders on its worker until asked to
# close (SDL turns SIGTERM into a quit event); keys typed into it switch
# the mode while a path frame renders and print the camera
"$F" view --builtin --size 128x96 --threads 2 --shade path >"$T/live.out" 2>"$T/live.err" &
VP=$!
sleep 2
for k in w 5 p m 7; do xdotool search --sync --name frusta key $k >/dev/null 2>&1; sleep 0.3; done
sleep 1
kill -TERM $VP 2>/dev/null
wait $VP; code=$?
[ "$code" -eq 0 ] && grep -q '^keys:' "$T/live.out" && ok || { bad "interactive view exited $code"; cat "$T/live.err"; }
grep -q '^whitted depth=' "$T/live.out" && ok || bad "key 5 did not switch the live view to whitted"
grep -q '^--eye .* --fov ' "$T/live.out" && ok || bad "key p did not print the camera"
grep -q '^view: [0-9]* changes answered in [0-9.]* ms median' "$T/live.out" && ok || bad "the live view did not say how soon it answered"

S="--size 96x64 --threads 2"
# every deterministic mode: one frame equals render
for m in eyelight normals shadows whitted; do
  expect 0 "$F" view --builtin $S --shade $m --frames 2 --screenshot "$T/v_$m.png"
  expect 0 "$F" render --builtin $S --shade $m --out "$T/r_$m.png"
  same "$T/v_$m.png" "$T/r_$m.png" "view and render, $m"
done
# progressive modes: N frames at rest equal render with as many samples
expect 0 "$F" view --builtin $S --shade path --frames 3 --denoise off --screenshot "$T/v_path.png"
expect 0 "$F" render --builtin $S --shade path --sampler sobol --spp 3 --out "$T/r_path.png"
same "$T/v_path.png" "$T/r_path.png" "view and render, path 3 spp"
[ -s "$T/v_path.exr" ] && ok || bad "a path screenshot has no EXR beside it"
expect 0 "$F" view --builtin $S --shade path --frames 2 --screenshot "$T/v_pd.png"
expect 0 "$F" render --builtin $S --shade path --sampler sobol --spp 2 --denoise on --out "$T/r_pd.png"
same "$T/v_pd.png" "$T/r_pd.png" "view and render, path 2 spp denoised"
expect 0 "$F" view --builtin $S --shade ao --frames 2 --denoise off --screenshot "$T/v_ao.png"
expect 0 "$F" render --builtin $S --shade ao --spp 32 --out "$T/r_ao.png"
same "$T/v_ao.png" "$T/r_ao.png" "view and render, ao 32 rays"
expect 0 "$F" view --builtin $S --shade softshadow --frames 1 --denoise off --screenshot "$T/v_s1.png"
expect 0 "$F" render --builtin $S --shade softshadow --out "$T/r_s1.png"
same "$T/v_s1.png" "$T/r_s1.png" "view and render, softshadow preview"
expect 0 "$F" view --builtin $S --shade softshadow --frames 6 --denoise off --screenshot "$T/v_s6.png"
expect 0 "$F" render --builtin $S --shade softshadow --light-samples 80 --out "$T/r_s6.png"
same "$T/v_s6.png" "$T/r_s6.png" "view and render, softshadow 5 spread passes"

# a recorded camera path played back: the last frame equals render of the last view
expect 0 "$F" view --builtin $S --frames 4 --turntable 10 --record "$T/cam.path"
[ "$(grep -c . "$T/cam.path")" -eq 4 ] && ok || bad "--record wrote $(grep -c . "$T/cam.path") views, not 4"
expect 0 "$F" view --builtin $S --camera-path "$T/cam.path" --shade normals --screenshot "$T/v_cam_#.png"
[ -s "$T/v_cam_0000.png" ] && [ -s "$T/v_cam_0003.png" ] && ok || bad "numbered screenshots missing"
last=$(tail -1 "$T/cam.path")
set -- $last
expect 0 "$F" render --builtin $S --shade normals --eye "$1" --at "$2" --up "$3" --fov "$4" --out "$T/r_cam.png"
same "$T/v_cam_0003.png" "$T/r_cam.png" "the camera path's last view"
grep -q '^frame 3: ' "$T/out" 2>/dev/null || true

# temporal blending along a turntable: without it the last frame is
# render's of the last view; with it the frames blend and reuse most pixels
expect 0 "$F" view --builtin $S --shade path --frames 5 --turntable 1 --denoise off --temporal off --record "$T/tt.path" \
  --screenshot "$T/v_t0.png"
last=$(tail -1 "$T/tt.path")
set -- $last
expect 0 "$F" render --builtin $S --shade path --sampler sobol --spp 1 --eye "$1" --at "$2" --up "$3" --fov "$4" --out "$T/r_t.png"
same "$T/v_t0.png" "$T/r_t.png" "a moving path view without temporal blending"
expect 0 "$F" view --builtin $S --shade path --frames 5 --turntable 1 --denoise off --screenshot "$T/v_t1.png"
grep -q '^frame 4: .* reused=[5-9][0-9]%' "$T/out" && ok || { bad "temporal blending reused little"; grep '^frame' "$T/out"; }
cmp -s "$T/v_t1.png" "$T/v_t0.png" && bad "temporal blending changed nothing" || ok

# a shared scene, its own view
K="$SHARED/scenes/kitchen/kitchen.ply.zst"
if [ -e "$K" ]; then
  expect 0 "$F" view "$K" $S --shade softshadow --frames 1 --screenshot "$T/v_k.png" --denoise off
  expect 0 "$F" render "$K" $S --shade softshadow --out "$T/r_k.png"
  same "$T/v_k.png" "$T/r_k.png" "view and render, kitchen softshadow"
fi

# bad input
expect 1 "$F" view "$T/missing.ply" --frames 1
printf 'garbage\n' >"$T/bad.path"
expect 1 "$F" view --builtin $S --camera-path "$T/bad.path"
printf '1,2,3 0,0,0 0,1,0 500\n' >"$T/fov.path"
expect 1 "$F" view --builtin $S --camera-path "$T/fov.path"
printf '# nothing\n' >"$T/empty.path"
expect 1 "$F" view --builtin $S --camera-path "$T/empty.path"
expect 1 "$F" view --builtin $S --camera-path "$T/missing.path"
expect 2 "$F" view --builtin $S --frames 0
expect 2 "$F" view --builtin $S --mode packet8
expect 2 "$F" view --builtin $S --screenshot "$T/a.png"
expect 2 "$F" view --builtin $S --frames 1 --screenshot "$T/a.bmp"
expect 2 "$F" view --builtin $S --shade ao --spp 10 --frames 1
expect 0 "$F" view --help

echo "view: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
