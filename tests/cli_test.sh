#!/bin/sh
# The command line as a user meets it: exit codes, one-line errors, whole
# outputs or none. usage: cli_test.sh FRUSTA SHARED_DIR SOURCE_DIR
set -u
F="$1"; SHARED="$2"; SRC="$3"
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
fails=0; passes=0
ok() { passes=$((passes+1)); }
bad() { echo "FAIL: $*"; fails=$((fails+1)); }

# expect CODE CMD...: exit code CODE, and on failure exactly one line on stderr starting "frusta: "
expect() {
  want=$1; shift
  "$@" >"$T/out" 2>"$T/err"; got=$?
  if [ "$got" -ne "$want" ]; then bad "exit $got, wanted $want: $*"; cat "$T/err"; return; fi
  if [ "$want" -ne 0 ]; then
    lines=$(wc -l <"$T/err")
    if [ "$lines" -ne 1 ] || ! grep -q '^frusta: ' "$T/err"; then bad "not a one-line error ($lines lines): $*"; cat "$T/err"; return; fi
  fi
  ok
}

expect 2 "$F"
expect 2 "$F" frobnicate
expect 2 "$F" render --builtin
expect 2 "$F" render --builtin --out "$T/a.png" --size 0x0
expect 2 "$F" render --builtin --out "$T/a.png" --size 10
expect 2 "$F" render --builtin --out "$T/a.png" --fov 200
expect 2 "$F" render --builtin --out "$T/a.png" --eye 1,2
expect 2 "$F" render --builtin --out "$T/a.png" --shade fancy
expect 2 "$F" render --builtin --out "$T/a.bmp"
expect 2 "$F" render --builtin --out "$T/a.png" --bogus
expect 1 "$F" render "$T/missing.ply" --out "$T/a.png"
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 99999999\nproperty float x\nproperty float y\nproperty float z\nend_header\n' >"$T/liar.ply"
expect 1 "$F" render "$T/liar.ply" --out "$T/a.png"
printf 'garbage' >"$T/g.ply.zst"
expect 1 "$F" stats "$T/g.ply.zst"
[ ! -e "$T/a.png" ] && ok || bad "a failed render left an output file"
expect 1 "$F" render --builtin --size 32x24 --out "$T/nodir/a.png"
[ -z "$(ls "$T" | grep tmp)" ] && ok || bad "temporary file left behind"

for ext in png exr pfm; do
  expect 0 "$F" render --builtin --size 64x48 --shade shadows --out "$T/b.$ext"
  [ -s "$T/b.$ext" ] && ok || bad "no $ext written"
done
head -c 4 "$T/b.png" | od -c | grep -q 'P   N   G' && ok || bad "not a PNG"
# camera rays go as multi-frusta by default; --mft off traces them as streams
expect 0 "$F" render --builtin --size 64x48 --out "$T/e1.pfm"
grep -q 'shade=eyelight spp=1 tracer=frusta mode=mft ' "$T/out" && ok || bad "render: camera rays not as frusta"
expect 0 "$F" render --builtin --size 64x48 --mft off --out "$T/e2.pfm"
grep -q 'shade=eyelight spp=1 tracer=frusta mode=auto ' "$T/out" && ok || bad "render --mft off: not as streams"
head -c 2 "$T/b.pfm" | grep -q PF && ok || bad "not a PFM"

expect 2 "$F" bench --builtin --workload primary
expect 2 "$F" bench --builtin --workload nope --mode single
expect 2 "$F" bench --builtin --workload primary --mode packet99 --tracer frusta
expect 2 "$F" bench --builtin --workload primary --mode hybrid16 --threshold 17
expect 2 "$F" bench --builtin --workload primary --mode hybrid16 --mailbox maybe
expect 2 "$F" bench --builtin --workload primary --mode single --prefetch maybe
expect 0 "$F" bench --builtin --workload diffuse8 --mode single --prefetch off --size 32x32 --repeat 1
grep -q ' prefetch=off ' "$T/out" && ok || bad "bench does not report prefetch=off"
expect 0 "$F" bench --builtin --workload ao16 --mode hybrid16 --threshold 3 --packet-width 4 --size 32x32 --repeat 1
grep -q 'workload=ao16 tracer=frusta mode=hybrid16 ' "$T/out" && ok || bad "no hybrid16 line"
expect 2 "$F" bench --builtin --workload primary --mode single --threads 0
expect 0 "$F" bench --builtin --workload shadow --mode single --tracer both --size 64x64 --repeat 1
grep -q '^scene=builtin tris=[0-9]* workload=shadow tracer=frusta mode=single threads=[0-9]* rays=[0-9]* seconds=' "$T/out" && ok || bad "bench line format"
grep -q 'tracer=embree mode=single' "$T/out" && ok || bad "no embree line"
# a list of modes: each tracer runs the ones it has, interleaved
expect 0 "$F" bench --builtin --workload shadow --mode packet16,hybrid16,stream --tracer both --size 32x32 --repeat 2
[ "$(grep -c '^scene=' "$T/out")" = 4 ] && grep -q 'tracer=frusta mode=hybrid16 ' "$T/out" &&
  grep -q 'tracer=embree mode=stream ' "$T/out" && ok || bad "bench mode list"
expect 2 "$F" bench --builtin --workload shadow --mode packet16,stream --tracer frusta

# ray files: a small one written with perl (part of every Debian system)
perl -e 'my @r; for my $i (0..99) { push @r, pack("f<8", -0.5+$i*0.01, 5, 0.1, 0, -1, 0.001*$i, 0, 9**9**9) } print "RAYS0001", pack("Q<", 100), @r;' >"$T/r.rays"
expect 0 "$F" trace --builtin "$T/r.rays" --query closest --out "$T/f.hits"
expect 0 "$F" trace --builtin "$T/r.rays" --query closest --out "$T/e.hits" --tracer embree
expect 0 "$F" trace --builtin "$T/r.rays" --query any --out "$T/f.occl"
[ "$(head -c 8 "$T/f.hits")" = "HITS0001" ] && ok || bad "hits magic"
[ "$(stat -c %s "$T/f.hits")" -eq $((16 + 16 * 100)) ] && ok || bad "hits size"
[ "$(stat -c %s "$T/f.occl")" -eq $((16 + 100)) ] && ok || bad "occl size"
# agree by rayfile.md's rule, and hit something
agree() {
  perl -e 'open(A,"<",$ARGV[0]); open(B,"<",$ARGV[1]); binmode A; binmode B; read(A,$a,1e7); read(B,$b,1e7);
    my $n = unpack("Q<", substr($a,8,8)); my $bad = 0; my $hits = 0;
    for my $i (0..$n-1) { my ($t1) = unpack("f<", substr($a,16+16*$i,4)); my ($t2) = unpack("f<", substr($b,16+16*$i,4));
      my $m1 = $t1 > 1e38; my $m2 = $t2 > 1e38; $hits++ unless $m1;
      if ($m1 || $m2) { $bad++ unless $m1 && $m2; next }
      my $s = abs($t1) > 1 ? abs($t1) : 1; $bad++ if abs($t1-$t2) > 1e-4*$s; }
    exit($bad == 0 && $hits > 50 ? 0 : 1);' "$1" "$2"
}
agree "$T/f.hits" "$T/e.hits" && ok || bad "frusta and embree hit files disagree"
for m in packet8 packet16 hybrid16 auto raystream; do
  expect 0 "$F" trace --builtin "$T/r.rays" --query closest --out "$T/$m.hits" --mode $m
  agree "$T/$m.hits" "$T/e.hits" && ok || bad "frusta --mode $m and embree hit files disagree"
  expect 0 "$F" trace --builtin "$T/r.rays" --query any --out "$T/$m.occl" --mode $m
  cmp -s "$T/f.occl" "$T/$m.occl" && ok || bad "--mode $m occlusion differs from single rays"
done
expect 2 "$F" trace --builtin "$T/r.rays" --query any --out "$T/x.occl" --mode packet4
head -c 100 "$T/r.rays" >"$T/trunc.rays"
expect 1 "$F" trace --builtin "$T/trunc.rays" --query closest --out "$T/t.hits"
[ ! -e "$T/t.hits" ] && ok || bad "partial hit file"
expect 2 "$F" trace --builtin "$T/r.rays" --query nearest --out "$T/x.hits"
expect 1 "$F" trace --builtin "$T/none.rays" --query any --out "$T/x.occl"
expect 0 "$F" stats --builtin
expect 2 "$F" stats --builtin --workload nope
# Table V needs the counters build; without it, a clear error
if "$F" stats --builtin --workload ao16 --size 16x16 >"$T/out" 2>"$T/err"; then
  grep -q '^table5 scene=builtin workload=ao16' "$T/out" && ok || bad "table5 line"
else
  grep -q 'FRUSTA_COUNTERS' "$T/err" && ok || bad "stats --workload error message"
fi

# every ISA level this CPU has runs the command, with bit-identical answers;
# asking for one it lacks is an error, not a silent fallback
isas="scalar"
grep -qw avx2 /proc/cpuinfo && grep -qw fma /proc/cpuinfo && isas="$isas avx2"
grep -qw avx512f /proc/cpuinfo && grep -qw avx512vl /proc/cpuinfo && isas="$isas avx512"
for isa in $isas; do
  FRUSTA_ISA=$isa "$F" trace --builtin "$T/r.rays" --query closest --out "$T/$isa.hits" && ok || bad "FRUSTA_ISA=$isa"
  cmp -s "$T/scalar.hits" "$T/$isa.hits" && ok || bad "ISA $isa differs from scalar"
done
grep -qw avx512f /proc/cpuinfo || expect 1 env FRUSTA_ISA=avx512 "$F" stats --builtin
expect 1 env FRUSTA_ISA=sse9 "$F" stats --builtin

# multi-frusta: soft shadows render (filtered, against a reference), bench
# runs, bad values are usage errors
expect 0 "$F" render --builtin --size 48x32 --shade softshadow --out "$T/soft.png" --reference-out "$T/ref.png"
[ -s "$T/soft.png" ] && [ -s "$T/ref.png" ] && ok || bad "softshadow images"
grep -q '^mae_visibility=0\.' "$T/out" && ok || bad "softshadow mae line"
expect 0 "$F" render --builtin --size 32x32 --shade softshadow --filter off --light-sets spread --light-samples 32 --out "$T/s2.pfm"
expect 2 "$F" render --builtin --shade softshadow --light-samples 20 --out "$T/s3.png"
expect 2 "$F" render --builtin --shade softshadow --filter maybe --out "$T/s3.png"
expect 2 "$F" render --builtin --shade softshadow --light-sets grid --out "$T/s3.png"
expect 2 "$F" render --builtin --shade softshadow --reference-out "$T/r.bmp" --out "$T/s3.png"
[ ! -e "$T/s3.png" ] && ok || bad "a refused render left an output file"
# Whitted: MTL mirrors and glass, large packets, their flags
expect 0 "$F" render "$SHARED/scenes/museum/museum.obj.zst" --size 64x48 --shade whitted --out "$T/w.png"
[ -s "$T/w.png" ] && grep -q 'mirror_prims=[1-9]' "$T/out" && grep -q 'tracer=mft' "$T/out" && ok || bad "whitted museum render"
expect 0 "$F" render "$SHARED/scenes/museum/museum.obj.zst" --size 64x48 --shade whitted --mft off --out "$T/w.png"
grep -q 'tracer=packet16x16/ranged/off' "$T/out" && ok || bad "whitted --mft off: large packets"
expect 0 "$F" render --builtin=sphereflake --size 32x32 --shade whitted --out "$T/w.png"
grep -q 'tracer=packet16x16' "$T/out" && ok || bad "whitted with spheres: large packets"
expect 2 "$F" render --builtin --shade whitted --mft on --packet 8 --out "$T/w3.png"
expect 0 "$F" render --builtin --size 40x40 --shade whitted --mirror all --depth 2 --packet 8 --traversal partition --cull corners --out "$T/w2.pfm"
expect 2 "$F" render --builtin --shade whitted --mirror no_such --out "$T/w3.png"
expect 2 "$F" render --builtin --shade whitted --glass all --out "$T/w3.png"
expect 2 "$F" render --builtin --shade whitted --depth 0 --out "$T/w3.png"
expect 2 "$F" render --builtin --shade whitted --packet 12 --out "$T/w3.png"
expect 2 "$F" render --builtin --shade whitted --traversal sideways --out "$T/w3.png"
expect 2 "$F" render --builtin --shade whitted --cull maybe --out "$T/w3.png"
[ ! -e "$T/w3.png" ] && ok || bad "a failed whitted render left an output file"
expect 0 "$F" bench --builtin --size 64x64 --workload whitted --mode packet4x4 --traversal masked --cull planes --repeat 1 --mirror all
grep -q 'mode=packet4x4/masked/planes' "$T/out" && ok || bad "bench packet4x4 line"
expect 0 "$F" bench "$SHARED/scenes/museum/museum.obj.zst" --size 64x64 --workload whitted --mode packet32x32,stream --tracer both --repeat 1
grep -q 'workload=whitted tracer=embree mode=stream ' "$T/out" && grep -q 'workload=whitted tracer=frusta mode=packet32x32' "$T/out" && ok || bad "bench whitted both tracers"
# analytic spheres: the sphereflake; multi-frusta tracing refuses them
expect 0 "$F" render --builtin=sphereflake --size 48x48 --shade whitted --glass flake --out "$T/sf.png"
[ -s "$T/sf.png" ] && grep -q 'glass_prims=820' "$T/out" && ok || bad "sphereflake whitted render"
expect 0 "$F" bench --builtin=sphereflake --size 32x32 --workload whitted --mode all --tracer both --repeat 1
grep -q 'scene=sphereflake.*tracer=embree' "$T/out" && ok || bad "sphereflake bench with embree"
expect 2 "$F" bench --builtin=sphereflake --size 32x32 --workload primary --mode mft --repeat 1
expect 2 "$F" render --builtin=cubes --out "$T/sf2.png"
[ ! -e "$T/sf2.png" ] && ok || bad "an unknown built-in scene left an output file"
expect 0 "$F" bench --builtin --size 32x32 --workload soft16 --mode mft --repeat 1 --mft-leaf 8 --shrink off --light-sets cells
grep -q 'mode=mft' "$T/out" && ok || bad "bench mft line"
expect 0 "$F" bench --builtin --size 32x32 --workload soft16 --mode mft --repeat 1 --shrink corners
grep -q 'shrink=corners' "$T/out" && ok || bad "bench --shrink corners"
expect 2 "$F" bench --builtin --size 32x32 --workload soft16 --mode mft --repeat 1 --shrink intervals
expect 0 "$F" bench --builtin --size 32x32 --workload soft16 --mode mft --repeat 1 --mft-fallback off
grep -q ' fallback=off' "$T/out" && ok || bad "bench mft fallback off"
expect 2 "$F" bench --builtin --workload soft16 --mode mft --mft-fallback maybe
expect 0 "$F" bench --builtin --size 32x32 --workload soft16 --mode mft --repeat 1 --mft-shaft off
expect 2 "$F" bench --builtin --workload soft16 --mode mft --mft-shaft maybe
expect 2 "$F" bench --builtin --workload soft16 --mode mft --mft-leaf 16
expect 2 "$F" bench --builtin --workload soft16 --mode mft --corner-rays sometimes

# the path tracer: images (PNG tone-mapped, EXR linear, the AOVs), bad input
expect 0 "$F" render --builtin=materials --shade path --size 48x24 --spp 4 --out "$T/p.exr" --aov
[ -s "$T/p.exr" ] && [ -s "$T/p.albedo.exr" ] && [ -s "$T/p.normal.exr" ] && ok || bad "path render with --aov"
grep -q 'shade=path spp=4 ' "$T/out" && ok || bad "path render line"
expect 0 "$F" render --builtin=materials --shade path --size 48x24 --spp 2 --env "$SHARED/hdri/studio.exr" --env-rotate 90 \
  --aperture 0.1 --focus 8 --sampler sobol --max-depth 5 --lights env,point --exposure 1 --out "$T/p.png"
[ -s "$T/p.png" ] && grep -q 'sampler=sobol lights=env,point env=' "$T/out" && ok || bad "path render with an HDRI"
expect 0 "$F" bench --builtin=materials --size 32x32 --spp 2 --workload path --mode auto,stream --tracer both --repeat 1
grep -q 'workload=path tracer=frusta mode=auto' "$T/out" && grep -q 'workload=path tracer=embree mode=stream' "$T/out" \
  && grep -q 'stages tracer=frusta mode=auto workload=path .* outside_tracing=' "$T/out" && ok || bad "bench path both tracers"
expect 0 "$F" render --builtin=materials --shade path --size 32x16 --spp 2 --mode hybrid16 --out "$T/m1.pfm"
grep -q 'tracer=frusta mode=hybrid16 ' "$T/out" && ok || bad "render path --mode"
expect 0 "$F" render --builtin=materials --shade path --size 32x16 --spp 2 --mode single --out "$T/m2.pfm"
cmp -s "$T/m1.pfm" "$T/m2.pfm" && ok || bad "render path: the image depends on the trace mode"
expect 0 "$F" render --builtin=materials --shade path --size 32x16 --spp 2 --tracer embree --out "$T/m3.pfm"
grep -q 'tracer=embree mode=stream ' "$T/out" && ok || bad "render path --tracer embree"
expect 2 "$F" render --builtin --shade eyelight --mode single --out "$T/q.png"
expect 2 "$F" render --builtin --shade path --mode single --tracer embree --out "$T/q.png"
expect 1 "$F" render --builtin --shade path --env "$T/missing.exr" --out "$T/q.png"
printf 'not an exr at all' >"$T/bad.exr"
expect 1 "$F" render --builtin --shade path --env "$T/bad.exr" --out "$T/q.png"
printf '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n' >"$T/liar.hdr"
expect 1 "$F" render --builtin --shade path --env "$T/liar.hdr" --out "$T/q.png"
head -c 300 "$SHARED/hdri/city.exr" >"$T/cut.exr"
expect 1 "$F" render --builtin --shade path --env "$T/cut.exr" --out "$T/q.png"
# OpenEXR headers that would have the library take gigabytes before any
# check: a channel list longer than its attribute claims, a data window
# 16 million pixels wide; refused before OpenEXR reads them
tail -c +2 "$SRC/tests/fuzz/corpus/b566163560a48d3ea4d3bceabb3d804d633f6c3c" >"$T/chlist.exr"
expect 1 "$F" render --builtin --shade path --env "$T/chlist.exr" --out "$T/q.png"
at=$(grep -obUa dataWindow "$T/p.exr" | head -1 | cut -d: -f1)
cp "$T/p.exr" "$T/wide.exr"
printf '\007\000\377\000' | dd of="$T/wide.exr" bs=1 seek=$((at + 29)) conv=notrunc 2>/dev/null
expect 1 "$F" render --builtin --shade path --env "$T/wide.exr" --out "$T/q.png"
grep -q 'out of range' "$T/err" && ok || bad "a 16M-pixel-wide EXR: $(cat "$T/err")"
expect 2 "$F" render --builtin --shade path --spp 0 --out "$T/q.png"
expect 2 "$F" render --builtin --shade path --aperture -1 --out "$T/q.png"
expect 2 "$F" render --builtin --shade path --max-depth 0 --out "$T/q.png"
expect 2 "$F" render --builtin --shade path --env-color 1,nan,1 --out "$T/q.png"
expect 2 "$F" render --builtin --shade path --env-color -1,1,1 --out "$T/q.png"
expect 2 "$F" render --builtin --shade path --lights sun --out "$T/q.png"
expect 2 "$F" render --builtin --shade path --sampler halton --out "$T/q.png"
expect 2 "$F" render --builtin --shade path --env "$SHARED/hdri/city.exr" --env-color 1,1,1 --out "$T/q.png"
expect 2 "$F" bench --builtin --workload path --mode auto --spp 0
[ ! -e "$T/q.png" ] && ok || bad "a failed path render left an output file"

# scene files: meshes, materials, camera, lights and settings; flags win; errors name the key
mkdir -p "$T/sc/sub" "$T/out_of"
printf 'ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n-1 0 -1\n1 0 -1\n1 0 1\n-1 0 1\n3 0 2 1\n3 0 3 2\n' >"$T/sc/sub/floor.ply"
cp "$T/sc/sub/floor.ply" "$T/out_of/floor.ply"
cat >"$T/sc/s.json" <<'JSON'
{
  "meshes": [ { "file": "sub/floor.ply", "material": "gold" },
              { "file": "sub/floor.ply", "scale": 0.5, "translate": [0, 0.5, 0], "material": "paint" } ],
  "materials": { "gold": { "type": "metal", "preset": "gold", "roughness": 0.3 },
                 "paint": { "type": "carpaint", "color": [0.1, 0.2, 0.6] } },
  "camera": { "eye": [0, 2, 3], "at": [0, 0, 0], "fov": 50 },
  "environment": { "color": [0.8, 0.9, 1.0] },
  "lights": { "point": { "position": [0, 3, 0], "intensity": [20, 20, 20] } },
  "render": { "shade": "path", "size": [40, 30], "spp": 3, "sampler": "sobol", "seed": 9 }
}
JSON
expect 0 "$F" render "$T/sc/s.json" --out "$T/s1.png"
grep -q 'shade=path spp=3 ' "$T/out" && grep -q 'size=40x30' "$T/out" && grep -q 'sampler=sobol lights=env,point env=constant' "$T/out" \
  && grep -q 'tris=4 ' "$T/out" && ok || bad "scene file settings"
expect 0 "$F" render "$T/sc/s.json" --out "$T/s2.png" --spp 2 --size 20x10 --shade eyelight
grep -q 'size=20x10 shade=eyelight' "$T/out" && ok || bad "flags override a scene file"
bad_scene() { # bad_scene EXPECTED_TEXT JSON: a one-line error naming the key
  printf '%s' "$2" >"$T/sc/b.json"
  expect 1 "$F" render "$T/sc/b.json" --out "$T/sb.png"
  grep -q -- "$1" "$T/err" && ok || { bad "scene file error lacks '$1'"; cat "$T/err"; }
}
bad_scene 'line 1: not valid JSON' '{"meshes": ['
bad_scene 'meshes: expected an array' '{"meshes": {}}'
bad_scene 'meshes\[0\].colour: unknown key' '{"meshes": [{"file": "sub/floor.ply", "colour": 1}]}'
bad_scene 'meshes\[0\].file' '{"meshes": [{"file": "../out_of/floor.ply"}]}'
bad_scene 'meshes\[0\].file' '{"meshes": [{"file": "/etc/passwd"}]}'
bad_scene 'meshes\[0\].file' '{"meshes": [{"file": "sub/none.ply"}]}'
bad_scene 'materials.m.type' '{"meshes": [{"file": "sub/floor.ply"}], "materials": {"m": {"type": "velvet"}}}'
bad_scene 'materials.m.ior: expected a number' '{"meshes": [{"file": "sub/floor.ply"}], "materials": {"m": {"type": "glass", "ior": "high"}}}'
bad_scene 'materials.m.preset' '{"meshes": [{"file": "sub/floor.ply"}], "materials": {"m": {"type": "metal", "preset": "unobtainium"}}}'
bad_scene "meshes\[0\].material: 'x' is not" '{"meshes": [{"file": "sub/floor.ply", "material": "x"}]}'
bad_scene 'camera.fov' '{"meshes": [{"file": "sub/floor.ply"}], "camera": {"fov": 500}}'
bad_scene 'render.size' '{"meshes": [{"file": "sub/floor.ply"}], "render": {"size": [0, 5]}}'
bad_scene 'environment.file' '{"meshes": [{"file": "sub/floor.ply"}], "environment": {"file": "/etc/passwd"}}'
bad_scene 'lights.area' '{"meshes": [{"file": "sub/floor.ply"}], "lights": {"area": {"corner": [0, 1, 0]}}}'
[ ! -e "$T/sb.png" ] && ok || bad "a failed scene file left an output file"
# the repository's scene files for the shared scenes all load and render
# (the root is where the shared folder really lies, should it be a link)
if [ -d "$SHARED/scenes" ]; then
  root=$(cd "$SHARED/.." && pwd -P)
  [ -L "$SHARED" ] && root=$(cd "$(dirname "$(readlink -f "$SHARED")")" && pwd -P)
  for f in "$SRC"/scenes/*.json; do
    expect 0 "$F" render "$f" --scene-root "$root" --size 16x16 --spp 1 --out "$T/sf.png"
  done
else
  echo "cli: $SHARED/scenes absent: the scene files of scenes/ not rendered"
fi
printf '{"meshes": [{"file": "sub/floor.ply"}], "lights": {}}' >"$T/sc/nolamp.json"
expect 0 "$F" render "$T/sc/nolamp.json" --shade path --size 8x8 --spp 1 --out "$T/nl.png"
grep -q 'lights=env env=' "$T/out" && ok || bad "an empty lights object: the environment alone"
# --scene-root widens where a scene file may reach
printf '{"meshes": [{"file": "../out_of/floor.ply"}]}' >"$T/sc/up.json"
expect 1 "$F" render "$T/sc/up.json" --out "$T/u.png" --size 16x16
expect 0 "$F" render "$T/sc/up.json" --scene-root "$T" --out "$T/u.png" --size 16x16
expect 1 "$F" render "$T/sc/up.json" --scene-root "$T/sc" --out "$T/u.png" --size 16x16

# help, version and the manual page, all from the one flag table
for c in render bench trace stats; do
  expect 0 "$F" $c --help
  grep -q "^usage: frusta $c " "$T/out" && grep -q '^  --' "$T/out" && ok || bad "$c --help"
  expect 0 "$F" help $c
done
expect 0 "$F" bench --help
grep -q -- '--embree-flag best|hint|coherent|incoherent' "$T/out" && ok || bad "bench --help lacks --embree-flag"
expect 0 "$F" --help
grep -q 'render' "$T/out" && grep -q 'stats' "$T/out" && ok || bad "frusta --help"
expect 0 "$F" --version
grep -q '^frusta [0-9]*\.[0-9]* (' "$T/out" && ok || bad "--version"
expect 2 "$F" help frobnicate
expect 2 "$F" render --builtin --out "$T/h.png" --threads
expect 2 "$F" trace --builtin --mode single
expect 0 "$F" help --man
cmp -s "$T/out" "$SRC/docs/frusta.1" && ok || bad "docs/frusta.1 is not what 'frusta help --man' prints (regenerate it)"
# bench names Embree's context flag and packing, and takes them fixed
expect 0 "$F" bench --builtin --size 32x32 --workload ao16 --mode packet16 --tracer embree --repeat 1
grep -q 'tracer=embree mode=packet16 .* flag=[a-z]* packing=[a-z]*$' "$T/out" && ok || bad "bench embree line lacks flag and packing"
expect 0 "$F" bench --builtin --size 32x32 --workload ao16 --mode stream --tracer embree --repeat 1 --embree-flag coherent --embree-packing samples
grep -q 'flag=coherent packing=samples$' "$T/out" && ok || bad "bench --embree-flag/--embree-packing"
expect 2 "$F" bench --builtin --workload ao16 --mode stream --tracer embree --embree-flag sometimes
expect 0 "$F" bench --builtin --size 32x32 --workload primary,shadow --mode single --repeat 1
[ "$(grep -c '^scene=' "$T/out")" = 2 ] && ok || bad "bench --workload list"

echo "cli: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
