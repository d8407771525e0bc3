#!/usr/bin/env bash
# tests/makefile_petsc_check.sh -- owns the check of Makefile.petsc, the build for users with their own PETSc/SLEPc
# (docs/build.md "Makefile.petsc"), without the minutes of a whole build (the suite's budget): against the PETSc and
# SLEPc that CMake found (pkg-config), its `info` names the sources the CMake build compiles and the project's version;
# it compiles, into a fresh BUILD, the objects that need each outside header (SLEPc: provenance.cpp, HDF5: rom_file.cpp,
# METIS: partition.cpp) with the git commit in the provenance and header dependencies in the .d files; a missing
# PETSC_DIR or SLEPC_DIR, or one that is not an installation, stops make with a message naming it. A whole build was
# measured by hand (docs/build.md).
# Usage: makefile_petsc_check.sh SOURCE_DIR
set -eu
src=$(cd "$1" && pwd)
t=$(mktemp -d "${TMPDIR:-/tmp}/rbc_makefile_petsc.XXXXXX")
trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

petsc=$(pkg-config --variable=prefix PETSc) || fail "pkg-config finds no PETSc"
slepc=$(pkg-config --variable=prefix SLEPc) || fail "pkg-config finds no SLEPc"
mk=(make --no-print-directory -f "$src/Makefile.petsc" PETSC_DIR="$petsc" SLEPC_DIR="$slepc" BUILD="$t/b")

# info: the sources are those of CMakeLists.txt's globs (src/*/*.cpp, the apps apart), the version its project()'s
"${mk[@]}" info > "$t/info" || { cat "$t/info"; fail "make -f Makefile.petsc info"; }
want_lib=$(cd "$src" && ls src/*/*.cpp | grep -v '^src/apps/' | xargs -n1 basename | tr '\n' ' ' | sed 's/ $//')
want_app=$(cd "$src" && ls src/apps/*.cpp | xargs -n1 basename | tr '\n' ' ' | sed 's/ $//')
got=$(sed -n 's/^sources *= //p' "$t/info")
[ "$got" = "$want_lib | apps: $want_app" ] || fail "info's sources differ from src/*/*.cpp:
 got:  $got
 want: $want_lib | apps: $want_app"
version=$(sed -n 's/^project(rbcontact VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")
grep -q "^RBC_VERSION = $version\$" "$t/info" || { grep RBC_VERSION "$t/info"; fail "info's version is not CMakeLists.txt's $version"; }
grep -q "^PETSC_DIR   = $petsc " "$t/info" || fail "info does not name PETSC_DIR $petsc"
echo "ok: info names the $(echo "$want_lib $want_app" | wc -w) sources of src/ and version $version"

# three objects, each needing an outside header, compiled with PETSc's compiler and flags
objs=(src/io/provenance src/io/rom_file src/mesh/partition)
targets=()
for o in "${objs[@]}"; do targets+=("$t/b/obj/$o.o"); done
"${mk[@]}" "${targets[@]}" > "$t/make.log" 2>&1 || { tail -30 "$t/make.log"; fail "compiling ${objs[*]} with Makefile.petsc"; }
for o in "${objs[@]}"; do
  [ -s "$t/b/obj/$o.o" ] || fail "no object $o.o"
  grep -q "include/rbcontact/" "$t/b/obj/$o.d" || fail "$o.d lists no header of include/rbcontact (header dependencies)"
done
commit=$(git -C "$src" rev-parse --short=12 HEAD 2>/dev/null || echo unknown)
grep -q "RBC_GIT_COMMIT='\"$commit" "$t/make.log" || { grep -o "RBC_GIT_COMMIT=[^ ]*" "$t/make.log" | head -1; fail "the provenance is not compiled with the commit $commit"; }
grep -q -- "-std=c++17" "$t/make.log" || fail "not compiled as C++17"
echo "ok: compiled ${objs[*]} (SLEPc, HDF5, METIS headers), commit $commit, dependencies in the .d files"

# the variables' errors: make stops before compiling anything, naming the variable and the path
expect() { # expect WHAT WORDS... -- ARGS...
  local what=$1; shift
  local words=()
  while [ "$1" != "--" ]; do words+=("$1"); shift; done
  shift
  if make --no-print-directory -f "$src/Makefile.petsc" BUILD="$t/bad" "$@" info > "$t/err" 2>&1; then cat "$t/err"; fail "$what: make succeeded"; fi
  for w in "${words[@]}"; do grep -qF -- "$w" "$t/err" || { cat "$t/err"; fail "$what: the message does not name '$w'"; }; done
  [ ! -e "$t/bad" ] || fail "$what: $t/bad was created"
  echo "ok: $what: $(grep -o '\*\*\*.*' "$t/err" | head -1)"
}
expect "no PETSC_DIR" "PETSC_DIR is not set" -- PETSC_DIR= SLEPC_DIR="$slepc"
expect "no SLEPC_DIR" "SLEPC_DIR is not set" -- PETSC_DIR="$petsc" SLEPC_DIR=
expect "PETSC_DIR not an installation" "PETSC_DIR=$t/nosuch" "lib/petsc/conf/variables not found" -- PETSC_DIR="$t/nosuch" SLEPC_DIR="$slepc"
expect "SLEPC_DIR not an installation" "SLEPC_DIR=$t/nosuch" "slepc_common not found" -- PETSC_DIR="$petsc" SLEPC_DIR="$t/nosuch"
echo "all Makefile.petsc checks passed"
