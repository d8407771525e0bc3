#!/usr/bin/env bash
# share/setup.sh: installs what rbcontact needs on a Debian bookworm machine (PETSc/SLEPc 3.18,
# METIS, HDF5 (OpenMPI), OpenMPI, gmsh, CMake, compilers, and the Python plotting packages),
# pybind11 (pybind11-dev: the Python module, docs/python.md), git (the commit in every report's provenance: a minbase
# Debian has none, and reports then said "unknown"), and
# OpenBLAS (libopenblas0-pthread: Debian's alternatives then give it to PETSc, MUMPS and LAPACK in place
# of the reference BLAS; the dense compliance and MUMPS's fronts run 5-10x faster, docs/fom_speed.md).
# Idempotent: checks each package with dpkg-query and runs `apt-get update` + `apt-get install`
# only for the missing ones. Run as root (uses sudo only when not root and sudo exists).
# Usage: bash share/setup.sh
set -euo pipefail

PACKAGES=(
  petsc-dev slepc-dev libmetis-dev libhdf5-openmpi-dev openmpi-bin gmsh libgmsh-dev
  cmake pkg-config g++ make python3-matplotlib python3-h5py python3-numpy
  libopenblas0-pthread pybind11-dev git
)

die() { echo "setup.sh: error: $*" >&2; exit 1; }

command -v dpkg-query >/dev/null 2>&1 || die "dpkg-query not found: this script targets Debian bookworm (apt/dpkg)"

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed"; then
    missing+=("$p")
  fi
done

if [ "${#missing[@]}" -eq 0 ]; then
  echo "setup.sh: all ${#PACKAGES[@]} required packages are installed"
else
  SUDO=()
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then
      SUDO=(sudo)
    else
      die "missing packages (${missing[*]}) and not root, no sudo: run as root: apt-get install ${missing[*]}"
    fi
  fi
  command -v apt-get >/dev/null 2>&1 || die "apt-get not found; install by hand: ${missing[*]}"
  echo "setup.sh: installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update \
    || die "apt-get update failed (network? /etc/apt/sources.list?)"
  "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}" \
    || die "apt-get install failed for: ${missing[*]}"
  still=()
  for p in "${missing[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || still+=("$p")
  done
  [ "${#still[@]}" -eq 0 ] || die "still not installed after apt-get: ${still[*]}"
  echo "setup.sh: installed: ${missing[*]}"
fi

# The plotting scripts run with Debian's interpreter (a pyenv python3 on PATH lacks h5py).
/usr/bin/python3 -c "import numpy, h5py, matplotlib" 2>/dev/null \
  || die "/usr/bin/python3 cannot import numpy, h5py and matplotlib (python3-numpy python3-h5py python3-matplotlib)"
