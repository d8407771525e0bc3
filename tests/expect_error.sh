#!/usr/bin/env bash
# tests/expect_error.sh -- owns the bad-input test driver of the ctest suite.
# Usage: expect_error.sh REGEX cmd [args...]
# Runs the command (stdin closed) and passes only if
#   * its exit code is non-zero,
#   * its combined stdout + stderr matches the extended regular expression REGEX (grep -E), and
#   * that output contains no sign of a crash or of a NaN: 'SEGV', 'Segmentation', 'Caught signal',
#     'nan' (as a word, any case).
# Prints the command, the exit code and the error lines, so a failing test shows why.
# Special arguments: the tokens @GARBAGE_MSH@ / @GARBAGE_GEO@ in the command are replaced by the path
# of a fresh temp file holding a malformed gmsh .msh / .geo file, removed afterwards; @PIN_MSH22@ by
# meshes/pin_in_hole.geo meshed in gmsh format 2.2 (an entity tag equal to another group's physical tag); @NOBLOCK_GEO@
# by meshes/ring_on_block.geo without the block's Physical Surface; @ORDER2_GEO@ by the same with Mesh.ElementOrder = 2;
# @PIN_MSH22BIN@ by @PIN_MSH22@ in binary; @PART_MSH22@ by ring_on_block's mesh in format 2.2 partitioned in 2; @DUPPHYS_MSH@ by ring_on_block's mesh with "ring_top" under two physical tags;
# @MISSING_NODE_MSH@ / @INF_NODE_MSH@ by that mesh with a triangle pointing at an undefined node / a node at x = inf;
# @FREECURVE_GEO@ by ring_on_block.geo with a physical curve in no surface; @MIXED3D_GEO@ by a 3D mesh of tetrahedra and hexahedra;
# @SELFINC_GEO@ by a .geo including, through a second file, itself three times; @TWICE_GEO@ by a .geo that includes
# ring_on_block.geo twice (gmsh's parser gives up inside the Include, and gmsh 4.8 then hangs or aborts); @BADENTITY_MSH@
# by ring_on_block's mesh whose first node block names entity 77, which the file does not define (a segmentation fault
# in PETSc's reader before the structure check, src/mesh/gmsh_check.hpp); @BIN41_SHORT_MSH@ by that mesh in binary 4.1
# whose $Nodes header counts one node fewer than its blocks hold (PETSc's reader: an abort, then a hang);
# @BIG_SAMPLES_TXT@ by a -train_file of 10000001 one-parameter samples (one more than every training set's cap); @TMP@
# inside any other argument by the temporary directory (outputs a refused run may leave: removed at exit).
set -u
if [ $# -lt 2 ]; then
  echo "usage: $0 REGEX cmd [args...]" >&2
  exit 2
fi
regex=$1
shift

tmpdir=$(mktemp -d "${TMPDIR:-/tmp}/rbc_expect_error.XXXXXX") || exit 2
trap 'rm -rf "$tmpdir"' EXIT
args=()
for a in "$@"; do
  if [ "$a" = "@GARBAGE_MSH@" ]; then
    printf '$MeshFormat\nthis is not a mesh\n$EndMeshFormat\n$Nodes\n3\n1 0 0\n2 x y z\n' > "$tmpdir/garbage_mesh.msh"
    args+=("$tmpdir/garbage_mesh.msh")
  elif [ "$a" = "@PIN_MSH22@" ]; then
    # meshes/pin_in_hole.geo written in gmsh format 2.2: entity 13 (master arc) vs physical group 13
    "${RBC_GMSH:-gmsh}" -2 "$(dirname "$0")/../meshes/pin_in_hole.geo" -format msh22 -v 0 -o "$tmpdir/pin_in_hole.22.msh" > /dev/null 2>&1 || { echo "expect_error: gmsh failed"; exit 2; }
    args+=("$tmpdir/pin_in_hole.22.msh")
  elif [ "$a" = "@NOBLOCK_GEO@" ]; then
    # meshes/ring_on_block.geo without the block's Physical Surface (a body of -bodies with no cells in the mesh)
    grep -v 'Physical Surface("block"' "$(dirname "$0")/../meshes/ring_on_block.geo" > "$tmpdir/noblock.geo"
    args+=("$tmpdir/noblock.geo")
  elif [ "$a" = "@ORDER2_GEO@" ]; then
    # meshes/ring_on_block.geo meshed with second-order (curved) elements
    { cat "$(dirname "$0")/../meshes/ring_on_block.geo"; echo 'Mesh.ElementOrder = 2;'; } > "$tmpdir/order2.geo"
    args+=("$tmpdir/order2.geo")
  elif [ "$a" = "@PART_MSH22@" ]; then
    # meshes/ring_on_block.geo in gmsh format 2.2, partitioned in 2: the partition count (1) and tags (1, 2) after the
    # entity tag equal the surfaces' physical tags (ring 1, block 2)
    "${RBC_GMSH:-gmsh}" -2 "$(dirname "$0")/../meshes/ring_on_block.geo" -format msh22 -part 2 -v 0 -o "$tmpdir/ring.part.22.msh" > /dev/null 2>&1 || { echo "expect_error: gmsh failed"; exit 2; }
    args+=("$tmpdir/ring.part.22.msh")
  elif [ "$a" = "@PIN_MSH22BIN@" ]; then
    # meshes/pin_in_hole.geo in binary gmsh format 2.2 (the tag clash of @PIN_MSH22@, unreadable as text)
    "${RBC_GMSH:-gmsh}" -2 "$(dirname "$0")/../meshes/pin_in_hole.geo" -format msh22 -bin -v 0 -o "$tmpdir/pin_in_hole.22bin.msh" > /dev/null 2>&1 || { echo "expect_error: gmsh failed"; exit 2; }
    args+=("$tmpdir/pin_in_hole.22bin.msh")
  elif [ "$a" = "@DUPPHYS_MSH@" ]; then
    # meshes/ring_on_block.geo (format 4.1) with the name "ring_top" given a second physical tag, 15, on one of its two
    # curves (a mesh merged from several files)
    "${RBC_GMSH:-gmsh}" -2 "$(dirname "$0")/../meshes/ring_on_block.geo" -format msh41 -v 0 -o "$tmpdir/ring.msh" > /dev/null 2>&1 || { echo "expect_error: gmsh failed"; exit 2; }
    /usr/bin/python3 - "$tmpdir/ring.msh" "$tmpdir/dupphys.msh" <<'PY' || { echo "expect_error: the mesh edit failed"; exit 2; }
import sys
L = open(sys.argv[1]).read().split("\n")
i = L.index("$PhysicalNames")
L[i + 1] = str(int(L[i + 1]) + 1)
L.insert(L.index('1 12 "ring_top"') + 1, '1 15 "ring_top"')
e = L.index("$Entities")
npts, ncur = map(int, L[e + 1].split()[:2])
for k in range(e + 2 + npts, e + 2 + npts + ncur):  # the second curve of ring_top gets tag 15
    f = L[k].split()
    if f[7] == "1" and f[8] == "12" and f[0] != "5":
        f[8] = "15"
        L[k] = " ".join(f) + " "
        break
else:
    sys.exit("no second ring_top curve")
open(sys.argv[2], "w").write("\n".join(L))
PY
    args+=("$tmpdir/dupphys.msh")
  elif [ "$a" = "@MISSING_NODE_MSH@" ] || [ "$a" = "@INF_NODE_MSH@" ]; then
    # ring_on_block's mesh (format 4.1) with the first triangle pointing at node 99999, which does not exist (PETSc's
    # reader indexed with it: a segmentation fault), or with the first node's x coordinate inf
    "${RBC_GMSH:-gmsh}" -2 "$(dirname "$0")/../meshes/ring_on_block.geo" -format msh41 -v 0 -o "$tmpdir/ring.msh" > /dev/null 2>&1 || { echo "expect_error: gmsh failed"; exit 2; }
    /usr/bin/python3 - "$tmpdir/ring.msh" "$tmpdir/edited.msh" "$a" <<'PY' || { echo "expect_error: the mesh edit failed"; exit 2; }
import sys
L = open(sys.argv[1]).read().split("\n")
if sys.argv[3] == "@MISSING_NODE_MSH@":
    i = L.index("$Elements") + 2
    while L[i].split()[0] != "2":  # the first block of triangles
        i += 1 + int(L[i].split()[3])
    f = L[i + 1].split()
    L[i + 1] = " ".join([f[0], "99999"] + f[2:])
else:
    i = L.index("$Nodes") + 2
    n = int(L[i].split()[3])
    f = L[i + 1 + n].split()
    L[i + 1 + n] = " ".join(["inf"] + f[1:])
open(sys.argv[2], "w").write("\n".join(L))
PY
    args+=("$tmpdir/edited.msh")
  elif [ "$a" = "@MIXED3D_GEO@" ]; then
    # flat_punch3d's names with the punch in hexahedra (transfinite, recombined) and the base in tetrahedra
    cat > "$tmpdir/mixed3d.geo" <<'GEO'
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 0.5};
Box(2) = {0, 0, -0.5, 1, 1, 0.5};
Mesh.MeshSizeMax = 0.25;
c[] = Boundary{ Volume{1}; };
cc[] = Unique(Abs(Boundary{ Surface{c[]}; }));
Transfinite Curve{cc[]} = 4;
Transfinite Surface{1:6};
Recombine Surface{1:6};
Transfinite Volume{1};
Physical Volume("punch", 1) = {1};
Physical Volume("base", 2)  = {2};
Physical Surface("slave", 11)     = {5};
Physical Surface("punch_top", 12) = {6};
Physical Surface("punch_x0", 13)  = {1};
Physical Surface("punch_y0", 14)  = {3};
Physical Surface("master", 21)      = {12};
Physical Surface("base_bottom", 22) = {11};
Physical Surface("base_x0", 23)     = {7};
Physical Surface("base_y0", 24)     = {9};
GEO
    args+=("$tmpdir/mixed3d.geo")
  elif [ "$a" = "@FREECURVE_GEO@" ]; then
    # meshes/ring_on_block.geo with a physical curve that lies in no surface (PETSc's reader refuses the mesh on rank 0)
    { cat "$(dirname "$0")/../meshes/ring_on_block.geo"
      echo 'Point(301) = {-0.6,-0.001,0,0.0167}; Point(302) = {0.6,-0.001,0,0.0167}; Line(301) = {301,302}; Physical Curve("freeline",16) = {301};'; } > "$tmpdir/freecurve.geo"
    args+=("$tmpdir/freecurve.geo")
  elif [ "$a" = "@SELFINC_GEO@" ]; then
    printf 'lc = 0.1;\nInclude "selfinc_b.geo";\n' > "$tmpdir/selfinc.geo"
    printf 'Include "selfinc.geo";\nInclude "selfinc.geo";\nInclude "selfinc.geo";\n' > "$tmpdir/selfinc_b.geo"
    args+=("$tmpdir/selfinc.geo")
  elif [ "$a" = "@TWICE_GEO@" ]; then
    cp "$(dirname "$0")/../meshes/ring_on_block.geo" "$tmpdir/ring_on_block.geo"
    printf 'Include "ring_on_block.geo";\nInclude "ring_on_block.geo";\n' > "$tmpdir/twice.geo"
    args+=("$tmpdir/twice.geo")
  elif [ "$a" = "@BADENTITY_MSH@" ]; then
    "${RBC_GMSH:-gmsh}" -2 "$(dirname "$0")/../meshes/ring_on_block.geo" -format msh41 -v 0 -o "$tmpdir/ring.msh" > /dev/null 2>&1 || { echo "expect_error: gmsh failed"; exit 2; }
    /usr/bin/python3 - "$tmpdir/ring.msh" "$tmpdir/badentity.msh" <<'PY' || { echo "expect_error: the mesh edit failed"; exit 2; }
import sys
L = open(sys.argv[1]).read().split("\n")
i = L.index("$Nodes") + 2  # the first block's header: dim, entity, parametric, count
h = L[i].split()
h[1] = "77"
L[i] = " ".join(h)
open(sys.argv[2], "w").write("\n".join(L))
PY
    args+=("$tmpdir/badentity.msh")
  elif [ "$a" = "@BIN41_SHORT_MSH@" ]; then
    "${RBC_GMSH:-gmsh}" -2 "$(dirname "$0")/../meshes/ring_on_block.geo" -format msh41 -bin -v 0 -o "$tmpdir/ring.msh" > /dev/null 2>&1 || { echo "expect_error: gmsh failed"; exit 2; }
    /usr/bin/python3 - "$tmpdir/ring.msh" "$tmpdir/bin41_short.msh" <<'PY' || { echo "expect_error: the mesh edit failed"; exit 2; }
import struct, sys
b = bytearray(open(sys.argv[1], "rb").read())
assert b.startswith(b"$MeshFormat\n4.1 1 8\n")
i = b.index(b"\n$Nodes\n") + 8  # numEntityBlocks, numNodes, minNodeTag, maxNodeTag (size_t, little-endian)
n = struct.unpack_from("<Q", b, i + 8)[0]
struct.pack_into("<Q", b, i + 8, n - 1)
open(sys.argv[2], "wb").write(b)
PY
    args+=("$tmpdir/bin41_short.msh")
  elif [ "$a" = "@BIG_SAMPLES_TXT@" ]; then
    /usr/bin/python3 -c "open('$tmpdir/big_samples.txt', 'w').write('1\\n' * 10000001)" || { echo "expect_error: cannot write the sample file"; exit 2; }
    args+=("$tmpdir/big_samples.txt")
  elif [ "$a" = "@GARBAGE_GEO@" ]; then
    printf 'Point(1) = {0, 0, 0, 0.1};\nthis is not gmsh syntax (\n' > "$tmpdir/garbage_geometry.geo"
    args+=("$tmpdir/garbage_geometry.geo")
  else
    args+=("${a//@TMP@/$tmpdir}")  # @TMP@ inside an argument: this run's temporary directory (removed at exit)
  fi
done

out="$tmpdir/output.txt"
echo "expect_error: running: ${args[*]}"
"${args[@]}" < /dev/null > "$out" 2>&1
rc=$?
echo "expect_error: exit code $rc"
# The error lines (PETSc prints many lines of configuration noise after the message).
grep -E "ERROR: [^-]|error|Error" "$out" | grep -vE "Configure options|See https|Petsc Release|named .* by|#[0-9]+ " | head -n 12

status=0
if [ "$rc" -eq 0 ]; then
  echo "expect_error: FAILED: the command succeeded (exit code 0), an error was expected"
  status=1
fi
if ! grep -Eq -- "$regex" "$out"; then
  echo "expect_error: FAILED: the output does not match /$regex/; full output:"
  cat "$out"
  status=1
fi
if grep -Eiq 'SEGV|Segmentation|Caught signal|\bnan\b' "$out"; then
  echo "expect_error: FAILED: the output shows a crash or a NaN:"
  grep -Ein 'SEGV|Segmentation|Caught signal|\bnan\b' "$out" | head -n 5
  status=1
fi
[ $status -eq 0 ] && echo "expect_error: passed (non-zero exit, message matches /$regex/)"
exit $status
