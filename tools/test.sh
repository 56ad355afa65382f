#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Run the lint gate and the whole test suite: pure, FreeCAD headless and GUI (under Xvfb).
# Arguments go to pytest (e.g. tests/pure); the lint gate runs only for a full run.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -eq 0 ]; then
  echo "surfcomp tests: lint with $(ruff --version) (pyproject.toml)"
  ruff check --no-cache .
fi
export QTWEBENGINE_CHROMIUM_FLAGS="${QTWEBENGINE_CHROMIUM_FLAGS:---no-sandbox}"
# -a: the first free X server number from SURFCOMP_XVFB_FROM (default 99; the version
# matrix gives each root its own range)
exec xvfb-run -a -n "${SURFCOMP_XVFB_FROM:-99}" -s "-screen 0 1600x1200x24" \
  /usr/bin/python3 -m pytest "$@"
