#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# The long fuzz run before a release: every bad-input case of tests/fuzz and the
# property-based layer with many random (not derandomized) examples per property.
#   bash tools/fuzz.sh                 2000 examples per property (about 10 minutes)
#   SURFCOMP_FUZZ_EXAMPLES=20000 bash tools/fuzz.sh -k properties
# Arguments go to pytest. A failing property prints its smallest example and a
# @reproduce_failure line to paste over the test.
set -euo pipefail
cd "$(dirname "$0")/.."
export SURFCOMP_FUZZ_EXAMPLES="${SURFCOMP_FUZZ_EXAMPLES:-2000}"
echo "surfcomp fuzz: $SURFCOMP_FUZZ_EXAMPLES random examples per property, every table case"
exec /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/fuzz "$@"
