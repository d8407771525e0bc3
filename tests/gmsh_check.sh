#!/usr/bin/env bash
# tests/gmsh_check.sh -- owns the test of the gmsh structure check (src/mesh/gmsh_check.hpp) on gmsh's own output: every
# meshes/*.geo meshed in formats 4.1 (ASCII and binary) and 2.2 must be accepted, then the check's own cases
# (tests/test_gmsh_check.cpp); with the rbcontact executable, the FOM of ring_on_block from its binary 4.1 mesh on 1 and
# 2 ranks must give the ASCII mesh's contact force and energy (the binary reading of the check and PETSc's reader agree).
# Usage: gmsh_check.sh <test_gmsh_check executable> <source dir> [<rbcontact executable> <mpiexec>]
set -u
exe=$1
src=$2
rbc=${3:-}
mpiexec=${4:-mpiexec}
d=$(mktemp -d "${TMPDIR:-/tmp}/rbc_gmsh_check.XXXXXX") || exit 2
trap 'rm -rf "$d"' EXIT
files=()
for g in "$src"/meshes/*.geo; do
  b=$(basename "$g" .geo)
  for f in msh41 msh22 bin41; do
    opt=(-format "${f/bin/msh}")
    [ $f = bin41 ] && opt+=(-bin)
    "${RBC_GMSH:-gmsh}" -3 "$g" "${opt[@]}" -v 0 -o "$d/$b.$f.msh" > "$d/gmsh.log" 2>&1 || { cat "$d/gmsh.log"; echo "FAIL: gmsh could not mesh $g"; exit 1; }
    files+=("$d/$b.$f.msh")
  done
done
[ ${#files[@]} -ge 24 ] || { echo "FAIL: only ${#files[@]} meshes made"; exit 1; }
"$exe" "${files[@]}" || exit 1
[ -n "$rbc" ] || exit 0
# the FOM from the 2D ring_on_block mesh, ASCII then binary (the 3D-meshed files above hold the same 2D mesh; made
# again with -2, as the scene's .geo is meshed)
for f in msh41 bin41; do
  opt=(-format msh41)
  [ $f = bin41 ] && opt+=(-bin)
  "${RBC_GMSH:-gmsh}" -2 "$src/meshes/ring_on_block.geo" "${opt[@]}" -v 0 -o "$d/ring.$f.msh" > "$d/gmsh.log" 2>&1 || { cat "$d/gmsh.log"; echo "FAIL: gmsh"; exit 1; }
done
for np in 1 2; do
  for f in msh41 bin41; do
    (cd "$src" && "$mpiexec" -n $np "$rbc" fom -options_file runs/ring_on_block.opts -mesh_file "$d/ring.$f.msh" -report "$d/$f.$np.json") > "$d/fom.log" 2>&1 \
      || { tail -20 "$d/fom.log"; echo "FAIL: the FOM from the $f mesh on $np rank(s)"; exit 1; }
  done
done
/usr/bin/python3 - "$d" <<'PY'
import json, sys
d = sys.argv[1]
ref = json.load(open(d + "/msh41.1.json"))
bad = 0
for np in (1, 2):
    r = json.load(open("%s/bin41.%d.json" % (d, np)))
    for k in ("contact_force", "energy"):
        e = abs(r[k] - ref[k]) / abs(ref[k])
        ok = r["ndofs"] == ref["ndofs"] and r["nactive"] == ref["nactive"] and e < 1e-10
        bad += not ok
        print("  %-5s binary 4.1 mesh, %d rank(s): %s %.15g (ASCII, 1 rank: %.15g; relative difference %.1e), %d dofs, %d active"
              % ("ok" if ok else "FAIL", np, k, r[k], ref[k], e, r["ndofs"], r["nactive"]))
sys.exit(1 if bad else 0)
PY
