# SPDX-License-Identifier: LGPL-2.1-or-later
"""``compensate --program`` plans a long program's moves in a fork of the process
(:class:`surfcomp.io.gcode.offset_stream._Planner`, programs of at least
``FORK_LINES`` lines; lowered here so that a small raster on the example face takes it):
the same bytes as the moves planned in the process; Ctrl-C, SIGTERM or SIGHUP while the
child plans: the command's exit code, nothing written, the child gone."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from surfcomp.core.simulation.presets import werner_surface
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP, ROOT
from tests.conftest import default_signals
from tests.toolpath_checks import drop_cutter

#: the CLI with the fork taken for any program; ``hold``: the child holds its first block
#: (so that the signal lands while it plans, however loaded the machine is)
RUN = r"""
import os, sys, time
from surfcomp.app import program_route
from surfcomp.io.gcode import offset_stream as m
program_route.FORK_LINES = 0
parent = os.getpid()
if os.environ.get("HOLD_PLAN"):
    plan = m.ProgramOffset.plan
    def held(self, prog):
        if os.getpid() != parent:
            sys.stderr.write("HELD %d\n" % os.getpid()); sys.stderr.flush()
            time.sleep(120)
        return plan(self, prog)
    m.ProgramOffset.plan = held
from surfcomp.cli import main
sys.exit(main(sys.argv[1:]))
"""


def raster(path, rows=40):
    """A drop-cutter raster program of ``rows`` x ``rows`` moves on the example face (ball
    radius 3 mm, as bench/bench_direct.py makes them)."""
    X, Y = np.meshgrid(np.linspace(0.5, 44.5, rows), np.linspace(0.5, 44.5, rows))
    X[1::2] = X[1::2, ::-1]
    z, _ = drop_cutter(werner_surface(), 1, np.column_stack([X.ravel(), Y.ravel()]),
                       np.full(X.size, 5.0), 3.0, iterations=4)
    Z = z.reshape(rows, rows)
    text = ["G21 G90 G17\nG0 Z20\n"]
    for i in range(rows):
        text.append("G0 X%.4f Y%.4f\nG1 Z%.4f F1200\n" % (X[i, 0], Y[i, 0], Z[i, 0]))
        text.extend("G1 X%.4f Y%.4f Z%.4f\n" % (X[i, j], Y[i, j], Z[i, j])
                    for j in range(1, rows))
        text.append("G0 Z20\n")
    path.write_text("".join(text) + "M2\n")


def _cmd(program, out):
    return [sys.executable, "-c", RUN, "compensate", EXAMPLE_STEP, EXAMPLE_CSV, "--program",
            str(program), "--tool", "ball:3", "-o", str(out), "--quiet"]


def _env(**extra):
    # one BLAS thread (as python3 -m surfcomp sets it): a process with one thread forks
    return dict(os.environ, PYTHONPATH=ROOT, OPENBLAS_NUM_THREADS="1", **extra)


def test_the_forked_planner_writes_the_same_bytes(tmp_path):
    program = tmp_path / "raster.ngc"
    raster(program)
    outs = {}
    for threads in ("1", "2"):
        out = tmp_path / ("out%s.ngc" % threads)
        run = subprocess.run(_cmd(program, out), cwd=ROOT, capture_output=True, text=True,
                             timeout=600, env=_env(SURFCOMP_THREADS=threads))
        assert run.returncode == 0, run.stderr
        outs[threads] = out.read_bytes()
    assert outs["1"] == outs["2"] and outs["1"] != program.read_bytes()


@pytest.mark.parametrize("group", [False, True], ids=["command", "group"])
@pytest.mark.parametrize("signame, code", [("SIGINT", 130), ("SIGTERM", 143),
                                            ("SIGHUP", 129)])
def test_a_signal_while_the_child_plans_leaves_nothing(tmp_path, signame, code, group):
    """The signal to the command alone, or to its process group (a terminal's Ctrl-C, a
    session's hang-up): the child too gets it and must not die of it before the parent
    has unwound (the exit code would be the child's death, 1)."""
    program = tmp_path / "raster.ngc"
    raster(program, 20)
    out = tmp_path / "out" / "moved.ngc"
    out.parent.mkdir()
    proc = subprocess.Popen(_cmd(program, out), cwd=ROOT, stderr=subprocess.PIPE, text=True,
                            env=_env(SURFCOMP_THREADS="2", HOLD_PLAN="1"),
                            preexec_fn=default_signals, start_new_session=group)
    seen = []
    child = None
    for line in proc.stderr:
        seen.append(line)
        if line.startswith("HELD "):
            child = int(line.split()[1])
            if group:
                os.killpg(proc.pid, getattr(signal, signame))
            else:
                proc.send_signal(getattr(signal, signame))
            break
    rest = proc.stderr.read()
    assert proc.wait(timeout=300) == code, "".join(seen) + rest
    assert child is not None
    assert "; nothing was written" in rest
    assert os.listdir(out.parent) == []
    for _ in range(50):     # the parent killed and waited for it: gone
        try:
            os.kill(child, 0)
        except ProcessLookupError:
            break
        time.sleep(0.1)
    else:
        pytest.fail("the planning child %d outlived the command" % child)
