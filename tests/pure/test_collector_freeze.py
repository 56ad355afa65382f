# SPDX-License-Identifier: LGPL-2.1-or-later
"""The cycle collector in a process of one command (``python3 -m surfcomp``): what exists
when the startup's imports are done is frozen, so the command's collections skip it."""

import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# in a fresh process: freezing would keep this test session's objects from the collector
SCENARIO = r"""
import gc, sys
from surfcomp.core import memory

if sys.argv[1] == "one":
    memory.one_command_process()
before = gc.get_freeze_count()
with memory.collector_paused():
    assert not gc.isenabled()
    made = [[k] for k in range(1000)]           # containers made while paused
after = gc.get_freeze_count()
print(before, after - before, gc.isenabled(), gc.is_tracked(made[0]))
"""


def _run(mode):
    return subprocess.run([sys.executable, "-c", SCENARIO, mode], cwd=ROOT,
                          capture_output=True, text=True, check=True).stdout.split()


def test_a_one_command_process_freezes_what_the_pause_leaves():
    before, frozen, enabled, tracked = _run("one")
    assert before == "0"
    assert int(frozen) >= 1000 + 1              # the 1000 lists and their outer list
    assert enabled == "True"                    # the collector runs again for the work
    assert tracked == "True"                    # frozen, still a tracked container


def test_another_process_freezes_nothing():
    """FreeCAD or a test session runs on: its cycles must stay collectable."""
    before, frozen, enabled, _tracked = _run("other")
    assert (before, frozen, enabled) == ("0", "0", "True")
