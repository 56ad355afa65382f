#!/usr/bin/env bash
# Run the whole test suite: pure, FreeCAD headless and GUI (under Xvfb).
set -euo pipefail
cd "$(dirname "$0")/.."
export QTWEBENGINE_CHROMIUM_FLAGS="${QTWEBENGINE_CHROMIUM_FLAGS:---no-sandbox}"
exec xvfb-run -a -s "-screen 0 1600x1200x24" /usr/bin/python3 -m pytest "$@"
