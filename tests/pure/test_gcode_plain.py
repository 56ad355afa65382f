# SPDX-License-Identifier: LGPL-2.1-or-later
"""Runs of plain G0/G1 lines read and written as arrays (issue 27, the million-move
program): the output, statistics, points and refusals are those of the line-by-line path,
byte for byte, for the axis route (``gcode``) and the direct program route, on the
FreeCAD 3D Surface program of the example face and on random programs mixing plain lines
of every spelling with comments, feeds, tool changes, arcs, modal lines and terse lines.
(``tests/pure/test_gcode_stream.py`` compares the block path, which reads runs as arrays,
with the whole-program path, which reads every line on its own, on the test programs.)"""

import io
import os

import numpy as np
import pytest

from surfcomp.core.axis.axis_errors import AxisErrorModel
from surfcomp.core.compensation.program_offset import BallOffset
from surfcomp.core.simulation.presets import werner_surface
from surfcomp.errors import GCodeError, InputError
from surfcomp.io.gcode import ProgramFile, compensate_gcode, plain
from surfcomp.io.gcode.offset_stream import offset_stream
from surfcomp.io.gcode.stream import iter_lines
from tests.conftest import ROOT
from tests.toolpath_checks import drop_cutter

SURF = werner_surface()
R = 3.0
FINISH = open(os.path.join(ROOT, "tests", "data", "gcode", "freecad_3dsurface_excerpt.ngc"),
              "rb").read()
#: a squareness error: X corrections follow Y, so terse lines gain words
SQUARE = AxisErrorModel.from_components(squareness={"xy": 2e-4, "xz": -1e-4},
                                        scale={"z": 5e-5})


def _both(fn, monkeypatch):
    """``fn()`` with the plain runs read as arrays and line by line (exceptions returned)."""
    out = []
    for on in (True, False):
        monkeypatch.setattr(plain, "ENABLED", on)
        try:
            out.append(fn())
        except (GCodeError, InputError) as exc:
            out.append(exc)
    return out


def _same_axis(data, model, monkeypatch, block_lines=1000, **kw):
    fast, slow = _both(lambda: compensate_gcode(data, model, segment_length=1.0,
                                                block_lines=block_lines, source="p.ngc",
                                                **kw), monkeypatch)
    if isinstance(slow, Exception):
        assert type(fast) is type(slow) and str(fast) == str(slow)
        return slow
    assert fast.data == slow.data
    assert fast.stats == slow.stats and fast.warnings == slow.warnings
    for name in ("nominal", "emitted", "known", "line"):
        np.testing.assert_array_equal(getattr(fast, name), getattr(slow, name))
    return slow


def _words(rng, pt, spaced, prev=None):
    """Axis and feed words of a plain line in one of the spellings met in programs (with
    ``prev``, the previous point: only axes that keep their value are left out, with
    4 or 5 decimals)."""
    sep = " " if spaced else ""
    ws = []
    formats = ("%.4f", "%.5f") if prev is not None else ("%.4f", "%.3f", "%.1f", "%.5f")
    for a, letter in enumerate("XYZ"):
        if rng.random() < 0.75 or (prev is not None and pt[a] != prev[a]):
            ws.append("%s%s" % (letter, formats[rng.integers(len(formats))] % pt[a]))
    if not ws:
        ws.append("Z%.4f" % pt[2])
    if rng.random() < 0.2:
        ws.append("F%d" % rng.integers(100, 2000))
    return sep.join(ws)


def random_program(seed, n=1500, tip=None):
    """A program of mostly plain lines in varied spellings with other lines between
    (``tip(xy) -> z`` puts the points on the face's ball offset)."""
    rng = np.random.default_rng(seed)
    lines = ["%", "(random program %d)" % seed, "G21 G90 G17", "M6 T1", "M3 S8000",
             "G0 X5 Y5 Z20"]
    steps = np.round(rng.normal(0, 0.6, (n, 2)), 4)
    if tip is not None:
        steps[np.arange(n), rng.integers(2, size=n)] *= rng.random(n) < 0.5
    path = np.empty((n, 2))
    xy = np.array([5.0, 5.0])
    for k in range(n):
        xy = path[k] = np.clip(xy + steps[k], 1.0, 44.0)
    zs = np.round(tip(path), 5) if tip is not None else rng.uniform(-2, 2, n)
    prev = None
    for k in range(n):
        xy = path[k]
        z = zs[k]
        pt = (xy[0], xy[1], z)
        r = rng.random()
        spaced = rng.random() < 0.8
        motion = ("", "G1 ", "G01 ", "G1", "G0 ", "G00")[rng.integers(6)]
        if r < 0.82:
            lines.append(motion + _words(rng, pt, spaced, None if tip is None else prev)
                         + (" " if rng.random() < 0.3 else ""))
        elif r < 0.86:
            lines.append("(comment %d)" % rng.integers(100))
            continue
        elif r < 0.88:
            lines.append("G1 X%.4f Y%.4f Z%.4f (with a comment)" % pt)
        elif r < 0.90:
            lines.append("N%d G1 X%.4f Y%.4f Z%.4f" % ((rng.integers(1, 999),) + pt))
        elif r < 0.92:
            lines.append("g1 x%.4f y%.4f z%.4f" % pt)
        elif r < 0.93:
            lines.append("G17 G90")
            continue
        elif r < 0.94:
            lines.append("M6 T%d" % rng.integers(1, 5))
            continue
        elif r < 0.95:
            lines.append("G1 X%.4f  Y%.4f\tZ%.4f" % pt)
        elif r < 0.96 and tip is None:
            lines.append("G1 X%.4f Y%.4f Z%.4f" % pt)
            lines.append("G2 X%.4f Y%.4f I0.5 J0" % (xy[0] + 1.0, xy[1]))
            lines.append("G1 X%.4f Y%.4f" % pt[:2])
        elif r < 0.97:
            lines.append("")
            continue
        else:
            lines.append("G1 X%.4f Y%.4f Z%.4f F300 ; feed" % pt)
        prev = pt
    lines += ["G0 Z20", "M2"]
    return ("\n".join(lines) + "\n").encode()


#: seed -> the random program's output under the zero model (both paths compared once: the
#: outcome does not depend on the parametrized block size)
_ZERO_OUTPUT = {}


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("block_lines", [97, 1000])
def test_axis_route_random_programs_byte_for_byte(seed, block_lines, monkeypatch):
    data = random_program(seed)
    res = _same_axis(data, SQUARE, monkeypatch, block_lines=block_lines)
    assert not isinstance(res, Exception), res
    # compensated, terse lines gained words, and most lines were read in runs
    assert res.data != data and res.stats["lines_changed"] > 500
    if seed not in _ZERO_OUTPUT:
        _ZERO_OUTPUT[seed] = _same_axis(data, AxisErrorModel.zero(), monkeypatch).data
    assert _ZERO_OUTPUT[seed] == data


def test_axis_route_freecad_3d_surface_program(monkeypatch):
    res = _same_axis(FINISH, SQUARE, monkeypatch)
    assert res.stats["lines_changed"] > 500
    assert _same_axis(FINISH, AxisErrorModel.zero(), monkeypatch).data == FINISH


def _tip(xy):
    z, _ = drop_cutter(SURF, 1, xy, np.full(len(xy), 5.0), R, iterations=6)
    return z


def wave(u, v):
    return 0.03 * np.sin(6 * u) * np.cos(5 * v)


def zero(u, v):
    return np.zeros(np.shape(u))


def _same_offset(data, correction, monkeypatch, tmp_path, block_lines=None):
    path = tmp_path / "p.ngc"
    path.write_bytes(data)

    def run():
        out = []
        po = offset_stream(ProgramFile(str(path)), out.append,
                           BallOffset(SURF, 1, R, correction, 1.0), block_lines=block_lines,
                           source="p.ngc")
        return "".join(out).encode("latin-1"), po.stats(), po.warnings()

    fast, slow = _both(run, monkeypatch)
    if isinstance(slow, Exception):
        assert type(fast) is type(slow) and str(fast) == str(slow)
        return slow
    assert fast == slow
    return slow


def test_offset_route_freecad_3d_surface_program(monkeypatch, tmp_path):
    # the comparison is between the two paths: most lines are in runs
    lines = [(c, "") for c in FINISH.decode().splitlines()]
    assert sum(e - s for s, e, _m in plain._candidates(lines)) > 0.9 * len(lines)
    out, st, _w = _same_offset(FINISH, wave, monkeypatch, tmp_path)
    assert st["moves_moved"] > 500 and st["lines_added"] > 0
    assert _same_offset(FINISH, zero, monkeypatch, tmp_path)[0] == FINISH
    # block boundaries inside the runs
    assert _same_offset(FINISH, wave, monkeypatch, tmp_path, block_lines=77)[0] == out


@pytest.mark.parametrize("seed", range(3))
def test_offset_route_random_programs_byte_for_byte(seed, monkeypatch, tmp_path):
    data = random_program(100 + seed, n=800, tip=_tip)
    out, st, _w = _same_offset(data, wave, monkeypatch, tmp_path, block_lines=300)
    assert out != data and st["lines_changed"] > 300
    assert _same_offset(data, zero, monkeypatch, tmp_path)[0] == data


@pytest.mark.parametrize("bad, says", [
    ("G91", "move in incremental mode (G91)"),
    ("G20", "move in inch mode (G20)"),
    ("G41 D1", "G41: cutter radius compensation"),
    ("G1 X1e5", "unsupported word E"),
])
def test_refusals_inside_a_run_name_the_same_line(bad, says, monkeypatch, tmp_path):
    lines = FINISH.decode().splitlines()
    k = next(i for i, s in enumerate(lines) if s.startswith("G1 ")) + 40
    data = ("\n".join(lines[:k] + [bad] + lines[k:]) + "\n").encode()
    exc = _same_offset(data, wave, monkeypatch, tmp_path)
    assert isinstance(exc, GCodeError) and says in str(exc), exc
    # the mode lines refuse the move after them, the others their own line
    assert ":%d" % (k + 2 if bad in ("G91", "G20") else k + 1) in str(exc), exc
    exc = _same_axis(data, SQUARE, monkeypatch)
    if bad in ("G41 D1", "G1 X1e5"):
        assert isinstance(exc, GCodeError) and says in str(exc), exc


def _lines_one_by_one(data):
    """The lines of ``data`` as a binary file iterates them (the reading before chunks)."""
    out = []
    for k, raw in enumerate(io.BytesIO(data)):
        s = raw.decode("latin-1")
        if k == 0 and s.startswith("\xef\xbb\xbf"):
            s = s[3:]
            if not s:
                continue
        if s.endswith("\r\n"):
            out.append((s[:-2], "\r\n"))
        elif s.endswith("\n"):
            out.append((s[:-1], "\n"))
        else:
            out.append((s, ""))
    return out


def test_lines_read_in_chunks_are_the_lines_of_the_file():
    """Chunks split anywhere: inside a CRLF, inside the byte-order mark, inside a line."""
    rng = np.random.default_rng(7)
    bom = b"\xef\xbb\xbf"
    cases = [b"", bom, bom + b"\n", b"\xef", b"\xef\xbb", b"\r", b"a\r", b"a\rb\n",
             bom + b"x\r\ny", b"\n\n", b"\xef\xbbx\n"]
    cases += [(bom if rng.random() < 0.2 else b"")
              + bytes(rng.choice(list(b"ab\r\n\xef\xbb\xbf "), size=rng.integers(0, 30)))
              for _ in range(2000)]
    for data in cases:
        for chunk in (1, 2, 3, 5, 1 << 14):
            assert list(iter_lines(io.BytesIO(data), chunk)) == _lines_one_by_one(data)
