#!/usr/bin/env bash
# tests/install_check.sh -- owns the installation test: `cmake --install` into a fresh prefix, then from an
# empty directory the installed binary runs offline for a scene of the installed share/rbcontact (its mesh
# found there: the -info line names the installed copy), and an outside program (the installed example
# share/rbcontact/examples/online_loop.cpp) is built against the installed tree twice, with CMake's
# find_package(rbcontact) and with pkg-config, and solves online from that ROM file; the installed Python
# module (when built) solves 100 radii from it. The prefix has a space in its name (the pkg-config file escapes it:
# its output is used through eval, as make would), and the pkg-config file of an absolute libdir with spaces
# (cmake/pkgconfig.cmake run as a script) builds the same program.
# Usage: install_check.sh BUILD_DIR
set -eu
build=$(cd "$1" && pwd)
t=$(mktemp -d "${TMPDIR:-/tmp}/rbc_install.XXXXXX")
trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

P="$t/pre fix" # a space in the prefix
cmake --install "$build" --prefix "$P" > "$t/install.log" || { cat "$t/install.log"; fail "cmake --install"; }
share="$P/share/rbcontact"
for f in runs/ring_on_block.opts meshes/ring_on_block.geo examples/online_loop.cpp scripts/plot_speed_error.py; do
  [ -f "$share/$f" ] || fail "not installed: share/rbcontact/$f"
done
for f in lib/cmake/rbcontact/rbcontactConfig.cmake lib/pkgconfig/rbcontact.pc include/rbcontact/reduced_model.hpp bin/rbcontact; do
  [ -e "$P/$f" ] || fail "not installed: $f"
done
echo "ok: installed tree"

mkdir "$t/run" && cd "$t/run"
"$P/bin/rbcontact" offline -options_file "$share/runs/ring_on_block.opts" -train_size 5 -rom rom.h5 -report off.json -info > offline.log 2>&1 \
  || { tail -20 offline.log; fail "installed rbcontact offline from an empty directory"; }
grep -q "mesh file meshes/ring_on_block.geo -> $P/bin/../share/rbcontact/meshes/ring_on_block.geo" offline.log \
  || { grep "mesh file" offline.log; fail "the installed binary did not use the installed mesh"; }
[ -f rom.h5 ] || fail "no ROM file"
echo "ok: installed binary, offline from an empty directory with the installed scene"
# a missing mesh: the installed binary names where it looked, and that is not the build machine's checkout
src=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$build/CMakeCache.txt")
"$P/bin/rbcontact" fom -options_file "$share/runs/ring_on_block.opts" -mesh_file meshes/nosuch.geo > missing.log 2>&1 && fail "a missing mesh was accepted"
grep -q "Mesh file 'meshes/nosuch.geo' not found" missing.log || { cat missing.log; fail "no clear message for a missing mesh"; }
if [ -n "$src" ] && grep "looked in" missing.log | grep -qF "$src"; then grep "looked in" missing.log; fail "the installed binary looks in the source tree $src"; fi
echo "ok: the installed binary does not look in the source tree"

# an outside program with find_package(rbcontact)
mkdir "$t/app" && cat > "$t/app/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.18)
project(outside LANGUAGES C CXX)
find_package(rbcontact 0.1 REQUIRED)
add_executable(outside ${rbcontact_DATA_DIR}/examples/online_loop.cpp)
target_link_libraries(outside PRIVATE rbcontact::rbcontact)
add_executable(outside_pipeline ${rbcontact_DATA_DIR}/examples/offline_online.cpp)
target_link_libraries(outside_pipeline PRIVATE rbcontact::rbcontact)
CM
cmake -S "$t/app" -B "$t/app/build" -DCMAKE_PREFIX_PATH="$P" -DCMAKE_BUILD_TYPE=Release > "$t/app/cmake.log" 2>&1 || { tail -30 "$t/app/cmake.log"; fail "configure with find_package(rbcontact)"; }
cmake --build "$t/app/build" > "$t/app/build.log" 2>&1 || { tail -30 "$t/app/build.log"; fail "build with find_package(rbcontact)"; }
"$t/app/build/outside" -rom rom.h5 > cmake_app.log 2>&1 || { cat cmake_app.log; fail "the find_package program"; }
[ "$(grep -c 'iterations' cmake_app.log)" = 11 ] || { cat cmake_app.log; fail "the find_package program: 11 solves expected"; }
[ "$(grep -c 'force [0-9]' cmake_app.log)" = 11 ] || { cat cmake_app.log; fail "the find_package program: the online contact force of each solve expected"; }
"$t/app/build/outside" -rom rom.h5 -rom_kacanov_monitr > cmake_typo.log 2>&1 || { cat cmake_typo.log; fail "the find_package program with a misspelled option"; }
grep -q "^Option left: name:-rom_kacanov_monitr" cmake_typo.log || { tail -3 cmake_typo.log; fail "the example did not name the misspelled option -rom_kacanov_monitr (PetscOptionsLeft)"; }
! grep -q "^Option left" cmake_app.log || { grep "^Option left" cmake_app.log; fail "the example named options left without a misspelling"; }
echo "ok: outside program with find_package(rbcontact): 11 online solves with their contact force; a misspelled option named"

# an outside program running the whole pipeline through the library (RunOffline, RunValidation,
# ReducedModel) for the installed scene, its mesh found through RBC_DATA_DIR = the installed share
mkdir "$t/pipe" && cd "$t/pipe"
RBC_DATA_DIR="$share" "$t/app/build/outside_pipeline" -options_file "$share/runs/ring_on_block.opts" -sizes 3,5 -test_size 4 -info > pipe.log 2>&1 \
  || { tail -20 pipe.log; fail "the find_package pipeline program (offline, validate, online through the library)"; }
grep -q "mesh file meshes/ring_on_block.geo -> $share/meshes/ring_on_block.geo" pipe.log || { grep "mesh file" pipe.log; fail "the pipeline program did not use the installed mesh"; }
[ -f rom_train3.h5 ] && [ -f rom_train5.h5 ] || fail "the pipeline program wrote no ROM files"
[ "$(grep -c '^train [35]: .* online force at the defaults [0-9]' pipe.log)" = 2 ] || { grep -v '^\[' pipe.log | tail; fail "the pipeline program: two trained models with their errors and online force expected"; }
# the larger training set must not be worse (the u error of 5 radii below that of 3)
awk '/^train 3:/{a=$12} /^train 5:/{b=$12} END{exit !(a+0 > 0 && b+0 > 0 && b+0 < a+0)}' pipe.log || { grep '^train' pipe.log; fail "the pipeline program: u error of 5 training radii not below that of 3"; }
echo "ok: outside program with find_package(rbcontact): offline, validate and online through the library ($(grep -c '^train' pipe.log) models)"
cd "$t/run"

# the same with pkg-config: the prefix's space escaped in its output ("-I/tmp/.../pre\ fix/..."), read back through eval
export PKG_CONFIG_PATH="$P/lib/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
flags=$(pkg-config --cflags --libs rbcontact) || fail "pkg-config --cflags --libs rbcontact"
case "$flags" in *"-I${P// /\\ }/lib/pkgconfig/../../include "*) ;; *) fail "pkg-config --cflags: no escaped include directory of the prefix in: $flags" ;; esac
eval "mpicxx -std=c++17 -O2 \"\$share/examples/online_loop.cpp\" -o \"\$t/pc_app\" $flags" > pc.log 2>&1 || { tail -30 pc.log; fail "build with pkg-config"; }
"$t/pc_app" -rom rom.h5 > pc_app.log 2>&1 || { cat pc_app.log; fail "the pkg-config program"; }
cmp -s <(grep iterations cmake_app.log | sed 's/time.*//') <(grep iterations pc_app.log | sed 's/time.*//') || fail "pkg-config and find_package programs differ"
# an absolute libdir (written as it is: it had the prefix prepended, "${prefix}//opt/lib", and its spaces unescaped)
src_dir=$(cd "$(dirname "$0")/.." && pwd)
mkdir "$t/pc_abs"
cmake -DRBC_PC_IN="$src_dir/share/rbcontact.pc.in" -DRBC_PC_OUT="$t/pc_abs/rbcontact.pc" -DCMAKE_INSTALL_PREFIX="$P" -DCMAKE_INSTALL_LIBDIR="$P/lib" \
  -DPROJECT_VERSION=0 -P "$src_dir/cmake/pkgconfig.cmake" || fail "cmake/pkgconfig.cmake with an absolute libdir"
grep -qxF "libdir=${P// /\\ }/lib" "$t/pc_abs/rbcontact.pc" || { grep dir= "$t/pc_abs/rbcontact.pc"; fail "absolute libdir: not written as it is, its space escaped"; }
flags=$(PKG_CONFIG_PATH="$t/pc_abs:$PKG_CONFIG_PATH" pkg-config --cflags --libs rbcontact) || fail "pkg-config with the absolute libdir's file"
eval "mpicxx -std=c++17 -O2 \"\$share/examples/online_loop.cpp\" -o \"\$t/pc_abs_app\" $flags" > pc_abs.log 2>&1 || { tail -30 pc_abs.log; fail "build with the absolute libdir's pkg-config file"; }
"$t/pc_abs_app" -rom rom.h5 > pc_abs_app.log 2>&1 && cmp -s <(grep iterations pc_app.log | sed 's/time.*//') <(grep iterations pc_abs_app.log | sed 's/time.*//') \
  || fail "the absolute libdir's pkg-config program differs"
# a path the file cannot quote: refused, naming it
cmake -DRBC_PC_IN="$src_dir/share/rbcontact.pc.in" -DRBC_PC_OUT="$t/pc_abs/bad.pc" -DCMAKE_INSTALL_PREFIX="$t/it's" -DCMAKE_INSTALL_LIBDIR="$t/it's/lib" \
  -DPROJECT_VERSION=0 -P "$src_dir/cmake/pkgconfig.cmake" > pc_bad.log 2>&1 && fail "a quote in an absolute libdir was accepted"
tr -s ' \n' ' ' < pc_bad.log | grep -qF "CMAKE_INSTALL_PREFIX '$t/it's': the pkg-config file cannot hold a quote" || { cat pc_bad.log; fail "no clear message for a quote in the prefix"; }
echo "ok: outside program with pkg-config (a prefix with a space, an absolute libdir): the same 11 solves"

# the installed Python module (when the build has it): 100 radii from the same ROM file, the forces of the
# C++ program at its 11 radii
pydir="$P/lib/python3/dist-packages"
if [ -d "$build/python/rbcontact" ]; then
  [ -f "$pydir/rbcontact/__init__.py" ] && ls "$pydir/rbcontact"/_rbcontact*.so > /dev/null 2>&1 || fail "not installed: lib/python3/dist-packages/rbcontact"
  grep -o 'force [0-9.e+-]*' cmake_app.log | awk '{print $2}' > cpp_forces.txt
  PYTHONPATH="$pydir" /usr/bin/python3 - <<'PY' > py.log 2>&1 || { cat py.log; fail "the installed Python module"; }
import numpy as np, rbcontact
assert rbcontact.__file__.startswith(__import__("os").environ["PYTHONPATH"]), rbcontact.__file__
m = rbcontact.ReducedModel("rom.h5")
(name, lo, hi), = m.parameters
f = m.contact_forces(np.linspace(lo, hi, 100))
assert f.shape == (100,) and np.all(np.isfinite(f)) and np.all(f > 0), f
# online_loop.cpp's 11 radii: min + k (max - min) / 10
g = m.contact_forces(np.array([(1 - k / 10) * lo + (k / 10) * hi for k in range(11)]))
cpp = np.loadtxt("cpp_forces.txt")
assert np.allclose(g, cpp, rtol=1e-6, atol=0), (g, cpp)  # the C++ program prints 7 digits
print("forces", f.min(), f.max())
PY
  echo "ok: the installed Python module: 100 contact forces, the C++ program's at its 11 radii"
fi
