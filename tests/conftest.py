# SPDX-License-Identifier: LGPL-2.1-or-later
"""Shared test set-up: the repository root on sys.path and the path to the real test data."""

import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

#: public CAD, QIF and G-code files copied into the repository (see its README.md)
REALDATA = os.path.join(ROOT, "tests", "data", "real")
