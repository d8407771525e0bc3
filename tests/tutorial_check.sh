#!/usr/bin/env bash
# tests/tutorial_check.sh -- docs/tutorial.md ("Your own scene") works as written, with the installed package,
# from an empty directory. `cmake --install` into a fresh prefix; the .geo and .opts files are the fenced code
# blocks of the tutorial tagged `file=NAME`; its commands are the blocks tagged `step` (must exit 0) and `fails`
# (must exit non-zero), run in order with the installed binary first on PATH, $RBC = the prefix, 1 rank, no
# RBC_MESH_CACHE / RBC_DATA_DIR (the mesh is generated in the working directory). A block tagged `output` after a
# command block lists lines that the command's output must contain (a line ending in "..." is a prefix).
# Then the reports: fom converged with a positive force and no warning; offline wrote the ROM; online's force
# near the FOM's at the same mu; validate's max relative errors finite and below loose bounds (docs/tutorial.md,
# "Validate": 5 x 5 training points miss u and lambda).
# Usage: tutorial_check.sh BUILD_DIR        (TUTORIAL_KEEP=1 keeps the temporary directory)
set -eu
src=$(cd "$(dirname "$0")/.." && pwd)
doc="$src/docs/tutorial.md"
build=$(cd "$1" && pwd)
t=$(mktemp -d "${TMPDIR:-/tmp}/rbc_tutorial.XXXXXX")
if [ "${TUTORIAL_KEEP:-0}" = 1 ]; then echo "keeping $t"; else trap 'rm -rf "$t"' EXIT; fi
fail() { echo "FAIL: $*"; exit 1; }
[ -f "$doc" ] || fail "no $doc"
start=$(date +%s)

cmake --install "$build" --prefix "$t/prefix" > "$t/install.log" || { cat "$t/install.log"; fail "cmake --install"; }
[ -x "$t/prefix/bin/rbcontact" ] || fail "not installed: bin/rbcontact"
echo "ok: installed into $t/prefix"

# Split the tutorial's fenced blocks: files (file=NAME) and the numbered command / output blocks, in order.
mkdir "$t/blocks" "$t/run"
awk -v out="$t/blocks" -v run="$t/run" '
  /^```/ {
    if (inb) { inb = 0; if (target != "") close(target); target = ""; next }
    inb = 1; target = ""; n = split(substr($0, 4), w, " ")
    for (i = 1; i <= n; i++) {
      if (w[i] ~ /^file=/) target = run "/" substr(w[i], 6)
      else if (w[i] == "step" || w[i] == "fails" || w[i] == "output") { k++; target = sprintf("%s/%03d.%s", out, k, w[i]) }
    }
    if (target != "") printf "" > target
    next
  }
  inb && target != "" { print > target }
' "$doc"
for f in roller_groove.geo roller_groove.opts; do
  [ -s "$t/run/$f" ] || fail "docs/tutorial.md has no block tagged file=$f"
done
ls "$t/blocks" | grep -q 'step$' || fail "docs/tutorial.md has no block tagged step"
echo "ok: extracted $(ls "$t/run" | tr '\n' ' ')and $(ls "$t/blocks" | wc -l) command/output blocks"

# The tutorial's environment: the installed package first on PATH, nothing pointing back at the build.
export RBC="$t/prefix" PATH="$t/prefix/bin:$PATH"
unset RBC_MESH_CACHE RBC_DATA_DIR
cd "$t/run"
last=""
for b in "$t"/blocks/*; do
  name=$(basename "$b"); kind=${name#*.}
  case "$kind" in
    step|fails)
      last="$t/blocks/$name.log"
      set +e; bash -eu -o pipefail "$b" > "$last" 2>&1; rc=$?; set -e
      if [ "$kind" = step ] && [ $rc != 0 ]; then cat "$b"; tail -30 "$last"; fail "tutorial step $name exited $rc"; fi
      if [ "$kind" = fails ] && [ $rc = 0 ]; then cat "$b"; cat "$last"; fail "tutorial step $name was expected to fail"; fi
      echo "ok: $kind $name ($(head -1 "$b" | cut -c1-90))"
      ;;
    output)
      [ -n "$last" ] || fail "output block $name before any command block"
      while IFS= read -r line; do
        [ -n "$line" ] || continue
        if [ "${line%...}" != "$line" ]; then
          grep -qF -- "${line%...}" "$last" || { cat "$last"; fail "output of the step before $name lacks: $line"; }
        else
          grep -qxF -- "$line" "$last" || { cat "$last"; fail "output of the step before $name lacks the line: $line"; }
        fi
      done < "$b"
      echo "ok: output $name"
      ;;
  esac
done

# The mesh came from the working directory and was cached there.
ls meshcache/*.msh > /dev/null 2>&1 || fail "no mesh generated in ./meshcache"

/usr/bin/python3 - <<'PY' || fail "report checks"
import json, math
def load(f):
    with open(f) as h:
        return json.load(h)
fom = load("fom.json")
assert fom["converged"] is True, fom
assert fom["contact_force"] > 0 and fom["nactive"] > 0, fom
assert fom["warnings"] == [], fom["warnings"]
print("fom: %d dofs, force %.6g, %d of %d active" % (fom["ndofs"], fom["contact_force"], fom["nactive"], fom["ncontact"]))
off = load("offline.json")
assert off["rom_file"] == "my.h5" and off["fom_solves"] == off["ntrain"] == 81, off
print("offline: N %d R %d Mc %d, %.2f s" % (off["rom"]["N"], off["rom"]["R"], off["rom"]["Mc"], off["time_s"]["total"]))
on, ref = load("online.json"), load("fom_085.json")
assert on["converged"] is True, on
f_rom, f_fom = on["outputs"]["contact_force"], ref["contact_force"]
assert abs(f_rom - f_fom) <= 1e-3 * f_fom, (f_rom, f_fom)
print("online: force %.6g, the FOM's %.6g" % (f_rom, f_fom))
v = load("validate.json")["test"]
bounds = {"max_rel_err_u": 1e-3, "max_rel_err_lambda": 3e-2, "max_rel_err_force": 1e-3, "max_rel_err_force_online": 1e-3}
assert v["n"] == 10 and v["failed"] == 0, v
for k, b in bounds.items():
    assert v[k] is not None and math.isfinite(v[k]) and v[k] < b, (k, v[k], b)
print("validate: " + ", ".join("%s %.3g (< %g)" % (k, v[k], b) for k, b in bounds.items()))
PY
echo "ok: reports (fom converged, force > 0; online force = FOM's to 1e-3; validate errors below the bounds)"
echo "tutorial_check: passed in $(( $(date +%s) - start )) s"
