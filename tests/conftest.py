# SPDX-License-Identifier: LGPL-2.1-or-later
"""Shared test set-up: the repository root on sys.path and the path to the real test data."""

import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

#: public CAD, QIF and G-code files copied into the repository (see its README.md)
REALDATA = os.path.join(ROOT, "tests", "data", "real")


def default_signals():
    """``preexec_fn`` for a subprocess that a test signals: SIGINT, SIGTERM and SIGHUP at
    their default dispositions in the child.

    A runner started in the background or under ``nohup`` hands on ignored SIGINT/SIGHUP,
    and Python keeps an inherited ignore (rightly: the program does too), so without this a
    test that sends the signal would see it ignored and fail on the machine's mood.
    """
    import signal

    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_DFL)


def pytest_collection_modifyitems(config, items):
    """Work units for parallel runs (``pytest -n 2 --dist loadgroup``, tools/test.sh).

    A module of ``tests/app`` stays on one worker, so its module-scoped fixtures (a solid
    read once, a shop document regenerated once) are built once. Every ``tests/gui`` module
    runs on the same worker, one FreeCAD GUI session after the other, so two sessions never
    share the X server and the cores (their latency checks allow for the machine's load,
    not for a second GUI). ``tests/pure`` and ``tests/fuzz`` are spread test by test.
    Without xdist the marks are unused.
    """
    import pytest

    for item in items:
        parts = item.nodeid.split("/")
        if len(parts) > 2 and parts[0] == "tests" and parts[1] == "gui":
            item.add_marker(pytest.mark.xdist_group("gui"))
        elif len(parts) > 2 and parts[0] == "tests" and parts[1] == "app":
            item.add_marker(pytest.mark.xdist_group(item.nodeid.split("::")[0]))
