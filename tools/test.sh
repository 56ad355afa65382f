#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Run the lint gate and the whole test suite: pure, FreeCAD headless and GUI (under Xvfb).
# Arguments go to pytest (e.g. tests/pure); the lint gate runs only for a full run.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -eq 0 ]; then
  echo "surfcomp tests: lint with $(ruff --version) (pyproject.toml)"
  ruff check --no-cache .
  # the tests against converged reference solvers, once per OpenBLAS kernel this CPU can run
  # (OpenBLAS picks its kernel by CPU; a reference that stopped at rounding level passed on
  # one kernel and failed on another); only the modules that hold such tests are collected
  reference_files=$(grep -l "mark.reference_solver" tests/pure/test_*.py)
  for kernel in Haswell:avx2 SkylakeX:avx512f; do
    if grep -qw "${kernel#*:}" /proc/cpuinfo; then
      echo "surfcomp tests: reference solves with OPENBLAS_CORETYPE=${kernel%%:*}"
      # shellcheck disable=SC2086
      OPENBLAS_CORETYPE=${kernel%%:*} /usr/bin/python3 -m pytest -q -p no:cacheprovider \
        -m reference_solver $reference_files
    fi
  done
fi
# In parallel on the machine's cores with pytest-xdist where it is installed (Debian's
# python3-pytest-xdist, tools/install.sh): pure and fuzz tests spread test by test, each
# tests/app module on one worker, the GUI sessions one after the other on one worker
# (tests/conftest.py). SURFCOMP_TEST_WORKERS=1 runs everything in this one process.
workers="${SURFCOMP_TEST_WORKERS:-$(nproc 2>/dev/null || echo 1)}"
parallel=()
if [ "$workers" -gt 1 ] && /usr/bin/python3 -c "import xdist" 2>/dev/null; then
  parallel=(-n "$workers" --dist loadgroup)
fi
export QTWEBENGINE_CHROMIUM_FLAGS="${QTWEBENGINE_CHROMIUM_FLAGS:---no-sandbox}"
# -a: the first free X server number from SURFCOMP_XVFB_FROM (default 99; the version
# matrix gives each root its own range)
run_pytest() {
  xvfb-run -a -n "${SURFCOMP_XVFB_FROM:-99}" -s "-screen 0 1600x1200x24" \
    /usr/bin/python3 -m pytest "$@"
}
if [ $# -eq 0 ] && [ ${#parallel[@]} -gt 0 ]; then
  # a full parallel run: the GUI sessions come after the rest, alone on the machine, so
  # their latency checks (every key press repainted, answered within a bound) measure the
  # GUI and not a neighbouring worker's load; both parts always run
  rc=0
  run_pytest "${parallel[@]}" tests/pure tests/fuzz tests/app || rc=$?
  run_pytest tests/gui || rc=$?
  exit "$rc"
fi
run_pytest "${parallel[@]}" "$@"
