# SPDX-License-Identifier: LGPL-2.1-or-later
"""The first pass of a streamed program (:mod:`surfcomp.io.gcode.prescan`): its segment
count is the whole program's estimate whatever the block size, and a program refused by it
has no block planned."""

import os
import tracemalloc

import numpy as np
import pytest

from surfcomp.core.axis.axis_errors import AxisErrorModel
from surfcomp.core.axis.moves import estimate_segments, plan_moves
from surfcomp.errors import GCodeError, InputError
from surfcomp.io.gcode import ProgramFile, compensate_stream, parse_gcode, read_gcode, stream
from surfcomp.io.gcode.prescan import count_segments
from tests.conftest import REALDATA, ROOT

BEAR = os.path.join(REALDATA, "gcode", "CAMotics_GPL", "bear.nc")
WAVE = os.path.join(REALDATA, "gcode", "CAMotics_GPL", "wave.gcode")
ARCS = os.path.join(ROOT, "tests", "data", "gcode", "arcs.ngc")
MODEL = AxisErrorModel(slope=np.diag([1e-4, -5e-5, 2e-5]))


@pytest.mark.parametrize("path, seg, arc_tol", [
    (BEAR, 0.001, 1e-3), (BEAR, 2.0, 1e-3), (WAVE, 0.05, 1e-3), (ARCS, 0.5, 1e-3),
    (ARCS, 5.0, 1e-9)], ids=lambda v: os.path.basename(v) if isinstance(v, str) else None)
@pytest.mark.parametrize("block_lines", [1, 7, 10_000])
def test_the_first_pass_counts_what_the_whole_program_needs(path, seg, arc_tol, block_lines):
    if block_lines == 1 and path == BEAR:
        block_lines = 997          # one-line blocks of 15 000 lines: seconds for nothing
    whole = estimate_segments(parse_gcode(read_gcode(path))[0], seg, arc_tol)
    est, moves = count_segments(stream.program_blocks(ProgramFile(path), block_lines), seg,
                                arc_tol)
    assert est.total == whole.total and est.by_angle == whole.by_angle
    np.testing.assert_allclose(est.length, whole.length, rtol=1e-12)
    assert moves == parse_gcode(read_gcode(path))[0].n_moves
    if path == ARCS and arc_tol == 1e-9:
        assert est.by_angle > est.total / 2 > 0      # the arc tolerance sets the count


def _counting(monkeypatch):
    planned = []

    def counted(*args, **kwargs):
        planned.append(args[0].n_moves)
        return plan_moves(*args, **kwargs)

    monkeypatch.setattr(stream, "plan_moves", counted)
    return planned


def test_too_many_segments_are_refused_before_anything_is_planned_or_written(monkeypatch):
    """300 short moves (27 554 segments of 0.05 mm), then one move of 8998 mm
    that alone needs 180 000 (limit lowered to 100 000); in blocks of 100 lines the first
    three are below the limit: without the first pass they were planned and written."""
    planned = _counting(monkeypatch)
    body = "G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F300\n" + "".join(
        "G1 X%d Y%d\n" % (k % 9, (3 * k) % 9) for k in range(300)) + "G1 X9000 Y0\n"
    head = parse_gcode(body.rsplit("G1 X9000", 1)[0])[0]
    assert estimate_segments(head, 0.05, 1e-3).total == 27554
    written = []
    with pytest.raises(InputError) as refused:
        compensate_stream(ProgramFile("long.ngc", body.encode()), written.append, MODEL,
                          block_lines=100, segment_length=0.05, max_segments=100_000,
                          source="long.ngc", names=("--segment-length", "--arc-tolerance"))
    assert str(refused.value) == (
        "long.ngc: --segment-length 0.05 mm: the program's 10366.9 mm of G1 moves and arcs "
        "would be split into about 2.08e+05 segments, more than the 100000 one compensation "
        "may write (memory and time); expected a --segment-length of at least 0.104 mm")
    assert planned == [] and written == []
    # the suggestion is enough, and the counter counts
    compensate_stream(ProgramFile("long.ngc", body.encode()), written.append, MODEL,
                      block_lines=100, segment_length=0.104, max_segments=100_000)
    assert planned == [99, 100, 100, 4]          # 303 moves (the first line has none)


def test_a_read_error_in_a_late_block_is_refused_before_anything_is_planned(monkeypatch):
    planned = _counting(monkeypatch)
    body = "G21 G90\nG0 X0 Y0 Z5\n" + "G1 X1 Y1\nG1 X2 Y0\n" * 100 + "G1 X#1\n"
    written = []
    with pytest.raises(GCodeError) as refused:
        compensate_stream(ProgramFile("late.ngc", body.encode()), written.append, MODEL,
                          block_lines=10, source="late.ngc")
    assert str(refused.value).startswith("late.ngc:203:4: LinuxCNC parameter")
    assert planned == [] and written == []


def test_the_first_pass_holds_one_block():
    """200 000 lines read in blocks of 5000: the first pass alone peaks at a bound of the
    block size, not of the program (the program's bytes, 2.4 MB, are not traced: they
    are given as data)."""
    data = ("G21 G90\nG0 X0 Y0 Z5\n" + "G1 X1.5 Y1 Z-1\nG1 X0.25 Y0.125\n" * 100_000).encode()
    program = ProgramFile("big.ngc", data)
    tracemalloc.start()
    try:
        est, moves = count_segments(stream.program_blocks(program, 5000), 2.0, 1e-3)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert moves == 200_001
    assert est.total == 200_004     # the rapid, the plunge's 4 pieces, then 1.53 mm moves
    assert peak < 8e6, peak
