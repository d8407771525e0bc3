#!/usr/bin/env bash
# share/quickstart.sh: from a fresh Debian bookworm machine to a solved scene and its picture.
#   1. share/setup.sh             installs the missing Debian packages (idempotent)
#   2. cmake configure + build    into build/ (Release)
#   3. the main job               (the MAIN JOB block below) under mpirun -n $NP
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
# Extend here: the offline/online pipeline (offline snapshots, bases, EIM, online, validate) goes
# below the fom stage, each writing its report into $OUT.
SCENE=ring_on_block
OUT="results/$SCENE"
# The FOM runs with contact (the scene's -contact_slave/-contact_master pair). Add options here,
# e.g. CONTACT_OPTS=(-kacanov_monitor); CONTACT_OPTS=(-contact 0) solves the elastic problem only
# (then there is no contact pressure to plot: drop the plot_pressure line).
CONTACT_OPTS=()

main_job() {
  step "main job: scene $SCENE on $NP ranks -> $OUT/"
  rbc fom "$OUT/fom.json" -options_file "runs/$SCENE.opts" ${CONTACT_OPTS[@]+"${CONTACT_OPTS[@]}"} -fom_output "$OUT/fom.h5"
  plot "$OUT/fom.h5" "$OUT/fom.png" "$SCENE"
  plot_pressure "$OUT/fom.h5" "$OUT/pressure.png" "$SCENE"
}
# ============================ END MAIN JOB ============================

main_job

step "done: outputs"
for r in "${REPORTS[@]}"; do echo "report:  $ROOT/$r"; done
echo "fields:  $ROOT/$OUT/fom.h5"
echo "fields:  $ROOT/$OUT/fom.xmf (open it in ParaView)"
for p in "${PICTURES[@]}"; do echo "picture: $ROOT/$p"; done
