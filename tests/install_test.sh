#!/bin/sh
# frusta installed as a user installs it: `cmake --install` into a fresh
# prefix puts the shared library (with its SONAME), the static one,
# frusta.h alone, the command, its manual page, frusta.pc and the CMake
# package there; every example program builds against it from outside the
# build tree through pkg-config and through find_package(frusta) (one also
# statically), and runs.
# usage: install_test.sh BUILD_DIR SOURCE_DIR
set -u
B="$1"; SRC="$2"
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
fails=0; passes=0
ok() { passes=$((passes+1)); }
bad() { echo "FAIL: $*"; fails=$((fails+1)); }
P="$T/prefix"
cmake --install "$B" --prefix "$P" >"$T/install.log" 2>&1 || { bad "cmake --install failed"; cat "$T/install.log"; }
LIB=$(dirname "$(find "$P" -name libfrusta.a | head -1)")
for f in "$P/include/frusta.h" "$P/bin/frusta" "$LIB/libfrusta.a" "$LIB/libfrusta.so" "$LIB/pkgconfig/frusta.pc" \
         "$LIB/cmake/frusta/frustaConfig.cmake" "$P/share/man/man1/frusta.1"; do
  [ -e "$f" ] && ok || bad "not installed: $f"
done
[ "$(ls "$P/include")" = "frusta.h" ] && ok || bad "the include folder holds more than frusta.h: $(ls "$P/include")"
readelf -d "$LIB/libfrusta.so" | grep -q 'SONAME.*libfrusta\.so\.0' && ok || bad "libfrusta.so has no SONAME libfrusta.so.0"
"$P/bin/frusta" --version >/dev/null && ok || bad "the installed command does not run"

# pkg-config, shared and static; each example checks its own answer
EXAMPLES="$(cd "$SRC" && pwd)/examples"
export PKG_CONFIG_PATH="$LIB/pkgconfig"
for EX in "$EXAMPLES"/*.c; do
  name=$(basename "$EX" .c)
  if cc "$EX" $(pkg-config --cflags --libs frusta) -lm -o "$T/${name}_shared" 2>"$T/cc.log"; then
    LD_LIBRARY_PATH="$LIB" "$T/${name}_shared" >/dev/null && ok || bad "$name built through pkg-config does not run"
  else
    bad "$name does not build through pkg-config"; cat "$T/cc.log"
  fi
done
EX="$EXAMPLES/trace_one_ray.c"
if cc "$EX" $(pkg-config --cflags frusta) "$LIB/libfrusta.a" $(pkg-config --static --libs-only-l frusta | sed 's/-lfrusta //') \
     -o "$T/one_static" 2>"$T/cc.log"; then
  "$T/one_static" >/dev/null && ok || bad "the example linked statically does not run"
  ldd "$T/one_static" | grep -q libfrusta && bad "the static build still needs libfrusta.so" || ok
else
  bad "the example does not link statically through pkg-config --static"; cat "$T/cc.log"
fi

# CMake: find_package(frusta) and frusta::frusta, every example
if cmake -S "$SRC/tests/install_consumer" -B "$T/consumer" -DCMAKE_PREFIX_PATH="$P" -DEXAMPLES="$EXAMPLES" >"$T/cm.log" 2>&1 &&
   cmake --build "$T/consumer" >>"$T/cm.log" 2>&1; then
  for EX in "$EXAMPLES"/*.c; do
    name=$(basename "$EX" .c)
    LD_LIBRARY_PATH="$LIB" "$T/consumer/$name" >/dev/null && ok || bad "$name built through CMake does not run"
  done
else
  bad "the examples do not build through find_package(frusta)"; tail -20 "$T/cm.log"
fi

# the Python module, where it was built: installed under the prefix, it
# imports in Debian's python3 and traces
if [ -d "$B/python/frusta" ]; then
  PY=$(find "$P" -name __init__.py -path '*frusta*' | head -1)
  if [ -n "$PY" ]; then
    (cd "$T" && PYTHONPATH="$(dirname "$(dirname "$PY")")" /usr/bin/python3 -c "
import numpy as np, frusta
s = frusta.Scene(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), np.array([[0, 1, 2]]))
h = s.intersect(np.array([[0.2, 0.2, 1]], np.float32), np.array([[0, 0, -1]], np.float32))
assert h.prim[0] == 0 and abs(h.t[0] - 1) < 1e-6
") && ok || bad "the installed Python module does not import or trace"
  else
    bad "the Python module was built but not installed"
  fi
fi
echo "install: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
