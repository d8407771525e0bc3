#!/usr/bin/env bash
# tests/install_check.sh -- owns the installation test: `cmake --install` into a fresh prefix, then from an
# empty directory the installed binary runs offline for a scene of the installed share/rbcontact (its mesh
# found there: the -info line names the installed copy), and an outside program (the installed example
# share/rbcontact/examples/online_loop.cpp) is built against the installed tree twice, with CMake's
# find_package(rbcontact) and with pkg-config, and solves online from that ROM file.
# Usage: install_check.sh BUILD_DIR
set -eu
build=$(cd "$1" && pwd)
t=$(mktemp -d "${TMPDIR:-/tmp}/rbc_install.XXXXXX")
trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cmake --install "$build" --prefix "$t/prefix" > "$t/install.log" || { cat "$t/install.log"; fail "cmake --install"; }
share="$t/prefix/share/rbcontact"
for f in runs/ring_on_block.opts meshes/ring_on_block.geo examples/online_loop.cpp scripts/plot_speed_error.py; do
  [ -f "$share/$f" ] || fail "not installed: share/rbcontact/$f"
done
for f in lib/cmake/rbcontact/rbcontactConfig.cmake lib/pkgconfig/rbcontact.pc include/rbcontact/reduced_model.hpp bin/rbcontact; do
  [ -e "$t/prefix/$f" ] || fail "not installed: $f"
done
echo "ok: installed tree"

mkdir "$t/run" && cd "$t/run"
"$t/prefix/bin/rbcontact" offline -options_file "$share/runs/ring_on_block.opts" -train_size 5 -rom rom.h5 -report off.json -info > offline.log 2>&1 \
  || { tail -20 offline.log; fail "installed rbcontact offline from an empty directory"; }
grep -q "mesh file meshes/ring_on_block.geo -> $t/prefix/bin/../share/rbcontact/meshes/ring_on_block.geo" offline.log \
  || { grep "mesh file" offline.log; fail "the installed binary did not use the installed mesh"; }
[ -f rom.h5 ] || fail "no ROM file"
echo "ok: installed binary, offline from an empty directory with the installed scene"

# an outside program with find_package(rbcontact)
mkdir "$t/app" && cat > "$t/app/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.18)
project(outside LANGUAGES C CXX)
find_package(rbcontact 0.1 REQUIRED)
add_executable(outside ${rbcontact_DATA_DIR}/examples/online_loop.cpp)
target_link_libraries(outside PRIVATE rbcontact::rbcontact)
CM
cmake -S "$t/app" -B "$t/app/build" -DCMAKE_PREFIX_PATH="$t/prefix" -DCMAKE_BUILD_TYPE=Release > "$t/app/cmake.log" 2>&1 || { tail -30 "$t/app/cmake.log"; fail "configure with find_package(rbcontact)"; }
cmake --build "$t/app/build" > "$t/app/build.log" 2>&1 || { tail -30 "$t/app/build.log"; fail "build with find_package(rbcontact)"; }
"$t/app/build/outside" -rom rom.h5 > cmake_app.log 2>&1 || { cat cmake_app.log; fail "the find_package program"; }
[ "$(grep -c 'iterations' cmake_app.log)" = 11 ] || { cat cmake_app.log; fail "the find_package program: 11 solves expected"; }
echo "ok: outside program with find_package(rbcontact): 11 online solves"

# the same with pkg-config
export PKG_CONFIG_PATH="$t/prefix/lib/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
mpicxx -std=c++17 -O2 $(pkg-config --cflags rbcontact) "$share/examples/online_loop.cpp" -o "$t/pc_app" $(pkg-config --libs rbcontact) > pc.log 2>&1 || { tail -30 pc.log; fail "build with pkg-config"; }
"$t/pc_app" -rom rom.h5 > pc_app.log 2>&1 || { cat pc_app.log; fail "the pkg-config program"; }
cmp -s <(grep iterations cmake_app.log | sed 's/time.*//') <(grep iterations pc_app.log | sed 's/time.*//') || fail "pkg-config and find_package programs differ"
echo "ok: outside program with pkg-config: the same 11 solves"
