#!/usr/bin/env bash
# tests/gmsh_check.sh -- owns the test of the gmsh structure check (src/mesh/gmsh_check.hpp) on gmsh's own output: every
# meshes/*.geo meshed in formats 4.1 and 2.2 must be accepted, then the check's own cases (tests/test_gmsh_check.cpp).
# Usage: gmsh_check.sh <test_gmsh_check executable> <source dir>
set -u
exe=$1
src=$2
d=$(mktemp -d "${TMPDIR:-/tmp}/rbc_gmsh_check.XXXXXX") || exit 2
trap 'rm -rf "$d"' EXIT
files=()
for g in "$src"/meshes/*.geo; do
  b=$(basename "$g" .geo)
  for f in msh41 msh22; do
    "${RBC_GMSH:-gmsh}" -3 "$g" -format $f -v 0 -o "$d/$b.$f.msh" > "$d/gmsh.log" 2>&1 || { cat "$d/gmsh.log"; echo "FAIL: gmsh could not mesh $g"; exit 1; }
    files+=("$d/$b.$f.msh")
  done
done
[ ${#files[@]} -ge 16 ] || { echo "FAIL: only ${#files[@]} meshes made"; exit 1; }
"$exe" "${files[@]}"
