# SPDX-License-Identifier: LGPL-2.1-or-later
"""G-code parsing, axis error compensation and byte-exact rewriting (surfcomp.io.gcode)."""

import math
import os
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.axis.axis_errors import AxisErrorModel, SimulatedMachine, fit_axis_errors
from surfcomp.errors import GCodeError
from surfcomp.io.gcode import (
    _fmt,
    arc_points,
    arc_steps,
    compensate_commands,
    compensate_gcode,
    parse_gcode,
    read_gcode,
    tokenize,
)
from tests.conftest import REALDATA, ROOT

DATA = os.path.join(ROOT, "tests", "data", "gcode")
CAMOTICS = os.path.join(REALDATA, "gcode", "CAMotics_GPL")
LINUXCNC = os.path.join(REALDATA, "gcode", "LinuxCNC_GPL")
#: golden programs: (name, segment length, arc tolerance)
GOLDEN = [("basic", 10.0, 0.01), ("arcs", 5.0, 0.01), ("inch_incremental", 10.0, 0.01)]


def golden_model():
    """Large, readable errors: X scale 1000 um/m, Y -500 um/m, Z quadratic 20 um/m^2 ...,
    flatness z(x) 1 um/m^2 ..., squareness 100 urad (XY) and 200 urad (ZX)."""
    return AxisErrorModel.from_components(
        scale={"x": 1e-3, "y": -5e-4}, positional={"z": (0.0, 2e-5)},
        straightness={"z(x)": (0.0, 1e-6)}, squareness={"xy": 1e-4, "zx": 2e-4})


def _read(name):
    with open(os.path.join(DATA, name), "rb") as fh:
        return fh.read()


def comp(text, model=None, **kw):
    model = golden_model() if model is None else model
    data = text.encode("latin-1") if isinstance(text, str) else text
    return compensate_gcode(data, model, source="t.ngc", **kw)


def output_lines(res):
    return res.data.decode("latin-1").split("\n")


def check_lands_on_nominal(res, model, atol):
    """Re-parse the output: its moves are the emitted commands, and a machine with the
    model's errors brings each of them onto the programmed (nominal) point."""
    out, _ = parse_gcode(res.data, start=res.program.start_pos if res.program.start_known
                         else None)
    assert out.n_moves == res.stats["points"]
    known = res.known
    assert_allclose(out.end[known], res.emitted[known], rtol=0, atol=1e-9)
    landed = model.actual(out.end[known])
    assert_allclose(landed, res.nominal[known], rtol=0, atol=atol)
    return out


# ---------------------------------------------------------------------- golden files
@pytest.mark.parametrize("name, seg, arc_tol", GOLDEN)
def test_golden_programs(name, seg, arc_tol):
    data = _read(name + ".ngc")
    res = compensate_gcode(data, golden_model(), segment_length=seg, arc_tolerance=arc_tol,
                           source=name)
    assert res.data == _read(name + ".out.ngc")
    # rounding to 4 decimals (mm) / 5 decimals (inch): at most half a unit per axis
    half = 0.5e-4 if name != "inch_incremental" else 0.5e-5 * 25.4
    check_lands_on_nominal(res, golden_model(), atol=half * 1.002)
    # the zero model leaves every byte alone
    assert compensate_gcode(data, AxisErrorModel.zero(), segment_length=seg).data == data


def test_golden_basic_hand_checked_lines():
    """basic.ngc with golden_model(): the X move N40 to X40 at Y0 Z-2 is split into four
    10 mm pieces (its flatness term z(x) = 1e-6 x^2 bends it by 0.4 um); the last piece
    ends at X = 40 / 1.001 = 39.96004 (scale 1000 um/m, Z-2 adds 200 urad * -2 mm = -0.4 um
    along X), Y = -(1e-4 * 40) / (1 - 5e-4) = -0.004."""
    lines = output_lines(comp(_read("basic.ngc"), segment_length=10.0))
    i = lines.index("N40 X9.9904 Y-0.001 Z-2.0002 F1200")
    assert lines[i + 1:i + 4] == ["X19.9804 Y-0.002 Z-2.0005", "X29.9704 Y-0.003 Z-2.001",
                                  "X39.9604 Y-0.004 Z-2.0017"]
    x = (40 - 2e-4 * -2) / 1.001
    assert float(lines[i + 3].split()[0][1:]) == pytest.approx(x, abs=0.5e-4)
    # terse line keeps its style, gains Y between X and Z; comments and case are kept
    assert "N60 X31.9685Y4.9993Z-2.1011" in lines
    assert "N80 x20.4799 y12.2541 z-1.7505 (lower case words)" in lines
    # unchanged lines stay byte for byte
    for keep in ("T1 M6 (ball nose 6 mm)", "S12000 M3", "N100 M5", "%", "G54"):
        assert keep in lines


def test_golden_arcs_both_ends_and_circle():
    """Every converted arc starts where the previous move ended and ends at the
    compensated end point; its pieces land (through the model) on the programmed circle
    within the arc tolerance, on both ends exactly (up to rounding)."""
    model = golden_model()
    data = _read("arcs.ngc")
    res = compensate_gcode(data, model, segment_length=5.0, arc_tolerance=0.01)
    prog = res.program
    assert res.stats["arcs_converted"] == 6
    landed = model.actual(res.emitted)
    # both ends: the nominal of every move's last piece is the programmed end point
    k = 0
    for j in range(prog.n_moves):
        while not np.allclose(res.nominal[k], prog.end[j], atol=1e-12):
            k += 1
        assert_allclose(landed[k], prog.end[j], atol=1e-4)
    # the pieces of the quarter circle (move 2, G3 centre 0,0 r 10) land on the circle
    first = np.flatnonzero(np.isclose(res.nominal[:, 1], 10.0) & np.isclose(
        res.nominal[:, 0], 0.0))[0]
    quarter = landed[2:first + 1]
    r = np.hypot(quarter[:, 0], quarter[:, 1])
    assert_allclose(r, 10.0, atol=1e-4)
    # the chord between two landed points stays within the arc tolerance of the circle
    mid = (quarter[1:] + quarter[:-1]) / 2
    sag = 10.0 - np.hypot(mid[:, 0], mid[:, 1])
    assert sag.max() < 0.01 and sag.min() > -1e-4


# ------------------------------------------------------------------ zero model
def test_zero_model_round_trip_is_byte_identical():
    cases = [
        b"G21 G90\r\nG0 X1 Y2 Z3\r\nG2 X3 Y2 I1 J0\r\n",          # CRLF
        b"G21\nG90\nG1 X1 F100\nX2 ; last line without newline",
        "G21 G90\n(Fr\xe4ser \xf8 6 mm)\nG1 X1.50000 Y-0.0 F1000.\n".encode("latin-1"),
        b"%\nG20 G91.1 G90\nG0 X0 Y0 Z0\nG91 G1 X0.1\nY.2\nG90\n%\n",
        b"",
    ]
    for data in cases:
        assert compensate_gcode(data, AxisErrorModel.zero()).data == data


@pytest.mark.parametrize("name", ["bear.nc", "wave.gcode"])
def test_zero_model_round_trip_real_programs(name):
    data = read_gcode(os.path.join(CAMOTICS, name))
    res = compensate_gcode(data, AxisErrorModel.zero())
    assert res.data == data
    assert res.stats["lines_changed"] == 0 and res.stats["lines_added"] == 0


# ---------------------------------------------------------------- real programs
def test_real_programs_parse():
    bear, lines = parse_gcode(read_gcode(os.path.join(CAMOTICS, "bear.nc")))
    assert len(lines) == 15163 and bear.n_moves == 15159
    ends = bear.endpoints(known_only=True)
    assert_allclose(ends.min(axis=0), [0.0, 0.0, -17.368])
    assert_allclose(ends.max(axis=0), [79.999, 79.998, 20.0])
    assert (bear.kind == 1).sum() == 15152     # G1, mostly modal axis words
    wave, wl = parse_gcode(read_gcode(os.path.join(CAMOTICS, "wave.gcode")))
    assert len(wl) == 2309 and wave.n_moves == 1153
    # wave.gcode cuts before it gives Y: Y is unknown for its first 25 moves
    assert (~wave.known[:, 1]).sum() == 25
    assert_allclose(wave.end[-2], [92.0, 92.0, -1.802791])


@pytest.mark.parametrize("name, line, col, what", [
    ("3D_Chips.ngc", 8, 1, "LinuxCNC parameter or expression '#<xscale> = 1.0'"),
    ("gridprobe.ngc", 11, 1, "LinuxCNC parameter or expression '#1=0"),
])
def test_real_programs_with_parameters_are_refused(name, line, col, what):
    path = os.path.join(LINUXCNC, name)
    with pytest.raises(GCodeError) as exc:
        compensate_gcode(read_gcode(path), golden_model(), source=path)
    assert (exc.value.line, exc.value.column) == (line, col)
    assert str(exc.value).startswith("%s:%d:%d: %s" % (path, line, col, what))
    assert exc.value.exit_code == 2


def test_bear_compensated_on_a_simulated_machine():
    """bear.nc on a machine with golden_model()'s errors, compensated with that model:
    before max 88 um / RMS 46 um at the program's points, after at most the output
    rounding (0.05 um per axis); re-parsing the output gives the same commands."""
    path = os.path.join(CAMOTICS, "bear.nc")
    model = golden_model()
    res = compensate_gcode(read_gcode(path), model, segment_length=2.0, source=path)
    # half a unit of the 4th decimal, times 1 + the model's largest slope
    out = check_lands_on_nominal(res, model, atol=0.5e-4 * 1.002)
    pred = res.predicted(model)
    assert 0.085 < pred["before"]["max_mm"] < 0.092
    assert 0.044 < pred["before"]["rms_mm"] < 0.048
    assert pred["after"]["max_mm"] < 0.5e-4 * math.sqrt(3)
    # long X passes are split (flatness z(x) is quadratic), every line was touched
    assert res.stats["moves_split"] == 60 and res.stats["lines_added"] == 771
    assert out.n_moves == 15159 + 771
    # every original line is still there in order, with its own words (N, F, S, M kept)
    text = res.data.decode()
    assert text.startswith("T1M6\nG21\nG17\nG0Z19.992\nG0X-0.004Y0.000S15000M3\n")
    assert text.endswith("M30\n")


def test_wave_compensated_with_a_fitted_model():
    """wave.gcode (feed before every move) with a model fitted from noisy measurements of
    a simulated machine: the feed lines are untouched; the actual positions of the known
    points are within the fit error of the programmed ones."""
    path = os.path.join(CAMOTICS, "wave.gcode")
    machine = SimulatedMachine(golden_model())
    data = machine.measure({"x": np.linspace(0, 100, 11), "y": np.linspace(0, 100, 11),
                            "z": np.linspace(-10, 10, 9)}, noise=0.0005, seed=7)
    fit = fit_axis_errors(data)
    raw = read_gcode(path)
    res = compensate_gcode(raw, fit, source=path)
    lines_in = raw.decode().split("\n")
    lines_out = res.data.decode().split("\n")
    assert len(lines_in) == len(lines_out)
    assert [a for a in lines_in if a.startswith("F")] == \
        [b for b in lines_out if b.startswith("F")]
    out, _ = parse_gcode(res.data)
    k = out.known.all(axis=1)
    err_after = np.linalg.norm(machine.actual(out.end[k]) - res.nominal[res.known], axis=1)
    err_before = np.linalg.norm(machine.error(res.nominal[res.known]), axis=1)
    assert err_before.max() > 0.09
    assert err_after.max() < 0.002
    assert any("Y position" in w for w in res.warnings)


# --------------------------------------------------------------------- refusals
@pytest.mark.parametrize("text, line, what", [
    ("G21 G90\nG0 X0 Y0 Z5\nG81 X1 Y1 Z-2 R1\n", 3, "G81: canned cycles"),
    ("G21\nG41 D1\n", 2, "G41: cutter radius compensation"),
    ("G21\nG0 X0 Y0 Z0\nG92 X10\n", 3, "G92: the program changes its coordinate system"),
    ("G21\nG93\n", 2, "G93: inverse time feed"),
    ("G21\nO100 sub\n", 2, "O word 'O100'"),
    ("G21\nM98 P100\n", 2, "M98: subprograms"),
    ("G21\nG0 X0 Y0 Z0 A90\n", 3 - 1, "axis word A"),
    ("G21\nG0 X[1+2]\n", 2, "parameter or expression"),
    ("G21\nG0 X#1\n", 2, "parameter or expression"),
    ("G21\nG0 X1 (open comment\n", 2, "comment opened with '(' is not closed"),
    ("G21\nG0 X1.2.3\n", 2, "malformed number"),
    ("G21\nG0 X1 E5\n", 2, "unsupported word E5"),
    ("G21\nG91 G0 X1\n", 2, "incremental (G91) X move before any absolute X position"),
    ("G21 G90\nG0 X0 Y0\nG2 X10 Y0 I4 J0\n", 3, "arc end point is not on the circle"),
    ("G21 G90\nG0 X0 Y0\nG2 X10 Y0 R4\n", 3, "radius R4 is smaller than half"),
    ("G21 G90\nG0 X0 Y0\nG2 X10 Y0\n", 3, "without I/J or R"),
    ("G21 G90 G54\nG0 X0 Y0\nG55\n", 3, "G55 selects a second work coordinate system"),
    ("G21 G90\nG0 X0 Y0\nG55\n", 3, "G55 selects a second work coordinate system after "
     "moves in G54 (none was named"),
    ("G21 G90\nX1\n", 2, "axis words but no motion mode"),
    ("G21 G90\nG0 X0\n/G1 X5\n", 3, "block delete"),
    ("G21 G90\nG0 X0 Y0 Z0\nG1 X100 M30\n", 3, "program stop"),
    ("G21 G90\nG1 X1 I2\n", 2, "I word on a line without G2/G3"),
    ("G21 G90\nG0 X1 X2\n", 2, "two X words"),
    ("G21 G90\nG0 G1 X2\n", 2, "two motion codes"),
    ("G21 G90\nG12 I5\n", 2, "G12: this mode"),
    ("G21 G90\nG65 P9000\n", 2, "G65 is not supported"),
])
def test_refusals_name_the_line(text, line, what):
    with pytest.raises(GCodeError) as exc:
        comp(text, segment_length=10.0)
    assert exc.value.line == line, str(exc.value)
    assert what in str(exc.value)
    assert str(exc.value).startswith("t.ngc:%d" % line)


def test_g54_after_moves_without_a_named_offset_is_no_change():
    """A program naming no work offset runs in G54 (power-up): G54 named after moves keeps
    it, so the program is compensated as if G54 had come first, with a warning."""
    body = "G0 X10 Y10 Z-1\nG1 X100 F100\nG54\nG0 X10 Y10\nG1 X100 Y50\nM2\n"
    late = comp("G21 G90 G17\n" + body, segment_length=10.0)
    first = comp("G21 G90 G17 G54\n" + body, segment_length=10.0)
    assert output_lines(late)[1:] == output_lines(first)[1:]
    assert_allclose(late.emitted, first.emitted, rtol=0, atol=0)
    assert [w for w in late.warnings if "G54 on line 4 after moves" in w]
    assert not [w for w in first.warnings if "G54" in w]


def test_tokenizer_spans_comments_and_case():
    words, block = tokenize("/n10 g1x-.5 Y 2. (c;omment) z+3 ; rest (x9)")
    assert block
    assert [(w.letter, w.text, w.decimals) for w in words] == [
        ("N", "10", 0), ("G", "1", 0), ("X", "-.5", 1), ("Y", "2.", 0), ("Z", "+3", 0)]
    assert words[3].start == 12 and words[3].end == 16


# ---------------------------------------------------------------- geometry
def test_arc_points_analytic():
    # G17 G2 from (10, 0) around the origin, a quarter turn to (0, -10): clockwise
    p = arc_points([10, 0, 0], [0, -10, 0], [0, 0, 0], 17, True, 1, 8)
    ang = np.arctan2(p[:, 1], p[:, 0])
    assert_allclose(ang, -np.pi / 2 * np.arange(1, 9) / 8, atol=1e-12)
    assert_allclose(np.hypot(p[:, 0], p[:, 1]), 10.0, atol=1e-12)
    # G18 (Z first, X second): G3 from Z = 5 half a turn to Z = -5 passes X = +5
    p = arc_points([0, 0, 5], [0, 0, -5], [0, 0, 0], 18, False, 1, 2)
    assert_allclose(p, [[5, 0, 0], [0, 0, -5]], atol=1e-12)
    # G19 (Y first, Z second) helix: full turn with P2 = two turns, Y/Z back, X linear
    p = arc_points([0, 3, 0], [4, 3, 0], [0, 0, 0], 19, False, 2, 8)
    assert_allclose(p[3], [2, 3, 0], atol=1e-12)
    assert_allclose(p[1], [1, -3, 0], atol=1e-12)
    # segment count: chord <= segment length and sagitta <= tolerance
    n = arc_steps([10, 0, 0], [10, 0, 0], [0, 0, 0], 17, True, 1, 1000.0, 0.001)
    dphi = 2 * np.pi / n
    assert 10 * (1 - np.cos(dphi / 2)) <= 0.001
    assert 10 * (1 - np.cos(2 * np.pi / (n - 1) / 2)) > 0.001
    assert arc_steps([10, 0, 0], [0, 10, 0], [0, 0, 0], 17, False, 1, 1.0, 1.0) == 16


def test_long_move_is_split_only_where_the_error_bends_it():
    """A 50 mm X move: with a quadratic flatness term z(x) the compensated path is curved,
    so the move is split into 2 mm pieces that land on the straight line; a purely linear
    model is an affine map (straight stays straight): no split."""
    prog = "G21 G90\nG0 X0 Y0 Z0\nG1 X50 F100\n"
    quad = AxisErrorModel.from_components(straightness={"z(x)": (0.0, 4e-6)})
    res = comp(prog, quad, segment_length=2.0)
    assert res.stats["moves_split"] == 1 and res.stats["lines_added"] == 24
    landed = quad.actual(res.emitted)
    assert_allclose(landed[:, 1:], 0.0, atol=0.5e-4)
    assert_allclose(np.diff(res.nominal[1:, 0]), 2.0, atol=1e-12)
    lin = AxisErrorModel.from_components(scale={"x": 1e-3}, squareness={"xz": 1e-4})
    res = comp(prog, lin, segment_length=2.0)
    assert res.stats["moves_split"] == 0
    assert output_lines(res)[2] == "G1 X49.95 Z-0.005 F100"
    # the midpoint of the written chord lands on the programmed line (affinity)
    a, b = res.emitted[0], res.emitted[1]
    assert_allclose(lin.actual((a + b) / 2), [25.0, 0.0, 0.0], atol=1e-4)


def test_terse_line_gets_missing_axis_words_in_order_and_crlf_kept():
    data = b"G21 G90\r\nG0 X0 Y0 Z-1\r\nG1X10Z-1F50\r\n"
    model = AxisErrorModel.from_components(squareness={"xy": 1e-3})
    res = compensate_gcode(data, model)
    assert res.data == b"G21 G90\r\nG0 X0 Y0 Z-1\r\nG1X10Y-0.01Z-1F50\r\n"
    res = compensate_gcode(data, AxisErrorModel.from_components(
        straightness={"y(x)": (0, 1e-4)}), segment_length=5.0)
    # a rewritten number keeps a decimal point (X10 -> X5.0: no controller reads it as um)
    assert res.data == (b"G21 G90\r\nG0 X0 Y0 Z-1\r\nG1X5.0Y-0.0025Z-1F50\r\n"
                        b"X10.0Y-0.01\r\n")


def test_modal_arc_after_a_converted_arc_gets_its_g_code():
    """With 1 decimal the first arc's compensation (up to 0.25 mm) needs G1 pieces while
    the second (below 0.05 mm) stays an arc: it relied on the modal G2, which the pieces
    replaced by G1, so G2 is written on it."""
    model = AxisErrorModel.from_components(straightness={"y(x)": (0.0, 1e-4)},
                                           reference=(50.0, 0.0, 0.0))
    prog = "G21 G90 G17\nG0 X0 Y0 Z0\nG2 X49 Y0 R24.5\nX51 Y0 R1\nX52 Y0 R0.5\n"
    res = comp(prog, model, decimals=1, segment_length=100.0, arc_tolerance=1.0)
    lines = output_lines(res)
    assert lines[2].startswith("G1 X") and "R" not in lines[2]
    assert res.stats["arcs_converted"] == 1
    i = lines.index("G2 X51 Y0 R1")
    assert lines[i + 1] == "X52 Y0 R0.5"


def test_incremental_program_equals_the_absolute_one():
    model = golden_model()
    absolute = ("G21 G90\nG0 X10 Y10 Z1\nG1 Z-1 F100\nX30\nY25 Z-2\nG2 X40 Y25 I5 J0\n"
                "G1 X10\n")
    incremental = ("G21 G90\nG0 X10 Y10 Z1\nG91\nG1 Z-2 F100\nX20\nY15 Z-1\n"
                   "G2 X10 Y0 I5 J0\nG1 X-30\n")
    ra = comp(absolute, model, segment_length=3.0)
    ri = comp(incremental, model, segment_length=3.0)
    assert_allclose(ri.nominal, ra.nominal, atol=1e-12)
    assert_allclose(ri.emitted, ra.emitted, atol=1e-12)
    check_lands_on_nominal(ri, model, atol=0.5e-4 * 1.002)


def test_incremental_steps_do_not_drift():
    """1000 steps of 0.1 mm in G91 under a scale error: the written increments add up to
    the compensated absolute end exactly (no rounding accumulates)."""
    model = AxisErrorModel.from_components(scale={"x": 3.3e-4})
    prog = "G21 G90\nG0 X0 Y0 Z0\nG91\n" + "G1 X0.1 F100\n" * 1000
    res = comp(prog, model)
    incs = [float(line.split()[1][1:]) for line in output_lines(res)[3:-1]]
    assert len(incs) == 1000
    assert round(sum(incs), 4) == round(100.0 / (1 + 3.3e-4), 4)
    assert abs(sum(incs) - 100.0 / (1 + 3.3e-4)) <= 0.5e-4 + 1e-9


def test_inch_program_converts_units():
    model = AxisErrorModel.from_components(scale={"x": 1e-3})
    res = comp("G20 G90\nG0 X0 Y0 Z0\nG1 X2.0 F10\n", model)
    assert output_lines(res)[2] == "G1 X1.998 F10"
    assert_allclose(res.nominal[-1], [50.8, 0, 0])
    res = comp("G20 G90\nG0 X0 Y0 Z0\nG1 X2.12345 F10\n", model)
    assert output_lines(res)[2] == "G1 X2.12133 F10"      # 5 decimals in inch


def test_unknown_axes_are_never_written():
    model = AxisErrorModel.from_components(squareness={"zx": 1e-3, "zy": 1e-3})
    prog = "G21 G90\nG1 Z-2 F100\nG1 X5 Z-3\nG1 Y5\n"
    res = comp(prog, model)
    lines = output_lines(res)
    # Z-2: X and Y unknown -> only Z written (unchanged); X5 Z-3: X written, Y still not;
    # Y5: Y written, X' = 5 - 1e-3 * -3 is what the machine holds already
    assert lines[1] == "G1 Z-2 F100"
    assert lines[2] == "G1 X5.003 Z-3"
    assert lines[3] == "G1 Y5.003"
    assert any("2 cutting move(s) from line 2 on" in w and "Y position" in w
               for w in res.warnings)
    # with a known start, the start axes are written from the first move on
    res = comp(prog, model, start=(0.0, 0.0, 0.0))
    assert output_lines(res)[1] == "G1 X0.002 Y0.002 Z-2 F100"
    assert not any("cutting move" in w for w in res.warnings)


def test_g53_and_g28_pass_through_and_forget_the_position():
    model = AxisErrorModel.from_components(scale={"x": 1e-3, "z": 1e-3})
    prog = ("G21 G90\nG0 X10 Y0 Z10\nG53 G0 Z0\nG1 X20 F100\nG28\nG0 X10 Y0 Z10\n")
    lines = output_lines(comp(prog, model))
    assert lines[2] == "G53 G0 Z0"
    assert lines[3] == "G1 X19.98 F100"            # Z is not known: not written
    assert lines[4] == "G28"
    assert lines[5] == "G0 X9.99 Y0 Z9.99"


def test_number_format():
    assert _fmt(1.5, 4, 3) == "1.500"
    assert _fmt(1.23456, 4, 1) == "1.2346"
    assert _fmt(-0.00001, 4, 1) == "0.0"
    assert _fmt(2.0, 4, 1) == "2.0"


# ------------------------------------------------------------ Path-style commands
def test_compensate_commands_keeps_feeds_and_other_commands():
    model = golden_model()
    cmds = [("(Profile)", {}), ("G0", {"Z": 5.0}), ("G0", {"X": 0.0, "Y": 0.0}),
            ("M3", {"S": 1000.0}), ("G1", {"X": 0.0, "Y": 0.0, "Z": -1.0, "F": 2.0}),
            ("G1", {"X": 40.0, "Y": 0.0, "Z": -1.0, "F": 10.0}),
            ("G2", {"X": 50.0, "Y": 0.0, "Z": -1.0, "I": 5.0, "J": 0.0, "K": 0.0, "F": 10.0}),
            ("G0", {"Z": 5.0})]
    zero = compensate_commands(cmds, AxisErrorModel.zero())
    assert zero.commands == list(range(len(cmds)))
    res = compensate_commands(cmds, model, segment_length=5.0, arc_tolerance=0.01)
    kept = [c for c in res.commands if isinstance(c, int)]
    assert kept == [0, 3]
    new = [c for c in res.commands if not isinstance(c, int)]
    moves = [c for c in new if c[0] == "G1"]
    # F on every piece: 2.0 on the two pieces of the 6 mm plunge (quadratic Z error),
    # 10.0 on the pieces of the X pass and of the arc
    fs = [c[1]["F"] for c in moves]
    assert fs[:2] == [2.0, 2.0] and set(fs[2:]) == {10.0}
    assert res.stats["moves_split"] == 2 and res.stats["arcs_converted"] == 1
    assert not any(k in c[1] for c in moves for k in "IJK")
    landed = model.actual(res.emitted[res.known])
    assert_allclose(landed, res.nominal[res.known], atol=1e-9)
    # order of non-moves is kept: the comment first, M3 after the rapid moves
    assert res.commands[0] == 0 and res.commands.index(3) == 3


def test_compensate_commands_refusals():
    with pytest.raises(GCodeError, match=r"^op:3: G81: canned cycles"):
        compensate_commands([("G0", {"Z": 5.0}), ("G99", {}),
                             ("G81", {"X": 1.0, "Y": 1.0, "Z": -1.0, "R": 1.0})],
                            golden_model(), source="op")
    with pytest.raises(GCodeError, match=r"^op:1: G20 \(inch\) in a FreeCAD Path"):
        compensate_commands([("G20", {})], golden_model(), source="op")
    with pytest.raises(GCodeError, match="command 'G1X' is not understood"):
        compensate_commands([("G1X", {})], golden_model(), source="op")


# ----------------------------------------------------------------------------- CLI
def _cli(argv, capsys):
    from surfcomp.cli import main
    rc = main(argv)
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_cli_compensates_bear_and_writes_a_report(tmp_path, capsys):
    import json

    from surfcomp.io.axis_csv import write_axis_errors
    machine = SimulatedMachine(golden_model())
    csv = tmp_path / "err.csv"
    write_axis_errors(str(csv), machine.measure({"x": np.linspace(0, 80, 9),
                                                 "y": np.linspace(0, 80, 9),
                                                 "z": np.linspace(-20, 20, 9)}), units="um")
    src = os.path.join(CAMOTICS, "bear.nc")
    (tmp_path / "o").mkdir()
    out = tmp_path / "o" / "bear_comp.nc"
    rep = tmp_path / "o" / "bear.json"
    rc, stdout, stderr = _cli(["gcode", src, "--axis-errors", str(csv), "-o", str(out),
                               "--segment-length", "2", "--report", str(rep)], capsys)
    assert rc == 0, stderr
    expected = compensate_gcode(read_gcode(src), fit_axis_errors(
        {a: v for a, v in machine.measure({"x": np.linspace(0, 80, 9),
                                           "y": np.linspace(0, 80, 9),
                                           "z": np.linspace(-20, 20, 9)}).items()}))
    assert out.read_bytes() == expected.data
    assert "before compensation: max 88." in stdout
    assert "after compensation:  max 0.0" in stdout
    # the model's figures, not a promise for the machine beyond what was measured
    assert re.search(r"these figures are the error model's own: on the machine the "
                     r"compensation is as good as the model, whose error functions fit the "
                     r"measurements within RMS \d+\.\d{3} um \(worst: .+\) and know nothing "
                     r"beyond the measured travel", stdout)
    assert "as good as that fit" not in stdout
    assert "delta_z(z)" in stdout and "squareness [urad] XY 100.000" in stdout
    assert "no G90/G91 before the first move (line 4)" in stderr
    r = json.loads(rep.read_text())
    assert r["schema"] == "surfcomp-gcode-report/1" and r["command"] == "gcode"
    assert r["program"]["lines_added"] == expected.stats["lines_added"]
    assert r["predicted"]["after"]["max_mm"] < 1e-4
    assert_allclose(r["model"]["components"]["squareness"]["xy"], 1e-4, atol=1e-12)
    assert len(r["model"]["fits"]) == 9 and r["model"]["fits"][0]["lines"][0] == 2
    assert sorted(os.listdir(out.parent)) == ["bear.json", "bear_comp.nc"]


def test_cli_zero_errors_copy_the_program(tmp_path, capsys):
    csv = tmp_path / "zero.csv"
    csv.write_text("X EXX EYX EZX\n0 0 0 0\n100 0 0 0\n")
    src = os.path.join(CAMOTICS, "wave.gcode")
    out = tmp_path / "wave.ngc"
    rc, stdout, err = _cli(["gcode", src, "--axis-errors", str(csv), "-o", str(out)], capsys)
    assert rc == 0, err
    assert out.read_bytes() == read_gcode(src)
    assert "0 lines changed, 0 added" in stdout


def test_cli_refuses_and_writes_nothing(tmp_path, capsys):
    csv = tmp_path / "e.csv"
    csv.write_text("axis,position,ex,ey,ez\nX,0,0,0,0\nX,100,0.01,0,0\n")
    src = os.path.join(LINUXCNC, "3D_Chips.ngc")
    out = tmp_path / "chips.ngc"
    rc, _out, err = _cli(["gcode", src, "--axis-errors", str(csv), "-o", str(out),
                          "--report", str(tmp_path / "r.json")], capsys)
    assert rc == 2
    assert "%s:8:1: LinuxCNC parameter" % src in err
    assert sorted(os.listdir(tmp_path)) == ["e.csv"]
    rc, _out, err = _cli(["gcode", os.path.join(CAMOTICS, "bear.nc"), "--axis-errors",
                          str(csv), "-o", str(out), "--segment-length", "0"], capsys)
    assert rc == 2 and "--segment-length 0.0: expected a positive length" in err
    rc, _out, err = _cli(["gcode", os.path.join(CAMOTICS, "bear.nc"), "--axis-errors",
                          str(csv), "-o", str(out), "--start", "1,2"], capsys)
    assert rc == 2 and "--start '1,2': expected three numbers" in err
    assert sorted(os.listdir(tmp_path)) == ["e.csv"]
