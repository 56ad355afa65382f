"""Shared test set-up: the repository root on sys.path and paths to shared data."""

import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

#: ../shared/realdata next to the checkout (read by path, never copied)
REALDATA = os.path.join(os.path.dirname(ROOT), "shared", "realdata")
