#!/bin/sh
# Frames across processes: `mpirun -np 2` and `-np 3` render every shade
# mode of the built-in scenes and a shared scene to the same bytes as one
# process, bench counts the same rays, and a rank that cannot load the
# scene, or dies, stops the job with one line from frusta and a non-zero
# exit within seconds. Exit 77 (skipped) when frusta was built without MPI.
# usage: cluster_test.sh FRUSTA SHARED_DIR
set -u
F="$1"; SHARED="$2"
"$F" --version | grep -q ', mpi)' || { echo "frusta was built without MPI: skipped"; exit 77; }
command -v mpirun >/dev/null || { echo "no mpirun: skipped"; exit 77; }
# Open MPI refuses root unless told; the shared-memory transport's
# single-copy mode needs ptrace rights a container may not grant
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none
# under the sanitizers: Open MPI keeps its allocations for the process's life
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
fails=0; passes=0
ok() { passes=$((passes+1)); }
bad() { echo "FAIL: $*"; fails=$((fails+1)); }
MPI="timeout 300 mpirun --oversubscribe"

# one process, then 2 and 3 ranks of one thread: the same bytes
same_image() { # NAME SCENE ARGS...
  name=$1; scene=$2; shift 2
  "$F" render "$scene" "$@" --threads 2 --out "$T/$name.1.exr" >/dev/null 2>"$T/err" || { bad "$name: one process failed"; cat "$T/err"; return; }
  for n in 2 3; do
    if ! $MPI -np $n "$F" render "$scene" "$@" --threads 1 --out "$T/$name.$n.exr" >"$T/out" 2>"$T/err"; then
      bad "$name: $n ranks failed"; tail -5 "$T/err"; continue
    fi
    cmp -s "$T/$name.1.exr" "$T/$name.$n.exr" && ok || bad "$name: $n ranks differ from one process"
  done
}
S="--size 100x70" # not a whole number of tiles
for shade in eyelight normals shadows softshadow whitted; do
  same_image "$shade" --builtin $S --shade $shade
done
same_image soft32 --builtin $S --shade softshadow --light-samples 32
same_image soft16_denoised --builtin $S --shade softshadow --denoise on
same_image ao --builtin $S --shade ao --spp 32
same_image path --builtin=materials $S --shade path --spp 6
same_image path_denoised --builtin=materials $S --shade path --spp 4 --denoise on
same_image spheres --builtin=sphereflake $S --shade whitted
K="$SHARED/scenes/kitchen/kitchen.ply.zst"
if [ -f "$K" ]; then
  for shade in softshadow whitted; do same_image "kitchen_$shade" "$K" --size 160x120 --shade $shade; done
  same_image kitchen_path "$K" --size 96x64 --shade path --spp 2
else
  bad "no shared kitchen scene at $K"
fi

# the PNG a path render writes, and its guides with --aov
"$F" render --builtin=materials $S --shade path --spp 2 --aov --threads 2 --out "$T/aov1.png" >/dev/null 2>&1
$MPI -np 2 "$F" render --builtin=materials $S --shade path --spp 2 --aov --threads 1 --out "$T/aov2.png" >/dev/null 2>&1
for f in aov1.png:aov2.png aov1.albedo.exr:aov2.albedo.exr aov1.normal.exr:aov2.normal.exr; do
  cmp -s "$T/${f%%:*}" "$T/${f##*:}" && ok || bad "path --aov: ${f%%:*} and ${f##*:} differ"
done

# bench: the cluster's rays are the one process's, and each rank has a share
"$F" bench --builtin --workload soft16,whitted --mode mft --size 96x96 --repeat 1 --threads 2 >"$T/b1" 2>&1
$MPI -np 3 "$F" bench --builtin --workload soft16,whitted --mode mft --size 96x96 --repeat 1 --threads 1 >"$T/b3" 2>&1
for wl in soft16 whitted; do
  r1=$(grep "^scene=.*workload=$wl " "$T/b1" | sed 's/.* rays=\([0-9]*\) .*/\1/')
  r3=$(grep "^scene=.*workload=$wl " "$T/b3" | sed 's/.* rays=\([0-9]*\) .*/\1/')
  [ -n "$r1" ] && [ "$r1" = "$r3" ] && ok || bad "bench $wl: $r3 rays on 3 ranks, $r1 on one"
  grep -q "^cluster .*workload=$wl ranks=3 .*rank_rays=[0-9.]*%,[0-9.]*%,[0-9.]*% rank_tiles=[0-9]*,[0-9]*,[0-9]*$" "$T/b3" &&
    ok || bad "bench $wl: no line of the ranks' shares"
done

# failures: one clear line from rank 0, a non-zero exit, no image
one_line() { # what: stderr has exactly one line of frusta's, matching $2
  n=$(grep -c '^frusta: ' "$T/err")
  [ "$n" -eq 1 ] && grep -q "^frusta: $2" "$T/err" && ok || { bad "$1: $n lines of frusta's, wanted one like '$2'"; cat "$T/err"; }
}
$MPI -np 1 "$F" render --builtin $S --out "$T/fail.png" : -np 1 "$F" render "$T/none.obj" $S --out "$T/fail.png" >/dev/null 2>"$T/err"
code=$?
[ $code -ne 0 ] && [ $code -ne 124 ] && ok || bad "a rank without its scene: exit $code"
one_line "a rank without its scene" "rank 1: .*none.obj"
[ ! -e "$T/fail.png" ] && ok || bad "a rank without its scene: an image was written"
$MPI -np 2 "$F" view --builtin >/dev/null 2>"$T/err"
[ $? -ne 0 ] && ok || bad "view under mpirun did not fail"
one_line "view under mpirun" "view runs as one process"
$MPI -np 2 "$F" render --builtin $S --shade nonsense --out "$T/fail.png" >/dev/null 2>"$T/err"
[ $? -ne 0 ] && ok || bad "a bad flag under mpirun did not fail"
one_line "a bad flag under mpirun" "--shade"

# a rank that dies mid-frame: the job stops within seconds
start=$(date +%s)
$MPI -np 2 "$F" render --builtin=materials --size 256x256 --shade path --spp 4096 --threads 1 --out "$T/dead.exr" \
  >/dev/null 2>"$T/err" &
J=$!
victim=""
for _ in $(seq 300); do
  for p in $(pgrep -f "frusta render --builtin=materials --size 256x256"); do
    tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=1' && victim=$p
  done
  [ -n "$victim" ] && break
  sleep 0.1
done
sleep 1
[ -n "$victim" ] && kill -KILL "$victim"
wait $J; code=$?
took=$(( $(date +%s) - start ))
[ -n "$victim" ] && [ $code -ne 0 ] && [ $code -ne 124 ] && [ $took -lt 60 ] && ok ||
  bad "a rank killed mid-frame: exit $code after ${took}s (rank 1: ${victim:-not found})"
one_line "a rank killed mid-frame" "stopped by the MPI launcher"
[ ! -e "$T/dead.exr" ] && ok || bad "a rank killed mid-frame: an image was written"

echo "cluster: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
