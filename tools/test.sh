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
  # one kernel and failed on another)
  for kernel in Haswell:avx2 SkylakeX:avx512f; do
    if grep -qw "${kernel#*:}" /proc/cpuinfo; then
      echo "surfcomp tests: reference solves with OPENBLAS_CORETYPE=${kernel%%:*}"
      OPENBLAS_CORETYPE=${kernel%%:*} /usr/bin/python3 -m pytest -q -p no:cacheprovider \
        -m reference_solver tests/pure
    fi
  done
fi
export QTWEBENGINE_CHROMIUM_FLAGS="${QTWEBENGINE_CHROMIUM_FLAGS:---no-sandbox}"
# -a: the first free X server number from SURFCOMP_XVFB_FROM (default 99; the version
# matrix gives each root its own range)
exec xvfb-run -a -n "${SURFCOMP_XVFB_FROM:-99}" -s "-screen 0 1600x1200x24" \
  /usr/bin/python3 -m pytest "$@"
