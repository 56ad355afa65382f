# SPDX-License-Identifier: LGPL-2.1-or-later
"""Bounds on G-code values and axis errors (issue 12): every refusal exits 2, writes nothing."""

import functools
import math
import os

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.cli import gcode as gcode_cli
from surfcomp.core.axis import axis_errors, machine
from surfcomp.core.axis.arcs import arc_steps
from surfcomp.core.axis.axis_errors import AxisErrorModel, fit_axis_errors
from surfcomp.core.axis.moves import (
    MAX_SEGMENTS,
    MIN_SEGMENT_LENGTH,
    check_segments,
    estimate_segments,
    plan_moves,
)
from surfcomp.errors import GCodeError, InputError, MeasurementFileError
from surfcomp.io.axis_csv import read_axis_errors
from surfcomp.io.gcode import (
    CommandsResult,
    CompensationResult,
    GCodeResult,
    compensate_commands,
    compensate_gcode,
    compensate_stream,
    parse_gcode,
    read_gcode,
    stream,
)
from tests.conftest import REALDATA, ROOT

CAMOTICS = os.path.join(REALDATA, "gcode", "CAMotics_GPL")
BEAR = os.path.join(CAMOTICS, "bear.nc")
ARCS = os.path.join(ROOT, "tests", "data", "gcode", "arcs.ngc")
#: X scale 100 um/m, Y straightness: errors of some um over the example programs
ERR_CSV = "axis,position,ex,ey,ez\nX,0,0,0,0\nX,100,0.01,0.002,0\nY,0,0,0,0\nY,100,0,-0.01,0\n"


def bending_model():
    """Every straight move is bent (cross-axis quadratic terms on all three slides)."""
    return AxisErrorModel.from_components(
        straightness={"y(x)": (0, 2e-6), "z(x)": (0, 1e-6), "x(y)": (0, 2e-6),
                      "z(y)": (0, 1e-6), "x(z)": (0, 3e-6), "y(z)": (0, 3e-6)})


def _cli(argv, capsys):
    from surfcomp.cli import main
    rc = main(argv)
    out = capsys.readouterr()
    return rc, out.out, out.err


def _run(tmp_path, capsys, program, *options, csv=ERR_CSV):
    """Run ``gcode`` on ``program`` (a path or text); return rc, stderr, output path."""
    err = tmp_path / "err.csv"
    err.write_text(csv)
    if not os.path.isabs(str(program)):
        src = tmp_path / "in.ngc"
        src.write_text(program)
        program = str(src)
    (tmp_path / "out").mkdir(exist_ok=True)
    out = tmp_path / "out" / "o.ngc"
    rc, _stdout, stderr = _cli(["gcode", str(program), "--axis-errors", str(err), "-o",
                                str(out), "--report", str(tmp_path / "out" / "r.json")]
                               + list(options), capsys)
    return rc, stderr, out


def _refused(tmp_path, capsys, program, *options, csv=ERR_CSV):
    rc, stderr, out = _run(tmp_path, capsys, program, *options, csv=csv)
    assert rc == 2, stderr
    assert "Traceback" not in stderr
    assert os.listdir(out.parent) == [], "a refused run must write nothing"
    return stderr


# ------------------------------------------------------------------------- options
@pytest.mark.parametrize("option, value, what", [
    ("--segment-length", "1e-9", "expected a positive length of at least 0.001 mm"),
    ("--segment-length", "0.0009", "expected a positive length of at least 0.001 mm"),
    ("--segment-length", "nan", "expected a positive length of at least 0.001 mm"),
    ("--segment-length", "inf", "expected a positive length of at least 0.001 mm"),
    ("--segment-length", "-2", "expected a positive length of at least 0.001 mm"),
    ("--tolerance", "0", "expected a positive length in mm"),
    ("--tolerance", "nan", "expected a positive length in mm"),
    ("--tolerance", "-inf", "expected a positive length in mm"),
    ("--arc-tolerance", "0", "expected a positive length in mm"),
    ("--arc-tolerance", "inf", "expected a positive length in mm"),
    ("--max-error", "nan", "expected a positive length in mm"),
    ("--max-error", "0", "expected a positive length in mm"),
])
def test_option_domains(tmp_path, capsys, option, value, what):
    err = _refused(tmp_path, capsys, os.path.join(CAMOTICS, "wave.gcode"),
                   "%s=%s" % (option, value))
    assert "%s %r: %s" % (option, float(value), what) in err


def test_smallest_segment_length_is_accepted(tmp_path, capsys):
    """1 um is the bound itself: a short program is compensated with it."""
    rc, err, out = _run(tmp_path, capsys, "G21 G90\nG0 X0 Y0 Z0\nG1 X0.5 F100\nM2\n",
                        "--segment-length", repr(MIN_SEGMENT_LENGTH))
    assert rc == 0, err
    assert out.read_bytes().startswith(b"G21 G90\n")


def test_too_many_segments_are_refused_before_planning(tmp_path, capsys, monkeypatch):
    """bear.nc has 14 806 mm of cutting moves: 1 um pieces would be 14.8 million points
    (the bound is 10 million); the estimate is exact and refused without sampling.

    The command line reads the program in blocks; a first pass adds up the blocks'
    estimates before any block is planned, so the refusal at the real limit comes at once
    (it used to plan the blocks below the limit first: some 37 s). No block is planned:
    the planning function is counted."""
    prog, _ = parse_gcode(read_gcode(BEAR))
    est = estimate_segments(prog, 0.001, 0.001)
    assert est.total > MAX_SEGMENTS
    assert_allclose(est.length, 14805.65, atol=0.01)
    with pytest.raises(InputError) as refused:
        check_segments(prog, 0.001, 0.001, names=("--segment-length", "--arc-tolerance"),
                       source=BEAR)
    err = str(refused.value)
    assert "%s: --segment-length 0.001 mm" % BEAR in err
    assert "about 1.48e+07 segments, more than the 10000000" in err
    assert "expected a --segment-length of at least 0.00149 mm" in err
    # the suggested length is enough
    assert estimate_segments(prog, 0.00149, 0.001).total <= MAX_SEGMENTS
    # the command line at the real limit: the same refusal, exit 2, nothing written, and
    # not one block planned
    planned = []

    def counted(*args, **kwargs):
        planned.append(args[0].n_moves)
        return plan_moves(*args, **kwargs)

    monkeypatch.setattr(stream, "plan_moves", counted)
    err = _refused(tmp_path, capsys, BEAR, "--segment-length", "0.001")
    assert "%s: --segment-length 0.001 mm" % BEAR in err
    assert "about 1.48e+07 segments, more than the 10000000" in err
    assert "expected a --segment-length of at least 0.00149 mm" in err
    assert planned == []
    # ... and with a lower limit the refusal names that limit and what meets it (0.05 mm
    # pieces: 304 000 points; the first block of 10 000 lines alone needs 173 000, which
    # a run without the first pass planned before it refused)
    limit = 200000
    assert estimate_segments(prog, 0.05, 0.001).total > limit
    monkeypatch.setattr(gcode_cli, "compensate_stream",
                        functools.partial(compensate_stream, max_segments=limit))
    err = _refused(tmp_path, capsys, BEAR, "--segment-length", "0.05")
    assert "%s: --segment-length 0.05 mm" % BEAR in err
    assert "about 3.04e+05 segments, more than the 200000" in err
    assert "expected a --segment-length of at least 0.0801 mm" in err
    assert estimate_segments(prog, 0.0801, 0.001).total <= limit
    assert planned == []
    # the counter counts: an accepted run plans every block
    rc, stderr, _out = _run(tmp_path, capsys, BEAR, "--segment-length", "0.0801")
    assert rc == 0, stderr
    assert sum(planned) == prog.n_moves == 15159


def test_tiny_arc_tolerance_names_its_option(tmp_path, capsys):
    text = "G21 G90 G17\nG0 X10 Y0 Z0\nG2 X10 Y0 I-10 J0 P20\nM2\n"
    err = _refused(tmp_path, capsys, text, "--arc-tolerance", "1e-15")
    assert "--arc-tolerance 1e-15 mm: the program would be split into about" in err
    assert "chords of arcs, set by this tolerance), more than the 10000000" in err
    assert "expected a larger --arc-tolerance" in err


def test_segment_estimate_is_the_number_of_sampled_points():
    """With every move bent and a tolerance of 1e-12 mm every long move is split, so the
    plan keeps every sampled point: its count equals the estimate."""
    for path, seg, arc_tol in ((ARCS, 0.5, 0.001), (BEAR, 2.0, 0.001)):
        prog, _ = parse_gcode(read_gcode(path))
        est = estimate_segments(prog, seg, arc_tol)
        plan = plan_moves(prog, bending_model(), seg, 1e-12, arc_tol)
        assert plan.offsets[-1] == est.total
        # the limit is exact: one point fewer is refused, before anything is sampled
        with pytest.raises(InputError, match="segments.*, more than the %d one"
                           % (est.total - 1)):
            plan_moves(prog, bending_model(), seg, 1e-12, arc_tol,
                       max_segments=int(est.total) - 1)
    # the arcs program by hand: 1 rapid, the feed moves' pieces, each arc's chord count
    prog, _ = parse_gcode(read_gcode(ARCS))
    expect = 0
    for j in range(prog.n_moves):
        if prog.kind[j] == 0:
            expect += 1
        elif prog.kind[j] == 1:
            expect += max(1, math.ceil(np.linalg.norm(prog.end[j] - prog.start[j]) / 0.5))
        else:
            expect += arc_steps(prog.start[j], prog.end[j], prog.centre[j], prog.plane[j],
                                prog.kind[j] == 2, prog.turns[j], 0.5, 0.001)
    assert estimate_segments(prog, 0.5, 0.001).total == expect


def test_library_refuses_settings_out_of_domain():
    prog, _ = parse_gcode(read_gcode(ARCS))
    model = bending_model()
    for kw in ({"segment_length": 0.0}, {"segment_length": float("nan")},
               {"segment_length": 1e-9}, {"tolerance": float("nan")}, {"tolerance": -1.0},
               {"arc_tolerance": 0.0}, {"arc_tolerance": float("inf")}):
        with pytest.raises(InputError):
            plan_moves(prog, model, **kw)
    with pytest.raises(InputError, match="segment length 0.001 mm"):
        check_segments(prog, 0.001, 0.001, max_segments=10)


# ---------------------------------------------------------------------- empty programs
@pytest.mark.parametrize("text", ["", "\n\n", "(only a comment)\n%\n; and another\n", "%\n%"])
def test_empty_program_is_refused(tmp_path, capsys, text):
    err = _refused(tmp_path, capsys, text)
    assert "in.ngc: the program is empty" in err


def test_program_without_moves_but_with_words_is_copied(tmp_path, capsys):
    rc, err, out = _run(tmp_path, capsys, "G21 G90\nM2\n")
    assert rc == 0, err
    assert out.read_bytes() == b"G21 G90\nM2\n"


# ------------------------------------------------------------------- axis error files
@pytest.mark.parametrize("value, what", [
    ("5000", "ex: error '5000' = 5000 mm is larger than --max-error 1 mm"),      # as the CLI
    ("1e308", "ex: error '1e308' = 1e+308 mm is larger than --max-error 1 mm"),  # says it
    ("1e999", "ex: '1e999' is out of range (expected a finite number)"),
])
def test_implausible_axis_errors_are_refused(tmp_path, capsys, value, what):
    """Before: 1e308 wrote a 308-digit X word; 5000 mm wrote X-515.49 for X40."""
    csv = "axis,position,ex,ey,ez\nX,0,0,0,0\nX,100,%s,0,0\n" % value
    err = _refused(tmp_path, capsys, "G21 G90\nG0 X0 Y0 Z0\nG1 X40 F100\nM2\n", csv=csv)
    assert "err.csv:3:3: " + what in err
    if "larger" in what:
        assert "check the unit;" in err and "ex[um], or --units um)" in err


def test_max_error_reader(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("X EXX EYX\n0 0 0\n100 0 12\n")
    with pytest.raises(MeasurementFileError) as exc:
        read_axis_errors(str(path), max_error=1.0)
    assert (exc.value.line, exc.value.column) == (3, 3)
    assert "EYX: error '12' = 12 mm is larger than max_error 1 mm" in str(exc.value)
    assert "EYX[um]" in str(exc.value)
    # without a limit the reader keeps its old behaviour
    assert read_axis_errors(str(path)).data["x"][1][1, 1] == 12.0
    # the limit is in mm after the unit conversion: 1500 um = 1.5 mm
    path.write_text("X EXX\n0 0\n100 0.5\n# um table\nY[mm] EXY[um] EYY[um]\n0 0 0\n"
                    "100 1500 0\n")
    with pytest.raises(MeasurementFileError, match="EXY: error '1500' = 1.5 mm") as exc:
        read_axis_errors(str(path), max_error=1.0)
    assert (exc.value.line, exc.value.column) == (7, 2)
    assert read_axis_errors(str(path), max_error=1.5).data["y"][1][1, 0] == 1.5
    # positions must be finite too
    path.write_text("axis,position,ex,ey,ez\nX,0,0,0,0\nX,1e400,0,0,0\n")
    with pytest.raises(MeasurementFileError, match="position: '1e400' is out of range"):
        read_axis_errors(str(path))


def test_extrapolated_error_beyond_max_error_is_refused(tmp_path, capsys):
    """12 um measured at a position of 100 um (--units um applies to the position column
    too): the slope 0.12 extrapolates to a 4.8 mm error at X40, which is refused at the
    program's line; a larger --max-error accepts it."""
    csv = "X EXX\n0 0\n100 12\n"
    text = "G21 G90\nG0 X0 Y0 Z0\nG1 X40 F100\nM2\n"
    err = _refused(tmp_path, capsys, text, "--units", "um", csv=csv)
    assert "in.ngc:3: the error model predicts an error of 4.8 mm" in err
    assert "more than --max-error 1 mm" in err
    rc, err, out = _run(tmp_path, capsys, text, "--units", "um", "--max-error", "5", csv=csv)
    assert rc == 0, err
    assert b"G1 X35.7143 F100" in out.read_bytes()        # 40 / 1.12


# ------------------------------------------------------------------- G-code numbers
@pytest.mark.parametrize("text, line, column, what", [
    ("G21 G90\nG0 X1%s\n" % ("0" * 400), 2, 4, "number X100000000000... with 401 digits"),
    ("G21 G90\nG0 X2000000 Y0\n", 2, 4, "X2000000: position 2e+06 mm is beyond any"),
    ("G20 G90\nG0 X0 Y50000\n", 2, 7, "Y50000: position 1.27e+06 mm is beyond"),
    ("G21 G90\nG0 X999999\nG91\nG0 X1\nX1\n", 5, 1, "X1: position 1e+06 mm is beyond"),
    ("G21 G90\nG0 X0 Y0\nG2 X10 Y0 R2000000\n", 3, 11, "R2000000: arc radius 2e+06 mm"),
    ("G21 G90\nG0 X0 Y0\nG2 X0 Y0 I1500000 J0\n", 3, 10, "I1500000: arc centre 1.5e+06 mm"),
    ("G21 G90\nG0 X0 Y0\nG2 X0 Y0 I1 J0 P2000000\n", 3, None, "P2000000: expected at most"),
])
def test_out_of_range_numbers_are_refused(text, line, column, what):
    with pytest.raises(GCodeError) as exc:
        compensate_gcode(text.encode(), bending_model(), source="t.ngc")
    assert (exc.value.line, exc.value.column) == (line, column), str(exc.value)
    if what is not None:
        assert what in str(exc.value)


def test_non_finite_points_are_refused_by_the_model():
    model = bending_model()
    with pytest.raises(InputError, match="cannot compensate 1 non-finite point"):
        model.compensate([[0.0, 0.0, 0.0], [np.nan, 1.0, 2.0]])
    with pytest.raises(InputError, match="no finite compensation for 1 point"):
        model.compensate([[1e200, 0.0, 0.0]])


# --------------------------------------------------------------------- output bounds
def test_output_bounds():
    """The compensated points move by at most the model's largest error (+10 %, + the
    rounding); a point moved farther, or not finite, is refused naming its line."""
    model = AxisErrorModel.from_components(scale={"x": 1e-3})
    res = compensate_gcode(b"G21 G90\nG0 X0 Y0 Z0\nG1 X40 F100\nG1 X100\n", model,
                           source="t.ngc")
    assert_allclose(res.max_correction(), 100 - 100 / 1.001, atol=0.6e-4)
    assert res.line.tolist() == [2, 3, 4]
    good = CompensationResult(b"", {}, res.nominal, res.emitted, res.known, [], None, res.line)
    good.check_bounds(model, 0.0)
    for bad_point, what in (([100.2, 0, 0], "moves it by 0.2 mm"),
                            ([np.nan, 0, 0], "moves it by nan mm")):
        emitted = res.emitted.copy()
        emitted[2] = bad_point
        bad = CompensationResult(b"", {}, res.nominal, emitted, res.known, [], None, res.line)
        with pytest.raises(GCodeError) as exc:
            bad.check_bounds(model, 0.0, source="t.ngc")
        assert str(exc.value).startswith("t.ngc:4: the compensated command")
        assert what in str(exc.value) and "nothing was written" in str(exc.value)


def test_path_commands_are_bounded_and_numbered():
    model = AxisErrorModel.from_components(scale={"x": 0.5})
    cmds = [("G0", {"X": 0.0, "Y": 0.0, "Z": 0.0}), ("G1", {"X": 40.0, "F": 10.0})]
    res = compensate_commands(cmds, model, source="op")
    assert res.line.tolist() == [1, 2]
    with pytest.raises(GCodeError, match=r"^op:2: the error model predicts an error of 20 mm"):
        res.check_bounds(model, 0.0, source="op", max_error=1.0)


# --------------------------------------------------------------- one result shape
def test_results_share_one_shape():
    model = AxisErrorModel.from_components(scale={"x": 1e-3})
    text = compensate_gcode(b"G21 G90\nG0 X0 Y0 Z0\nG1 X40 F100\n", model)
    cmds = compensate_commands([("G0", {"X": 0.0, "Y": 0.0, "Z": 0.0}),
                                ("G1", {"X": 40.0, "F": 100.0})], model)
    assert isinstance(text, GCodeResult) and isinstance(cmds, CommandsResult)
    assert text.output is text.data and cmds.output is cmds.commands
    for field in ("stats", "nominal", "emitted", "known", "warnings", "program", "line"):
        assert hasattr(text, field) and hasattr(cmds, field)
    assert text.stats.keys() == cmds.stats.keys()
    assert_allclose(text.nominal, cmds.nominal)
    assert_allclose(text.emitted, cmds.emitted, atol=0.5e-4)
    assert text.max_correction() == pytest.approx(cmds.max_correction(), abs=0.5e-4)
    assert text.predicted(model).keys() == cmds.predicted(model).keys()


def test_model_input_errors_are_input_errors():
    """Bad input to the model raises InputError (exit 2), not a bare ValueError."""
    with pytest.raises(InputError, match="non-finite values"):
        AxisErrorModel(slope=np.full((3, 3), np.nan))
    with pytest.raises(InputError, match="axis must be one of x, y, z"):
        AxisErrorModel.from_components(scale={"w": 1e-3})
    with pytest.raises(InputError, match="points must have shape"):
        AxisErrorModel.zero().error([1.0, 2.0])
    with pytest.raises(InputError, match="axis x: 2 positions but 1 error rows") as exc:
        fit_axis_errors({"x": ([0.0, 1.0], [[0.0, 0.0, 0.0]])}, source="e.csv")
    assert exc.value.file == "e.csv"
    # SimulatedMachine moved to core/axis/machine.py; the old import still works
    assert axis_errors.SimulatedMachine is machine.SimulatedMachine


def test_work_offset_change_without_a_named_first_offset_is_refused(tmp_path, capsys):
    """No offset named: the moves run in the active one (G54 at power-up); G55 after them
    is a change, refused with its line like G54 ... G55."""
    text = "G21 G90 G17\nG0 X10 Y10 Z-1\nG1 X100 F100\nG55\nG0 X10 Y10\nG1 X100\nM2\n"
    stderr = _refused(tmp_path, capsys, text)
    assert "in.ngc:4:1: G55 selects a second work coordinate system after moves in G54" \
        in stderr


def test_report_counts_the_rows_each_fit_used(tmp_path, capsys):
    """Two X runs, one giving EXX and one EYX: each fit counts and names its own 3 rows."""
    import json
    text = "G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X100 Y50\nG1 X150 Y150 Z-5\nM2\n"
    csv = "X EXX\n0 0\n100 0.010\n200 0.020\nX EYX\n0 0\n100 0.002\n200 0.004\n"
    rc, stderr, out = _run(tmp_path, capsys, text, csv=csv)
    assert rc == 0, stderr
    fits = {f["function"]: f for f in json.loads(
        (out.parent / "r.json").read_text())["model"]["fits"]}
    assert (fits["delta_x(x)"]["n"], fits["delta_x(x)"]["lines"]) == (3, [2, 3, 4])
    assert (fits["delta_y(x)"]["n"], fits["delta_y(x)"]["lines"]) == (3, [6, 7, 8])
    assert fits["delta_z(x)"]["lines"] == [2, 3, 4, 6, 7, 8]
    assert abs(fits["delta_x(x)"]["b1"] - 1e-4) < 1e-12
    assert abs(fits["delta_y(x)"]["b1"] - 2e-5) < 1e-12
    assert "EZX in no table, taken as 0" in stderr


BASIC = "G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X100 Y50\nG1 X150 Y150 Z-5\nG0 Z5\nM2\n"
#: errors of tens of um over 200 mm of X and Y (the brief's example)
TENS_CSV = ("axis,position,ex,ey,ez\nX,0,0,0,0\nX,50,0.010,0.002,0.001\nX,100,0.025,0.004,0.003\n"
            "X,150,0.045,0.007,0.005\nX,200,0.070,0.010,0.008\nY,0,0,0,0\n"
            "Y,100,0.006,-0.018,0.002\nY,200,0.012,-0.044,0.006\nZ,-100,0.002,0.001,-0.030\n"
            "Z,0,0,0,0\n")


@pytest.mark.parametrize("decimals, after_um", [("0", "750.8"), ("1", "71.12")])
def test_rounding_coarser_than_the_corrections_is_refused(tmp_path, capsys, decimals,
                                                          after_um):
    """0 or 1 decimals land the tool farther from the program than no compensation at all
    (60.74 um before): refused, nothing written, the option to change named."""
    stderr = _refused(tmp_path, capsys, BASIC, "--decimals", decimals, csv=TENS_CSV)
    assert ("the compensated program would be worse than the input: the error model "
            "predicts up to %s um at the program's points after compensation against 60.74 "
            "um before, as its numbers are rounded to %s decimal place(s)"
            % (after_um, decimals)) in stderr
    assert "--decimals 3 or more" in stderr


def test_two_decimals_improve_the_program_and_are_written(tmp_path, capsys):
    rc, stderr, out = _run(tmp_path, capsys, BASIC, "--decimals", "2", csv=TENS_CSV)
    assert rc == 0, stderr
    import json
    pred = json.loads((out.parent / "r.json").read_text())["predicted"]
    assert abs(pred["before"]["max_mm"] - 0.060739) < 1e-6
    assert pred["after"]["max_mm"] < 0.0069           # 6.87 um: rounding to 0.01 mm


def test_library_refuses_an_output_worse_than_its_input():
    model = fit_axis_errors(read_axis_errors("e.csv", text=TENS_CSV).data)
    with pytest.raises(GCodeError, match="would be worse than the input") as exc:
        compensate_gcode(BASIC.encode(), model, source="t.ngc", decimals=0)
    assert exc.value.options == ("decimals",)
    res = compensate_gcode(BASIC.encode(), model, source="t.ngc", decimals=3)
    assert res.predicted(model)["after"]["max_mm"] < 1e-3


def test_arc_points_outside_the_measured_travel_are_warned_about(tmp_path, capsys):
    """A full circle from (20, 20) around (0, 20) ends inside X 0..200 but its written
    points reach X = -20: they are extrapolated and must be warned about."""
    import json
    import re
    text = "G21 G90 G17\nG0 X20 Y20 Z-1\nG1 Z-2 F100\nG2 X20 Y20 I-20 J0\nG1 X25\nM2\n"
    rc, stderr, out = _run(tmp_path, capsys, text, csv=TENS_CSV)
    assert rc == 0, stderr
    m = re.search(r"(\d+) program point\(s\) lie outside the measured travel \(up to "
                  r"([0-9.]+) mm\)", stderr)
    assert m, stderr
    count, dist = int(m.group(1)), float(m.group(2))
    written = [ln for ln in out.read_text().splitlines()
               if re.match(r"^X-", ln) or " X-" in ln]
    assert count == len(written) > 100        # every written point with X < 0, no other
    assert abs(dist - 20.0) < 0.01            # the circle's leftmost point, X = -20
    assert m.group(0) in json.loads((out.parent / "r.json").read_text())["warnings"][0]
