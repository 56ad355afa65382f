# SPDX-License-Identifier: LGPL-2.1-or-later
"""The direct program route plans a block's moves on a second thread while it reads the
next block and writes the one before: the output, the statistics and the first refusal are
those of the blocks done one after the other (``SURFCOMP_THREADS=1``)."""

import os

import pytest

from surfcomp.core.compensation.program_offset import BallOffset
from surfcomp.core.simulation.presets import werner_surface
from surfcomp.errors import GCodeError
from surfcomp.io.gcode import ProgramFile
from surfcomp.io.gcode import offset_stream as offset_module
from surfcomp.io.gcode.offset_stream import offset_stream
from tests.conftest import ROOT
from tests.pure.test_gcode_plain import wave

SURF = werner_surface()
FINISH = open(os.path.join(ROOT, "tests", "data", "gcode", "freecad_3dsurface_excerpt.ngc"),
              "rb").read()


def _run(path, threads, monkeypatch, block_lines):
    monkeypatch.setattr(offset_module, "threads", lambda: threads)
    out = []
    try:
        po = offset_stream(ProgramFile(str(path)), out.append,
                           BallOffset(SURF, 1, 3.0, wave, 1.0), block_lines=block_lines,
                           source="p.ngc")
    except GCodeError as exc:
        return exc
    return "".join(out), po.stats(), po.fit


@pytest.mark.parametrize("block_lines", [50, 333])
def test_pipelined_blocks_write_the_same_bytes(monkeypatch, tmp_path, block_lines):
    path = tmp_path / "p.ngc"
    path.write_bytes(FINISH)
    one = _run(path, 1, monkeypatch, block_lines)
    two = _run(path, 2, monkeypatch, block_lines)
    assert one[0] == two[0] and one[1] == two[1]
    assert one[1]["moves_moved"] > 100 and one[0].encode("latin-1") != FINISH
    assert one[2] == two[2]


def test_pipelined_blocks_refuse_the_same_line(monkeypatch, tmp_path):
    # a move in inch mode in a late block: the same refusal, the same line
    lines = FINISH.decode("latin-1").splitlines(True)
    k = len(lines) * 2 // 3
    lines.insert(k, "G20\n")
    path = tmp_path / "p.ngc"
    path.write_bytes("".join(lines).encode("latin-1"))
    one = _run(path, 1, monkeypatch, 60)
    two = _run(path, 2, monkeypatch, 60)
    assert isinstance(one, GCodeError) and "inch mode" in str(one)
    assert str(one) == str(two) and one.line == two.line and one.line > k
