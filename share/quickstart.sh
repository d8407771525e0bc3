#!/usr/bin/env bash
# share/quickstart.sh: from a fresh Debian bookworm machine to a solved scene and its picture.
#   1. share/setup.sh             installs the missing Debian packages (idempotent)
#   2. cmake configure + build    into build/ (Release)
#   3. the main job               (the MAIN JOB block below) under mpirun -n $NP: FOM, offline
#                                 (ROM file), online (+ fields), validate (+ speed-error sweep)
#   4. prints where the reports, fields and pictures are
# Runs from any working directory (it changes to the repository root).
# Environment: RBC_BUILD_DIR (default build), RBC_NP (default 2).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

BUILD="${RBC_BUILD_DIR:-build}"
NP="${RBC_NP:-2}"
PYTHON=/usr/bin/python3 # Debian's interpreter: a pyenv python3 on PATH may lack h5py

die() { echo "quickstart.sh: error: $*" >&2; exit 1; }
# (RBC_NP=0 ran mpirun -n 0, one process per slot; RBC_NP=abc failed after the setup and the build, blamed on fom)
case "$NP" in '' | *[!0-9]* | 0*) die "RBC_NP='$NP' must be a number of MPI ranks >= 1" ;; esac
step() { echo; echo "==> $*"; }

step "setup (share/setup.sh)"
bash share/setup.sh || die "share/setup.sh failed"

step "configure + build ($BUILD)"
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release || die "cmake configure failed"
cmake --build "$BUILD" -j2 || die "build failed"
RBC="$BUILD/bin/rbcontact"
[ -x "$RBC" ] || die "$RBC was not built"

# mpirun: OpenMPI refuses root without these; allow more ranks than cores on small machines.
if [ "$(id -u)" -eq 0 ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
fi
export OMPI_MCA_rmaps_base_oversubscribe="${OMPI_MCA_rmaps_base_oversubscribe:-1}"
# (the PML Open MPI selects here anyway; named, MPI_Init skips probing libfabric: half of every start, docs/online.md)
export OMPI_MCA_pml="${OMPI_MCA_pml:-ob1}"
MPIRUN=(mpirun -n "$NP")

REPORTS=()  # JSON reports written by the main job (printed at the end)
PICTURES=() # PNG pictures written by the main job (printed at the end)

# rbc <stage> <report.json> [options...]: runs one stage of rbcontact under mpirun, writing <report.json>.
rbc() {
  local stage="$1" report="$2"
  shift 2
  mkdir -p "$(dirname "$report")"
  echo "+ ${MPIRUN[*]} $RBC $stage $* -report $report"
  "${MPIRUN[@]}" "$RBC" "$stage" "$@" -report "$report" || die "rbcontact $stage failed (see the messages above)"
  REPORTS+=("$report")
}

# plot <fields.h5> <picture.png> <title>: renders a FOM output with share/plot_fields.py.
plot() {
  echo "+ $PYTHON share/plot_fields.py $1 -o $2 --title $3"
  "$PYTHON" share/plot_fields.py "$1" -o "$2" --title "$3" || die "plotting $1 failed"
  PICTURES+=("$2")
}

# plot_pressure <fields.h5> <picture.png> <title> [plot_contact.py options...]: plots the contact
# pressure along the slave surface with share/plot_contact.py (needs a run with contact).
plot_pressure() {
  local h5="$1" png="$2" title="$3"
  shift 3
  echo "+ $PYTHON share/plot_contact.py $h5 -o $png --title $title${*:+ $*}"
  "$PYTHON" share/plot_contact.py "$h5" -o "$png" --title "$title" "$@" || die "plotting the contact pressure of $h5 failed"
  PICTURES+=("$png")
}

# ============================== MAIN JOB ==============================
# The default scene end to end: the FOM at the default radius, the offline stage (snapshots over the
# seed's 21 radii, POD + supremizers, dual basis, EIM -> the ROM file), one online solve with the
# full fields reconstructed (the deformed-configuration picture), and the validation against the FOM
# on 20 random radii with the speed-against-error sweep (the speed-error picture). Every setting is in
# runs/$SCENE.opts; each stage writes its report into $OUT.
SCENE=ring_on_block
OUT="results/$SCENE"
MU_ONLINE=1.02
# Extra options for the FOM run, e.g. CONTACT_OPTS=(-kacanov_monitor).
CONTACT_OPTS=()

speed_error() { # speed_error out.png table.json [table.json ...]
  local png="$1"
  shift
  echo "+ $PYTHON share/plot_speed_error.py $* -o $png --targets 1e-4,1e-2"
  "$PYTHON" share/plot_speed_error.py "$@" -o "$png" --targets 1e-4,1e-2 || die "plotting $* failed"
  PICTURES+=("$png")
}

main_job() {
  step "main job: scene $SCENE on $NP ranks -> $OUT/"
  rbc fom "$OUT/fom.json" -options_file "runs/$SCENE.opts" ${CONTACT_OPTS[@]+"${CONTACT_OPTS[@]}"} -fom_output "$OUT/fom.h5"
  plot "$OUT/fom.h5" "$OUT/fom.png" "$SCENE"
  plot_pressure "$OUT/fom.h5" "$OUT/pressure.png" "$SCENE"
  # offline: resumes the snapshot file of an earlier (killed) run of the same problem
  # (both hyper-reductions: the ECSW cubature, the default online, and the EIM, for the comparison)
  rbc offline "$OUT/offline.json" -options_file "runs/$SCENE.opts" -rom "$OUT/rom.h5" -rom_hyper ecsw,eim -snapshots_monitor -offline_basis_output "$OUT/basis_view.h5"
  rbc online "$OUT/online.json" -rom "$OUT/rom.h5" -mu "$MU_ONLINE" -online_repeat 1000 -options_file "runs/$SCENE.opts" -rom_reconstruct "$OUT/online_fields.h5"
  plot "$OUT/online_fields.h5" "$OUT/deformed_rom.png" "$SCENE-ROM-radius-$MU_ONLINE"
  plot_pressure "$OUT/online_fields.h5" "$OUT/pressure_rom.png" "$SCENE-ROM-radius-$MU_ONLINE"
  rbc validate "$OUT/validate.json" -options_file "runs/$SCENE.opts" -rom "$OUT/rom.h5" -validate_sweep -validate_sweep_output "$OUT/sweep"
  rbc validate "$OUT/validate_eim.json" -options_file "runs/$SCENE.opts" -rom "$OUT/rom.h5" -rom_hyper eim -validate_sweep -validate_sweep_output "$OUT/sweep_eim"
  # the same on the mesh refined twice (the hard setting: where the EIM lost its accuracy), 10 test radii
  rbc offline "$OUT/refine2/offline.json" -options_file "runs/$SCENE.opts" -mesh_refine 2 -rom "$OUT/refine2/rom.h5" -rom_hyper ecsw,eim
  rbc validate "$OUT/refine2/validate.json" -options_file "runs/$SCENE.opts" -mesh_refine 2 -rom "$OUT/refine2/rom.h5" -test_size 10 -validate_sweep -validate_sweep_output "$OUT/refine2/sweep"
  rbc validate "$OUT/refine2/validate_eim.json" -options_file "runs/$SCENE.opts" -mesh_refine 2 -rom "$OUT/refine2/rom.h5" -rom_hyper eim -test_size 10 -validate_sweep -validate_sweep_output "$OUT/refine2/sweep_eim"
  speed_error "$OUT/speed_error.png" "$OUT/sweep.json" "$OUT/sweep_eim.json" "$OUT/refine2/sweep.json" "$OUT/refine2/sweep_eim.json"
  "$PYTHON" - "$OUT/validate.json" <<'PY' || die "reading the validation report failed"
import json, os, sys
d = os.path.dirname(sys.argv[1])
for tag, path in (("refine 0", "validate.json"), ("refine 0", "validate_eim.json"), ("refine 2", "refine2/validate.json"), ("refine 2", "refine2/validate_eim.json")):
    r = json.load(open(os.path.join(d, path)))
    t, x, ro = r["test"], r["test_exact"], r["rom"]
    sizes = "Mc %d" % ro["Mc"] if ro["hyper"] == "ecsw" else "Mk %d Mg %d" % (ro["Mk"], ro["Mg"])
    print("validation %s, %s (%d random radii, %d dofs): ROM N %d R %d %s" % (tag, ro["hyper"].upper(), t["n"], ro["ndofs"], ro["N"], ro["R"], sizes))
    print("  max rel err u %.2e (target 1e-4), lambda %.2e (target 1e-2), force %.2e (target 1e-3); exact contact terms: u %.2e lambda %.2e"
          % (t["max_rel_err_u"], t["max_rel_err_lambda"], t["max_rel_err_force"], x["max_rel_err_u"], x["max_rel_err_lambda"]))
    print("  online median %.2e s per solve (in a sweep of distinct parameters %.2e s), FOM median %.2e s, speedup %.0f"
          % (r["online_time_s"]["median"], r["online_time_s"]["sweep_median"], r["fom_time_s"]["median"], r["speedup_median"]))
for tag, path in (("refine 0", "offline.json"), ("refine 2", "refine2/offline.json")):
    p = json.load(open(os.path.join(d, path))).get("probe")
    if p:  # the offline stage solved its ROM over the whole box, no FOM (docs/online.md "Probing a model")
        print("probe %s: the ROM at %d %s parameters of its box: %d failed, %d with projections at the edge of its contact data, Kacanov iterations max %d"
              % (tag, p["size"], p["type"], p["failed"], p["out_of_range"], p.get("kacanov_iterations", {}).get("max", 0)))
PY
  # the online error estimate (docs/error_estimate.md): the same snapshots, enriched bases and a calibration on 20
  # FOM solves (offline -estimate); every online solve reports its estimated errors, validate their effectivity
  rbc offline "$OUT/estimate/offline.json" -options_file "runs/$SCENE.opts" -rom "$OUT/estimate/rom.h5" -snapshots "$OUT/rom.snapshots.h5" -estimate
  rbc online "$OUT/estimate/online.json" -rom "$OUT/estimate/rom.h5" -mu "$MU_ONLINE" -online_repeat 1000 -options_file "runs/$SCENE.opts"
  rbc validate "$OUT/estimate/validate.json" -options_file "runs/$SCENE.opts" -rom "$OUT/estimate/rom.h5"
  "$PYTHON" - "$OUT/estimate" <<'PY' || die "reading the error-estimate reports failed"
import json, os, sys
d = sys.argv[1]
on, v = json.load(open(os.path.join(d, "online.json"))), json.load(open(os.path.join(d, "validate.json")))
e, t = on["error_estimate"], v["online_time_s"]
print("error estimate at %s: u %.2e, lambda %.2e, force %.2e (estimated relative errors)" % (", ".join("%s %g" % kv for kv in on["mu"].items()), e["u"], e["lambda"], e["force"]))
for k in ("u", "lambda", "force"):
    b = v["estimate"][k]
    print("  %-6s effectivity (estimate / true error) %.2f..%.2f on %d random radii, >= 1 on %.0f %%" % (k, b["min_effectivity"], b["max_effectivity"], len(b["effectivity"]), 100 * b["share_above_1"]))
print("  online %.2e s with the estimate, %.2e s without (%.2fx)" % (t["median"], t["median_without_estimate"], t["estimate_cost_ratio"]))
PY
  # 3D contact: a hemisphere on a block against Hertz's point contact, the deformed bodies in section and the
  # pressure on the slave surface (3D picture; radial profile against Hertz, contact plane)
  rbc fom "results/hertz3d/fom.json" -options_file runs/hertz3d.opts -fom_output "results/hertz3d/fom.h5"
  plot "results/hertz3d/fom.h5" "results/hertz3d/fom.png" "hertz3d"
  echo "+ $PYTHON share/plot_bodies3d.py results/hertz3d/fom.h5 -o results/hertz3d/bodies.png --title hertz3d"
  "$PYTHON" share/plot_bodies3d.py "results/hertz3d/fom.h5" -o "results/hertz3d/bodies.png" --title hertz3d || die "plotting the 3D bodies failed"
  PICTURES+=("results/hertz3d/bodies.png")
  plot_pressure "results/hertz3d/fom.h5" "results/hertz3d/pressure.png" "hertz3d" --report "results/hertz3d/fom.json"
  # the 3D reduced model (docs/rom3d.md): sphere radius and imposed displacement, 81 training solves, 20 test points
  rbc offline "results/sphere_block3d/offline.json" -options_file runs/sphere_block3d.opts -rom "results/sphere_block3d/rom.h5"
  rbc validate "results/sphere_block3d/validate.json" -options_file runs/sphere_block3d.opts -rom "results/sphere_block3d/rom.h5"
  "$PYTHON" - "results/sphere_block3d/validate.json" <<'PY' || die "reading the 3D validation report failed"
import json, sys
r = json.load(open(sys.argv[1]))
t, ro = r["test"], r["rom"]
print("3D ROM sphere_block3d (%d random points, %d dofs): N %d R %d Mc %d" % (t["n"], ro["ndofs"], ro["N"], ro["R"], ro["Mc"]))
print("  max rel err u %.2e (target 1e-3), lambda %.2e (target 2e-2), force %.2e (target 1e-3); online median %.2e s (in a sweep %.2e s), FOM median %.2e s, speedup %.0f"
      % (t["max_rel_err_u"], t["max_rel_err_lambda"], t["max_rel_err_force"], r["online_time_s"]["median"], r["online_time_s"]["sweep_median"], r["fom_time_s"]["median"], r["speedup_median"]))
print("  outputs computed online (no mesh) against the FOM's: max rel err max pressure %.2e, contact radius %.2e"
      % (t["max_rel_err_max_pressure_online"], t["max_rel_err_contact_radius_online"]))
PY
  # one online answer of the 3D ROM on the mesh: the deformed bodies and the pressure on the slave surface
  rbc online "results/sphere_block3d/online.json" -rom "results/sphere_block3d/rom.h5" -mu 1.1,0.045 -online_repeat 1000 -options_file runs/sphere_block3d.opts -rom_reconstruct "results/sphere_block3d/online_fields.h5"
  echo "+ $PYTHON share/plot_bodies3d.py results/sphere_block3d/online_fields.h5 -o results/sphere_block3d/bodies_rom.png"
  "$PYTHON" share/plot_bodies3d.py "results/sphere_block3d/online_fields.h5" -o "results/sphere_block3d/bodies_rom.png" --title "sphere_block3d ROM, radius 1.1, displacement 0.045" || die "plotting the 3D ROM's bodies failed"
  PICTURES+=("results/sphere_block3d/bodies_rom.png")
}
# ============================ END MAIN JOB ============================

main_job

step "done: outputs"
for r in "${REPORTS[@]}"; do echo "report:  $ROOT/$r"; done
echo "fields:  $ROOT/$OUT/fom.h5, $ROOT/$OUT/online_fields.h5 (ROM)"
echo "fields:  $ROOT/$OUT/fom.xmf, $ROOT/$OUT/online_fields.xmf, $ROOT/results/hertz3d/fom.xmf, $ROOT/results/sphere_block3d/online_fields.xmf (open them in ParaView)"
echo "bases:   $ROOT/$OUT/basis_view.xmf (POD modes, supremizers and the dual basis on the mesh, for ParaView)"
echo "ROM:     $ROOT/$OUT/rom.h5 (online data), rom.basis.h5, rom.snapshots.h5"
echo "sweep:   $ROOT/$OUT/sweep.csv, sweep_eim.csv, refine2/sweep.csv, refine2/sweep_eim.csv"
for p in "${PICTURES[@]}"; do echo "picture: $ROOT/$p"; done
