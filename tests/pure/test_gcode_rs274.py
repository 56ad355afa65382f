# SPDX-License-Identifier: LGPL-2.1-or-later
"""LinuxCNC's own interpreter reads our compensated G-code as we do.

``rs274 -g IN OUT`` (Debian package ``linuxcnc-uspace``; CI installs it) runs LinuxCNC's
RS274/NGC interpreter without a machine and prints the canonical moves a controller would
make: ``STRAIGHT_TRAVERSE(x, y, z, a, b, c)``, ``STRAIGHT_FEED(...)`` and
``ARC_FEED(first_end, second_end, first_centre, second_centre, rotation, axis_end, a, b,
c)`` with the plane's axes in the order of :data:`surfcomp.core.axis.arcs.PLANES`, all in the
program's units with 4 decimals. These tests fail (they do not skip) without it.

For the output of ``python3 -m surfcomp gcode`` with a non-trivial error model, rs274 must
accept the program, and the end points of its moves must be the positions our interpreter
computes for the same text and the commands the compensation wrote; with the zero model
the move lists of input and output are identical.
"""

import math
import os
import re
import subprocess
import sys

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.axis.arcs import PLANES
from surfcomp.core.axis.axis_errors import AxisErrorModel, fit_axis_errors
from surfcomp.core.axis.machine import SimulatedMachine
from surfcomp.io.axis_csv import read_axis_errors, write_axis_errors
from surfcomp.io.gcode import compensate_gcode, parse_gcode
from tests.conftest import REALDATA, ROOT
from tests.probe_checks import own_tool_data

RS274 = "/usr/bin/rs274"
WAVE = os.path.join(REALDATA, "gcode", "CAMotics_GPL", "wave.gcode")
#: rs274 prints 4 decimals of the program's unit
PRINTED = 0.5e-4
TOL_MM = 1e-4

#: hand-written (public domain): arcs in three planes by I/J/K, R (short and long), full
#: helical turns (P2), absolute centres (G90.1), incremental moves and arcs (G91), and two
#: tiny arcs at the model's reference point that need no compensation and stay arcs
ARCS_MM = """\
(surfcomp rs274 test: arcs in three planes, incremental moves; public domain)
G21 G90 G17 G94
G0 X0 Y0 Z5
G1 Z-1 F300
G1 X30 Y0
G3 X40 Y10 I0 J10 (quarter circle, IJK)
G2 X50 Y0 R10 (R format, short)
X40 Y-10 R-10 (R format, long, modal G2)
G3 X40 Y-10 I0 J10 Z-2 P2 (two full helical turns)
G90.1 G2 X50 Y0 I40 J0 (absolute centre)
G91.1
G18 G2 X60 Z-2 I5 K0
G19 G3 Y10 Z-2 J5 K0
G17 G91 G1 X-5 Y-5
G2 X-10 Y0 I-5 J0 (incremental arc)
G3 X5 Y5 R5
G90 G1 X20 Y10
G2 X20.1 Y10 I0.05 J0 (at the reference: stays an arc)
G3 X20 Y10 R0.05
G0 Z5
M2
"""

#: hand-written (public domain): inch units, incremental moves and arcs in three planes
ARCS_INCH = """\
(surfcomp rs274 test: inch, incremental; public domain)
G20 G90 G17 G94
G0 X0 Y0 Z0.2
G1 Z-0.04 F20
G1 X1.0 Y0.5
G91 G3 X0.5 Y0.5 I0 J0.5
G2 X0.5 Y-0.5 R0.5
G1 X0.5 Z-0.01
G18 G2 X0.5 I0.25 K0
G19 G3 Y0.5 J0.25 K0
G17 G90 G1 X1 Y1
G0 Z0.2
M2
"""

_MOVE = re.compile(r"^\s*\d+\s+N\S*\s+(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED)\((.*)\)\s*$")
_UNITS = re.compile(r"USE_LENGTH_UNITS\(CANON_UNITS_(MM|INCHES)\)")
_PLANE = re.compile(r"SELECT_PLANE\(CANON_PLANE_(XY|XZ|YZ)\)")
_PLANE_CODE = {"XY": 17, "XZ": 18, "YZ": 19}


def machine_model(reference=(0.0, 0.0, 0.0)):
    """Errors of some 10 um over 100 mm: scale, squareness, quadratic Z positioning,
    straightness and flatness (every straight move is bent, so long moves are split and
    arcs become G1 pieces)."""
    return AxisErrorModel.from_components(
        scale={"x": 2e-4, "y": -1.5e-4}, positional={"z": (1e-4, 3e-5)},
        straightness={"z(x)": (0.0, 2e-6), "y(x)": (0.0, -1e-6), "x(z)": (0.0, 2e-5)},
        squareness={"xy": 1e-4, "yz": -5e-5}, reference=reference)


def rs274(path, tmp_path):
    """Run rs274 on ``path``; the canonical moves and the raw canonical lines.

    Returns
    -------
    (list of dict, list of str)
        Per move: ``kind`` (the canonical name), ``end`` (mm), ``centre`` (mm, arcs),
        ``plane``, ``rotation``; and the canonical move lines as printed.
    """
    assert os.access(RS274, os.X_OK), (
        "%s is missing: install LinuxCNC's interpreter (Debian package linuxcnc-uspace)"
        % RS274)
    out = tmp_path / (os.path.basename(str(path)) + ".canon")
    run = subprocess.run([RS274, "-g", str(path), str(out)], cwd=str(tmp_path),
                         env=own_tool_data(tmp_path), capture_output=True, text=True,
                         timeout=300)
    errors = [ln for ln in run.stderr.splitlines() if ln.strip() not in ("", "executing")]
    assert run.returncode == 0 and not errors, "rs274 refused %s: %s" % (path, run.stderr)
    text = out.read_text()
    assert "PROGRAM_END" in text, "rs274 stopped before the end of %s" % path
    factor, plane = 1.0, 17
    moves, raw = [], []
    for line in text.splitlines():
        m = _UNITS.search(line)
        if m:
            factor = 25.4 if m.group(1) == "INCHES" else 1.0
        m = _PLANE.search(line)
        if m:
            plane = _PLANE_CODE[m.group(1)]
        m = _MOVE.match(line)
        if not m:
            continue
        raw.append(m.group(1) + "(" + m.group(2) + ")")
        vals = [float(v) for v in m.group(2).split(",")]
        move = {"kind": m.group(1), "plane": plane, "factor": factor}
        if m.group(1) == "ARC_FEED":
            p, q, w = PLANES[plane]
            end, centre = [0.0] * 3, [math.nan] * 3
            end[p], end[q], end[w] = vals[0], vals[1], vals[5]
            centre[p], centre[q] = vals[2], vals[3]
            move["rotation"] = int(vals[4])
            move["end"] = np.array(end) * factor
            move["centre"] = np.array(centre) * factor
        else:
            move["end"] = np.array(vals[:3]) * factor
        moves.append(move)
    return moves, raw


def compensate_cli(program, tmp_path, model, reference, *options):
    """``python3 -m surfcomp gcode`` with measurements of a machine with ``model``'s
    errors; returns the output path and the model the command fitted."""
    csv = tmp_path / "axis_errors.csv"
    write_axis_errors(str(csv), SimulatedMachine(model).measure(
        {"x": np.linspace(-10, 110, 13), "y": np.linspace(-20, 100, 13),
         "z": np.linspace(-10, 10, 11)}), units="um")
    out = tmp_path / ("comp_" + os.path.basename(str(program)))
    ref = ",".join("%g" % v for v in reference)
    run = subprocess.run([sys.executable, "-m", "surfcomp", "gcode", str(program),
                          "--axis-errors", str(csv), "-o", str(out), "--reference", ref]
                         + list(options), cwd=ROOT, capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    fitted = fit_axis_errors(read_axis_errors(str(csv)).data, reference=reference)
    return out, fitted


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_bytes(text.encode("latin-1"))
    return path


def check_same_moves(program, tmp_path, model, reference, decimals=None, printed_mm=None):
    """Compensate ``program``; compare rs274's moves of the output with ours."""
    options = [] if decimals is None else ["--decimals", str(decimals)]
    out, fitted = compensate_cli(program, tmp_path, model, reference, *options)
    data = out.read_bytes()
    # the same compensation in this process: the commands it wrote, where they came from
    res = compensate_gcode(program.read_bytes() if hasattr(program, "read_bytes")
                           else open(program, "rb").read(), fitted, decimals=decimals)
    assert res.output == data
    assert res.stats["lines_changed"] > 0
    ours, _ = parse_gcode(data)
    moves, _raw = rs274(out, tmp_path)
    assert len(moves) == ours.n_moves == res.stats["points"]
    ends = np.array([m["end"] for m in moves])
    # rs274 prints 4 decimals of the program's unit: that is all the tolerance needed
    atol = TOL_MM if printed_mm is None else printed_mm
    assert_allclose(ends, ours.end, rtol=0, atol=atol)
    # where every axis is known, that is the command the compensation wrote
    assert_allclose(ends[res.known], res.emitted[res.known], rtol=0, atol=atol)
    # arcs that stayed arcs: same centre, same direction and turns
    arcs = [k for k, m in enumerate(moves) if m["kind"] == "ARC_FEED"]
    assert [k for k in range(ours.n_moves) if ours.kind[k] >= 2] == arcs
    for k in arcs:
        p, q, _w = PLANES[moves[k]["plane"]]
        assert moves[k]["plane"] == ours.plane[k]
        assert_allclose(moves[k]["centre"][[p, q]], ours.centre[k][[p, q]], rtol=0, atol=atol)
        sign = -1 if ours.kind[k] == 2 else 1
        assert moves[k]["rotation"] == sign * ours.turns[k]
    kinds = {"STRAIGHT_TRAVERSE": 0, "STRAIGHT_FEED": 1}
    assert [kinds.get(m["kind"], 2) for m in moves] == \
        [min(int(v), 2) for v in ours.kind]
    return res, ends, moves


def test_rs274_reads_compensated_wave(tmp_path):
    """CAMotics' wave.gcode (1153 moves, 6-decimal Z words, Y unknown for 25 moves):
    rs274 moves the machine to exactly the points we wrote, and a machine with the fitted
    errors then lands on the programmed points (within the output and print rounding)."""
    model = machine_model()
    res, ends, _moves = check_same_moves(WAVE, tmp_path, model, (0.0, 0.0, 0.0))
    assert res.stats["moves_split"] > 0
    fitted = fit_axis_errors(SimulatedMachine(model).measure(
        {"x": np.linspace(-10, 110, 13), "y": np.linspace(-20, 100, 13),
         "z": np.linspace(-10, 10, 11)}))
    landed = fitted.actual(ends[res.known])
    assert_allclose(landed, res.nominal[res.known], rtol=0, atol=0.5e-4 + PRINTED + 1e-6)
    before = np.abs(model.error(res.nominal[res.known])).max()
    assert before > 0.01              # the errors were worth compensating


def test_rs274_reads_compensated_arcs_mm(tmp_path):
    """Arcs in G17/G18/G19, R arcs, helical full turns, G90.1 centres, G91 arcs: the
    converted arcs' G1 pieces and the two arcs kept as arcs (at the reference point,
    below the output resolution) are the moves rs274 makes."""
    model = machine_model(reference=(20.0, 10.0, -2.0))
    path = _write(tmp_path, "arcs_mm.ngc", ARCS_MM)
    res, ends, moves = check_same_moves(path, tmp_path, model, (20.0, 10.0, -2.0))
    assert res.stats["arcs_converted"] >= 9
    assert sum(m["kind"] == "ARC_FEED" for m in moves) == 2
    assert_allclose(model.actual(ends), res.nominal, rtol=0, atol=0.5e-4 * math.sqrt(3) + 1e-6)


@pytest.mark.parametrize("decimals", [4, None])
def test_rs274_reads_compensated_arcs_inch(tmp_path, decimals):
    """G20 with G91 moves and arcs. rs274 prints 4 decimals of an inch (2.5 um): with
    --decimals 4 every written number is printed exactly and the moves agree within
    1e-4 mm; with the default 5 decimals they agree within rs274's print rounding."""
    model = machine_model(reference=(20.0, 10.0, -2.0))
    path = _write(tmp_path, "arcs_inch.ngc", ARCS_INCH)
    printed = None if decimals == 4 else PRINTED * 25.4 + 1e-9
    res, ends, _moves = check_same_moves(path, tmp_path, model, (20.0, 10.0, -2.0),
                                         decimals=decimals, printed_mm=printed)
    assert (res.program.factor == 25.4).all()
    assert res.stats["arcs_converted"] == 4
    rounding = 0.5 * 10.0 ** -(5 if decimals is None else decimals) * 25.4
    assert_allclose(model.actual(ends), res.nominal, rtol=0,
                    atol=rounding + (0 if printed is None else printed) + 1e-6)


@pytest.mark.parametrize("name", ["wave.gcode", "arcs_mm.ngc", "arcs_inch.ngc"])
def test_rs274_zero_model_moves_are_identical(tmp_path, name):
    """With a zero error model the output is the input, so LinuxCNC makes exactly the same
    canonical moves from both."""
    path = WAVE if name == "wave.gcode" else _write(
        tmp_path, name, ARCS_MM if name == "arcs_mm.ngc" else ARCS_INCH)
    csv = tmp_path / "zero.csv"
    csv.write_text("X EXX EYX EZX\n0 0 0 0\n100 0 0 0\n")
    out = tmp_path / ("zero_" + name)
    run = subprocess.run([sys.executable, "-m", "surfcomp", "gcode", str(path),
                          "--axis-errors", str(csv), "-o", str(out)], cwd=ROOT,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    (tmp_path / "in").mkdir()
    (tmp_path / "out").mkdir()
    _m_in, raw_in = rs274(path, tmp_path / "in")
    _m_out, raw_out = rs274(out, tmp_path / "out")
    prog, _ = parse_gcode(open(path, "rb").read())
    assert len(raw_in) == prog.n_moves >= 10
    assert raw_out == raw_in
