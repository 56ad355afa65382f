# SPDX-License-Identifier: LGPL-2.1-or-later
"""G-code compensated a block of lines at a time (issue 25, item 7: a 2-million-line
program peaked at 5.8 GB): the output is the whole program's byte for byte whatever the
block size, a refusal in the last block writes nothing, and the memory follows the block
size, not the program's length."""

import functools
import os
import tracemalloc

import numpy as np
import pytest

from surfcomp.core.axis.axis_errors import AxisErrorModel
from surfcomp.errors import GCodeError, InputError
from surfcomp.io.gcode import ProgramFile, compensate_gcode, compensate_stream, stream
from tests.conftest import REALDATA, ROOT
from tests.pure.test_gcode_rs274 import ARCS_INCH, ARCS_MM

DATA = os.path.join(ROOT, "tests", "data", "gcode")
#: quadratic errors of a few um over 100 mm: lines are split, arcs converted
MODEL = AxisErrorModel(slope=np.diag([1e-4, -5e-5, 2e-5]),
                       curvature=[[2e-6, 1e-6, 0], [0, -3e-6, 1e-6], [1e-6, 0, 2e-6]])


def _programs():
    progs = {}
    for name in sorted(os.listdir(DATA)):
        if name.endswith(".ngc") and not name.endswith(".out.ngc"):
            progs[name] = open(os.path.join(DATA, name), "rb").read()
    for folder in ("CAMotics_GPL", "LinuxCNC_GPL"):
        base = os.path.join(REALDATA, "gcode", folder)
        for name in sorted(os.listdir(base)):
            if name.endswith((".nc", ".ngc", ".gcode")):
                progs[name] = open(os.path.join(base, name), "rb").read()
    progs["rs274_mm"] = ARCS_MM.encode("ascii")
    progs["rs274_inch"] = ARCS_INCH.encode("ascii")
    # a byte-order mark, CRLF endings and a last line without one
    progs["bom_crlf"] = (b"\xef\xbb\xbfG21 G90\r\nG0 X0 Y0 Z1\r\nG1Z-1F100\r\nX90\r\nY20 X0\r\n"
                         b"G2 X20 Y40 R20\r\nG1 X80")
    return progs


PROGRAMS = _programs()


def _outcome(data, name, **kw):
    if not kw:
        return _whole(name) if PROGRAMS.get(name) is data else _run(data, name)
    return _run(data, name, **kw)


@functools.lru_cache(maxsize=None)
def _whole(name):
    """The outcome of the program ``name`` compensated at once (computed once a run)."""
    return _run(PROGRAMS[name], name)


def _run(data, name, **kw):
    try:
        return compensate_gcode(data, MODEL, segment_length=1.0, source=name, **kw)
    except (GCodeError, InputError) as exc:
        return exc


@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_blocks_give_the_whole_program_byte_for_byte(name):
    data = PROGRAMS[name]
    whole = _outcome(data, name)
    # one-line blocks cost some 2 ms a line: 30 s for bear.nc's 15 000 lines
    for lines in (1, 7, 1000) if data.count(b"\n") < 3000 else (7, 1000):
        part = _outcome(data, name, block_lines=lines)
        if isinstance(whole, Exception):
            # refused the same way, naming the same line
            assert type(part) is type(whole) and str(part) == str(whole), (lines, part)
            continue
        assert part.data == whole.data, lines
        assert part.stats == whole.stats
        assert part.warnings == whole.warnings
        np.testing.assert_array_equal(part.nominal, whole.nominal)
        np.testing.assert_array_equal(part.emitted, whole.emitted)
        np.testing.assert_array_equal(part.line, whole.line)
        pp, pw = part.predicted(MODEL), whole.predicted(MODEL)
        assert pp["before"]["n"] == pw["before"]["n"]
        np.testing.assert_allclose(pp["after"]["rms_mm"], pw["after"]["rms_mm"], rtol=1e-12)


def test_the_test_programs_are_compensated_not_copied():
    """The comparison above is not between two unchanged copies."""
    changed = [n for n, d in PROGRAMS.items()
               if not isinstance(_outcome(d, n), Exception) and _outcome(d, n).data != d]
    assert len(changed) >= 8, changed
    assert _outcome(PROGRAMS["bom_crlf"], "b").data.startswith(b"\xef\xbb\xbfG21 G90\r\n")


def _cli(argv, capsys):
    from surfcomp.cli import main
    rc = main(argv)
    out = capsys.readouterr()
    return rc, out.out, out.err


AXIS_CSV = "axis,position,ex,ey,ez\nX,0,0,0,0\nX,100,0.01,0.002,0\nY,0,0,0,0\nY,100,0,-0.01,0\n"


@pytest.mark.parametrize("last, says", [
    ("G1 X#1", ":%d:4: LinuxCNC parameter"),
    ("G1 X90000", ":%d: the error model predicts an error of"),
])
def test_a_refusal_on_the_last_line_writes_nothing(last, says, tmp_path, capsys, monkeypatch):
    """A point out of bounds on the last line: the earlier blocks are written to the
    staged output before the last one is compensated (a read error there is refused by
    the first pass, :mod:`surfcomp.io.gcode.prescan`, before any block is written)."""
    monkeypatch.setattr(stream, "BLOCK_LINES", 3)
    body = "G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F300\n" + "".join(
        "G1 X%d Y%d\n" % (k % 90, (3 * k) % 90) for k in range(300))
    prog = tmp_path / "p.ngc"
    prog.write_text(body + last + "\n")
    (tmp_path / "e.csv").write_text(AXIS_CSV)
    out = tmp_path / "out.ngc"
    rc, _o, err = _cli(["gcode", str(prog), "--axis-errors", str(tmp_path / "e.csv"), "-o",
                        str(out), "--report", str(tmp_path / "r.json")], capsys)
    assert rc == 2
    assert says % 304 in err, err
    assert sorted(os.listdir(tmp_path)) == ["e.csv", "p.ngc"]
    # without the last line it is written, as compensate_gcode writes it
    prog.write_text(body)
    rc, _o, err = _cli(["gcode", str(prog), "--axis-errors", str(tmp_path / "e.csv"), "-o",
                        str(out)], capsys)
    assert rc == 0, err
    from surfcomp.core.axis.axis_errors import fit_axis_errors
    from surfcomp.io.axis_csv import read_axis_errors
    model = fit_axis_errors(read_axis_errors(str(tmp_path / "e.csv")).data)
    expected = compensate_gcode(body.encode(), model, max_error=1.0)
    assert out.read_bytes() == expected.data != body.encode()


def test_memory_follows_the_block_not_the_program():
    """50 000 lines (a move every 200th, comments and blank lines between) in blocks of
    5000 lines: the peak of Python's allocations stays within a bound of the block size,
    far below the 300 bytes a line (15 MB) of issue 25 (the peak is the same for 200 000
    lines: 3.0 MB)."""
    block = 5000
    lines = ["G21 G90\n", "G0 X0 Y0 Z5\n", "G1 Z-1 F300\n"]
    for k in range(50_000):
        if k % 200 == 0:
            lines.append("X%.3f Y%.3f\n" % ((k // 200 * 7) % 100, (k // 200 * 13) % 100))
        else:
            lines.append("(c)\n" if k % 2 else "\n")
    data = "".join(lines).encode("ascii")
    del lines
    size = [0]

    def write(text):
        size[0] += len(text)

    tracemalloc.start()
    try:
        comp = compensate_stream(ProgramFile("gen.ngc", data), write, MODEL,
                                 block_lines=block)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    st = comp.stats()
    assert st["lines_in"] == 50_003 and st["moves"] == 252
    assert st["lines_changed"] > 225                      # the moves were compensated
    assert size[0] > len(data)                            # 4 decimals, Z words added
    # measured 3.0 MB; the whole program at once takes some 3 kB a line
    assert peak < 1_000_000 + 500 * block, peak


def test_the_memory_estimate_uses_the_block_size():
    from surfcomp.core import budget
    assert budget.GCODE_BLOCK_LINES == stream.BLOCK_LINES
