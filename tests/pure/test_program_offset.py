# SPDX-License-Identifier: LGPL-2.1-or-later
"""Direct program compensation on core arrays (issue 27): a ball-end raster program on the
example face, moved by analytic corrections, checked against the exact geometry.

* zero correction: the output is the input, byte for byte;
* a constant correction t: every moved ball centre lies exactly t closer to the nominal
  (its contact point unchanged), so at every contact point the clearance is -t;
* a varying correction: the written pieces follow the exactly moved path within the
  tolerance (checked at 41 points per move);
* bad input (inch, incremental, G41, a wrong ball radius, a program away from the face,
  flat and bull-nose cutters) is refused naming the line.
"""

import numpy as np
import pytest

from surfcomp.core.compensation.program_offset import (
    BallOffset,
    _seg_dist,
    blend_weight,
    parse_tool,
    plan_offset,
)
from surfcomp.core.simulation.presets import werner_surface
from surfcomp.core.surface.projection import project
from surfcomp.errors import GCodeError, InputError
from surfcomp.io.gcode import ProgramFile, parse_gcode
from surfcomp.io.gcode.offset_stream import offset_stream
from tests.toolpath_checks import drop_cutter

R = 3.0
SURF = werner_surface()          # the example face: 45 x 45 mm, outward normal Su x Sv


def raster(radius=R, step=1.0, head="G21 G90 G17", lift=0.0):
    """A drop-cutter raster program on the example face (tips exact to 0.05 um), ``lift``
    mm above it."""
    rows = np.arange(2.0, 44.0, 6.0)
    xs = np.arange(-2.0, 47.01, step)
    lines = ["%", "(raster test program)", head, "M3 S10000", "G0 Z20"]
    for k, y in enumerate(rows):
        xy = np.column_stack([xs if k % 2 == 0 else xs[::-1], np.full(xs.size, y)])
        z, _ = drop_cutter(SURF, 1, xy, np.full(xs.size, 5.0), radius)
        z = z + lift
        lines.append("G0 X%.4f Y%.4f" % tuple(xy[0]))
        lines.append("G1 Z%.4f F600 (plunge)" % z[0])
        lines.extend("G1 X%.4f Y%.4f Z%.4f" % (p[0], p[1], q) for p, q in zip(xy[1:], z[1:]))
        lines.append("G0 Z20")
    lines.append("M2")
    return "\n".join(lines) + "\n"


def run(text, correction, tmp_path, radius=R, blend=1.0, tolerance=5e-4):
    path = tmp_path / "prog.ngc"
    path.write_text(text)
    out = []
    po = offset_stream(ProgramFile(str(path)), out.append, BallOffset(SURF, 1, radius,
                                                                      correction, blend),
                       tolerance=tolerance, source="prog.ngc")
    return "".join(out), po


def zero(u, v):
    return np.zeros(np.shape(u))


def wave(u, v):
    return 0.03 * np.sin(6 * u) * np.cos(5 * v)


@pytest.fixture(scope="module")
def program():
    return raster()


def test_zero_correction_gives_the_input_byte_for_byte(program, tmp_path):
    out, po = run(program, zero, tmp_path)
    assert out == program
    st = po.stats()
    assert st["moves"] > 300 and st["moves_moved"] == 0 and st["lines_changed"] == 0


def test_constant_correction_moves_every_contact_by_t(program, tmp_path):
    t = 0.02
    out, po = run(program, lambda u, v: np.full(np.shape(u), t), tmp_path)
    before, _ = parse_gcode(program)
    after, _ = parse_gcode(out)
    cut0 = before.end[before.kind == 1]
    pr0 = project(SURF, cut0 + [0, 0, R])
    touching = ~pr0.outside & (np.abs(pr0.distance - R) < 1e-4)
    assert touching.sum() > 200
    # the written end points of the contact moves: each input move's end is its last piece
    ends = after.end[after.kind == 1]
    moved = {tuple(np.round(p, 4)) for p in cut0[touching]}
    assert len(moved) > 200
    pr1 = project(SURF, ends + [0, 0, R])
    on = ~pr1.outside & (np.abs(pr1.distance - (R - t)) < 2e-3)
    # moved centres: t closer to the face (4-decimal output: 0.09 um)
    np.testing.assert_allclose(pr1.distance[on], R - t, atol=1e-4)
    assert on.sum() >= touching.sum()
    assert abs(po.stats()["largest_move_mm"] - t) < 1e-4


def test_pieces_follow_the_moved_path_within_the_tolerance(program):
    prog, _ = parse_gcode(program)
    for blend in (1.0, 0.3):
        off = BallOffset(SURF, 1, R, wave, blend)
        op = plan_offset(prog, off, 5e-4, 2.0, 0.5e-4)
        plan = op.plan
        fr = np.linspace(0, 1, 41)
        js = np.flatnonzero(prog.kind == 1)
        P = (prog.start[js][:, None] + (prog.end - prog.start)[js][:, None]
             * fr[None, :, None]).reshape(-1, 3)
        Q = (P + off.displace(P).move).reshape(js.size, fr.size, 3)
        worst = 0.0
        for k, j in enumerate(js):
            a = plan.compensated[plan.offsets[j] - 1]
            poly = np.vstack([a, plan.compensated[plan.offsets[j]:plan.offsets[j + 1]]])
            d = np.min([_seg_dist(Q[k], np.repeat(poly[i:i + 1], fr.size, 0),
                                  np.repeat(poly[i + 1:i + 2], fr.size, 0))
                        for i in range(len(poly) - 1)], axis=0)
            worst = max(worst, float(d.max()))
        assert 1e-5 < worst <= 5e-4 + 1e-9
        assert op.largest > 0.02


def test_blend_weight_is_smooth_and_ends_at_zero():
    e = np.array([-1.0, 0.0, 0.25, 0.5, 1.0, 2.0, np.inf])
    np.testing.assert_allclose(blend_weight(e, 1.0), [1, 1, 1 - 3 / 16 + 2 / 64, 0.5, 0, 0, 0],
                               atol=1e-15)
    h = 1e-6
    slope = (blend_weight(np.array([1.0 - h, h]), 1.0) - blend_weight(np.array([1.0, 0.0]),
                                                                        1.0)) / h
    np.testing.assert_allclose(slope, 0.0, atol=1e-5)


@pytest.mark.parametrize("text, message", [
    ("flat:3", "only ball-end cutters"), ("bull:5:1", "bull-nose"), ("ball:0", "ball:R"),
    ("ball:-1", "ball:R"), ("ball:nan", "ball:R"), ("ball", "ball:R"), ("3", "ball:R")])
def test_tools_other_than_a_ball_are_refused(text, message):
    with pytest.raises(InputError, match=message):
        parse_tool(text)


def test_ball_tool_parsed():
    assert parse_tool("ball:3") == ("ball", 3.0)
    assert parse_tool("BALL:1.5") == ("ball", 1.5)


@pytest.mark.parametrize("edit, line, message", [
    (lambda t: t.replace("G21 G90 G17", "G20 G90 G17"), 5, "inch mode"),
    (lambda t: t.replace("G0 Z20\nG0 X", "G0 Z20\nG91\nG0 X", 1), 7, "incremental"),
    (lambda t: t.replace("G21 G90 G17", "G21 G90 G17 G41 D1"), 3, "radius compensation"),
])
def test_modes_are_refused_with_the_line(program, tmp_path, edit, line, message):
    with pytest.raises(GCodeError, match=message) as exc:
        run(edit(program), wave, tmp_path)
    assert exc.value.line == line


def test_a_work_offset_change_is_refused_when_none_was_named(program, tmp_path):
    text = program.replace("M2\n", "G55\nM2\n")
    with pytest.raises(GCodeError, match="G55 selects a second work coordinate") as exc:
        run(text, wave, tmp_path)
    assert exc.value.line == text.split("\n").index("G55") + 1


def test_a_wrong_ball_radius_is_refused(tmp_path):
    text = raster(radius=2.0)
    # a larger ball than the program's cuts into the face
    with pytest.raises(GCodeError, match="cuts .* into the nominal"):
        run(text, wave, tmp_path, radius=3.0)
    # a smaller one sits off the face on the slopes
    with pytest.raises(GCodeError, match="fit a ball of radius 3.0"):
        run(raster(radius=3.0), wave, tmp_path, radius=1.5)


def test_a_program_too_deep_is_refused_naming_that_too(tmp_path):
    """50 um below the face with the right ball: the refusal blamed only the ball's radius
    or another face."""
    with pytest.raises(GCodeError, match="cuts 0.0[45].. mm into the nominal face .*a smaller "
                                         "ball, for another face, or cuts below this one"):
        run(raster(lift=-0.05), wave, tmp_path)


def test_a_program_away_from_the_face_is_refused(tmp_path):
    text = "G21 G90\nG0 X0 Y0 Z50\nG1 X10 F100\nG1 Y10\nM2\n"
    with pytest.raises(GCodeError, match="no cutting move of the program comes near") as exc:
        run(text, wave, tmp_path)
    assert exc.value.line == 3


@pytest.mark.parametrize("lift, blend", [(0.9, 1.0), (3.0, 5.0)])
def test_a_program_within_the_blend_that_never_touches_the_face_is_refused(tmp_path, lift,
                                                                           blend):
    """Lifted beyond the contact check's reach (a quarter of the radius) but within the
    blend: no contact point to check the stock and the radius on; it was moved by a share
    of the correction and its summary read '0 points ... 0.00 um off the offset'."""
    text = raster(lift=lift)
    with pytest.raises(GCodeError, match="no cutter-location point of the program touches "
                                         "the face") as exc:
        run(text, wave, tmp_path, blend=blend)
    assert exc.value.line is not None and exc.value.file == "prog.ngc"
    assert text.splitlines()[exc.value.line - 1].startswith("G1 ")


def with_arcs(text):
    """The raster program with one row's moves 10 and 30 as arcs through the same ends (R
    format, 1 mm chords, 5 mm radius: in contact with the face) and a full circle at the
    clearance height after it (far from the face)."""
    lines = text.splitlines()
    row = [k for k, ln in enumerate(lines) if ln.startswith("G1 X")][:48]
    for k in (row[10], row[30]):
        lines[k] = lines[k].replace("G1 ", "G2 ") + " R5"
    up = lines.index("G0 Z20", row[-1]) + 1
    lines[up:up] = ["G0 X10 Y10", "G2 X10 Y10 I5 J0 (circle at clearance)", "G1 X10 Y10"]
    return "\n".join(lines) + "\n"


def test_arcs_in_the_region_become_lines_and_arcs_away_stay(program, tmp_path):
    text = with_arcs(program)
    out, po = run(text, wave, tmp_path)
    assert po.stats()["arcs_converted"] == 2
    assert "G2 X10 Y10 I5 J0 (circle at clearance)" in out.splitlines()
    assert sum(ln.startswith("G2 ") for ln in out.splitlines()) == 1
    # the converted arcs follow the moved arc within the tolerance
    prog, _ = parse_gcode(text)
    off = BallOffset(SURF, 1, R, wave, 1.0)
    plan = plan_offset(prog, off, 5e-4, 2.0, 0.5e-4).plan
    from surfcomp.core.compensation.program_offset import _Arcs, _points

    arcs_j = np.flatnonzero(prog.kind == 2)
    arcs = _Arcs(prog, arcs_j)
    fr = np.linspace(0, 1, 41)
    for j in arcs_j[:2]:
        pts = _points(prog, arcs, np.full(fr.size, j), fr)
        Q = pts + off.displace(pts).move
        poly = np.vstack([plan.compensated[plan.offsets[j] - 1],
                          plan.compensated[plan.offsets[j]:plan.offsets[j + 1]]])
        assert len(poly) > 2 and plan.split[j]
        d = np.min([_seg_dist(Q, np.repeat(poly[i:i + 1], fr.size, 0),
                              np.repeat(poly[i + 1:i + 2], fr.size, 0))
                    for i in range(len(poly) - 1)], axis=0)
        assert d.max() <= 5e-4 + 1e-9
    assert plan.keep[arcs_j[2]]
