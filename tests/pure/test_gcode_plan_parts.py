# SPDX-License-Identifier: LGPL-2.1-or-later
"""The move plan is computed a run of moves at a time (issue 25, item 7: a 2-million-line
program sampled every move at once, 5.8 GB): the parts give the plan and the program of
the whole, byte for byte, wherever the runs end (arcs and split lines included)."""

import os

import numpy as np
import pytest

from surfcomp.core.axis import moves
from surfcomp.core.axis.axis_errors import AxisErrorModel
from surfcomp.io.gcode import compensate_gcode

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
WAVE = os.path.join(ROOT, "tests", "data", "real", "gcode", "CAMotics_GPL", "wave.gcode")
#: quadratic errors of a few um over 100 mm: lines are split, arcs converted
MODEL = AxisErrorModel(slope=np.diag([1e-4, -5e-5, 2e-5]),
                       curvature=[[2e-6, 1e-6, 0], [0, -3e-6, 1e-6], [1e-6, 0, 2e-6]])


def _program():
    with open(WAVE, "rb") as fh:
        data = fh.read()
    return data + b"G0 Z5\nG1 X0 Y0 F500\nG1 X120 Y40\nG2 X140 Y60 I10 J10\nM2\n"


@pytest.mark.parametrize("chunk", [1, 7, 1000])
def test_plan_in_parts_equals_the_plan_of_the_whole(chunk, monkeypatch):
    data = _program()
    whole = compensate_gcode(data, MODEL, segment_length=1.0)
    monkeypatch.setattr(moves, "PLAN_CHUNK", chunk)
    parts = compensate_gcode(data, MODEL, segment_length=1.0)
    assert parts.data == whole.data
    assert parts.data != data                   # the model moved points
    assert parts.stats["lines_out"] > parts.stats["lines_in"]     # and split moves
