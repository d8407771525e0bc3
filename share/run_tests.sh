#!/usr/bin/env bash
# share/run_tests.sh: installs what is missing (share/setup.sh), configures and builds into build/
# (the same build directory as share/quickstart.sh), then runs the whole test suite with
#   ctest --output-on-failure -j2
# in it. The exit code is ctest's; the last line printed is ctest's summary
# ("100% tests passed, 0 tests failed out of N"). Runs from any working directory.
# Environment: RBC_BUILD_DIR (default build), CI=true (no colours, nothing interactive).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
BUILD="${RBC_BUILD_DIR:-build}"

if [ "${CI:-}" = "true" ] || [ ! -t 1 ]; then
  # No terminal: no colours, no prompts, no progress bars.
  export CLICOLOR=0 CLICOLOR_FORCE=0 NO_COLOR=1 GCC_COLORS= TERM=dumb DEBIAN_FRONTEND=noninteractive
  # (not CMAKE_COLOR_DIAGNOSTICS=OFF: it adds -fno-diagnostics-color to every compile line, so the build quickstart.sh
  # made was compiled again in full; found in a fresh-machine run, 2026-12-02)
  COLOR_OPT=(-DCMAKE_COLOR_MAKEFILE=OFF)
else
  COLOR_OPT=()
fi

die() { echo "run_tests.sh: error: $*" >&2; exit 1; }

echo "==> setup (share/setup.sh)"
bash share/setup.sh </dev/null || die "share/setup.sh failed"

echo "==> configure + build ($BUILD)"
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release "${COLOR_OPT[@]}" </dev/null || die "cmake configure failed"
cmake --build "$BUILD" -j2 </dev/null || die "build failed"

echo "==> ctest ($BUILD)"
log="$(mktemp "${TMPDIR:-/tmp}/rbc_ctest.XXXXXX")"
trap 'rm -f "$log"' EXIT
set +e
(cd "$BUILD" && ctest --output-on-failure --no-tests=error -j2 </dev/null) 2>&1 | tee "$log"
rc=${PIPESTATUS[0]}
set -e
# ctest ends with "Total Test time" (and the list of failures): repeat its summary as the last line.
summary="$(grep -E '[0-9]+% tests passed' "$log" | tail -n 1 || true)"
if [ -n "$summary" ]; then echo "$summary"; else echo "run_tests.sh: ctest exited with $rc and printed no summary"; fi
exit "$rc"
