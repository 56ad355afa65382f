# SPDX-License-Identifier: LGPL-2.1-or-later
"""Shared test set-up: the repository root on sys.path and the path to the real test data."""

import os
import sys

import pytest

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


def pytest_configure(config):
    """``SURFCOMP_RECORD_DURATIONS=1``: record each test's time in tests/durations.json
    (in the controlling process of a parallel run, which sees every worker's reports)."""
    if os.environ.get("SURFCOMP_RECORD_DURATIONS") and not hasattr(config, "workerinput"):
        from tests.schedule import Recorder

        config.pluginmanager.register(Recorder(), "surfcomp-durations")


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """Work units for parallel runs (``pytest -n 2 --dist loadgroup``, tools/test.sh),
    longest first (tests/schedule.py). Without xdist the marks are unused and the order is
    the collection's. It runs before pytest-xdist's own hook, which reads the groups (as
    the last hook it would see no group and spread every test)."""
    from tests.schedule import assign

    parallel = hasattr(config, "workerinput") or bool(config.getoption("numprocesses", None))
    assign(items, parallel)
