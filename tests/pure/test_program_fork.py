# SPDX-License-Identifier: LGPL-2.1-or-later
"""A long program's moves planned in a fork of the process (``fork=True``, the command
line's route): the output, the statistics and the first refusal are those of the blocks
done one after the other; a child that dies is reported; an exception or an interruption
in the parent ends the child, and the child is always waited for.

Each case runs in a fresh Python (a fork is only taken by a process with one thread; the
test process may hold other tests' worker threads)."""

import json
import os
import subprocess
import sys

from tests.conftest import ROOT

FINISH = os.path.join(ROOT, "tests", "data", "gcode", "freecad_3dsurface_excerpt.ngc")

_CASE = r"""
import json, os, signal, sys
from surfcomp.core.compensation.program_offset import BallOffset
from surfcomp.core.simulation.presets import werner_surface
from surfcomp.errors import SurfcompError
from surfcomp.io.gcode import ProgramFile
from surfcomp.io.gcode import offset_stream as m
from tests.pure.test_gcode_plain import wave

path, threads, fork, case = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "1", sys.argv[4]
m.threads = lambda: threads
pids = []
real = m._Planner.__init__
def init(self, worker):
    real(self, worker)
    pids.append(self.pid)
m._Planner.__init__ = init
if case == "die":
    m.ProgramOffset.plan = lambda self, prog: os.kill(os.getpid(), signal.SIGKILL)
out = []
def write(text):
    if case == "interrupt" and len(out) == 3:
        raise KeyboardInterrupt
    out.append(text)
settings = {"max_segments": 400} if case == "limit" else {}
res = {"forked": 0}
try:
    po = m.offset_stream(ProgramFile(path), write, BallOffset(werner_surface(), 1, 3.0, wave,
                         1.0), block_lines=50, source="p.ngc", fork=fork, **settings)
    res.update(text=''.join(out), stats=po.stats(), stock=po.fit.stock)
except (SurfcompError, KeyboardInterrupt) as exc:
    res.update(error=type(exc).__name__, message=str(exc), line=getattr(exc, "line", None))
res["forked"] = len(pids)
res["waited"] = []
for pid in pids:    # every child already waited for: not a child of this process any more
    try:
        os.waitpid(pid, os.WNOHANG)
        res["waited"].append(False)
    except ChildProcessError:
        res["waited"].append(True)
print(json.dumps(res))
"""


def _run(path, threads, fork, case="plain"):
    proc = subprocess.run([sys.executable, "-c", _CASE, str(path), str(threads),
                           "1" if fork else "0", case], cwd=ROOT, capture_output=True,
                          text=True, timeout=120,
                          env=dict(os.environ, PYTHONPATH=ROOT, OPENBLAS_NUM_THREADS="1"))
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.splitlines()[-1])


def test_a_forked_planner_writes_the_same_bytes():
    one = _run(FINISH, 1, False)
    forked = _run(FINISH, 2, True)
    assert forked["forked"] == 1 and forked["waited"] == [True]
    assert one["forked"] == 0 and one["stats"]["moves_moved"] > 100
    assert one["text"] == forked["text"] and one["stats"] == forked["stats"]
    assert one["stock"] == forked["stock"]
    # without fork=True, or on one thread, no fork
    assert _run(FINISH, 2, False)["forked"] == 0


def test_a_refusal_of_the_forked_planner_names_the_same_line():
    # the piece limit passed in a late block: raised in the child, raised again here
    one = _run(FINISH, 1, False, "limit")
    forked = _run(FINISH, 2, True, "limit")
    assert one["error"] == "GCodeError" and "more than 400 pieces" in one["message"]
    assert forked["forked"] == 1 and forked["waited"] == [True]
    assert (forked["error"], forked["message"], forked["line"]) == \
        (one["error"], one["message"], one["line"])
    assert one["message"].startswith("p.ngc:%d: " % one["line"])


def test_a_planner_that_dies_is_reported_and_waited_for():
    got = _run(FINISH, 2, True, "die")
    assert got["error"] == "ComputationError"
    assert "ended unexpectedly (signal 9)" in got["message"]
    assert got["forked"] == 1 and got["waited"] == [True]


def test_an_interruption_ends_the_planner():
    got = _run(FINISH, 2, True, "interrupt")
    assert got["error"] == "KeyboardInterrupt"
    assert got["forked"] == 1 and got["waited"] == [True]
