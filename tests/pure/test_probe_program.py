# SPDX-License-Identifier: LGPL-2.1-or-later
"""Probing programs of a plan, read by LinuxCNC's own interpreter (rs274) and, for the
Fanuc dialect, by parsing (no Fanuc interpreter is available here: the test parses the
program's words and checks the same geometry: every G31 along the planned -normal to the
overtravel point, DPRNT of #5061-#5063 after each point's last touch, POPEN/PCLOS around
them)."""

import argparse
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.cli import plan as plan_cli
from surfcomp.cli.plan_program import write_from_args
from surfcomp.errors import InputError
from surfcomp.io.probe_program import ProbeSettings, program_text, write_probe_program
from tests.probe_checks import PRINTED, check_probe_moves, rs274_moves

R = 1.5
HASH = "0123456789abcdef" * 4


def dome_plan(n=37, seed=3):
    """Points on a spherical cap (radius 60 mm, top at z = 10), normals up to 40 degrees
    off the spindle axis, in a random (not sorted) order."""
    rng = np.random.default_rng(seed)
    theta = np.radians(rng.uniform(0, 40, n))
    phi = rng.uniform(0, 2 * np.pi, n)
    u = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], 1)
    return ["P%02d" % k for k in range(n)], np.array([0, 0, -50.0]) + 60 * u, u


def settings(**kw):
    base = dict(tip_radius=R, safe_z=10.0, plan_hash=HASH, clearance=4.0, stand_off=2.0,
                overtravel=1.0)
    base.update(kw)
    return ProbeSettings(**base)


@pytest.mark.parametrize("second, clearance", [(False, 4.0), (True, 4.0), (False, 1.5)])
def test_linuxcnc_program_read_by_rs274(tmp_path, second, clearance):
    """Clearance 1.5 mm below the 2 mm stand-off: no fast approach, the rapid move goes to
    the stand-off point."""
    ids, P, N = dome_plan()
    prog = tmp_path / "probe.ngc"
    summary = write_probe_program(str(prog), ids, P, N,
                                  settings(second_touch=second, clearance=clearance))
    text = prog.read_text()
    assert "(plan sha256 0123456789abcdef0123456789abcdef)" in text
    assert "(tip radius 1.5000 mm, 37 points" in text and "dialect linuxcnc" in text
    assert text.index("(PROBEOPEN probe.log)") < text.index("G38.2") < \
        text.rindex("G38.2") < text.index("(PROBECLOSE)")
    moves = rs274_moves(prog, tmp_path)
    probes, worst = check_probe_moves(moves, P, N, R, 1.0)
    assert len(probes) == (2 if second else 1) * len(ids) == summary["log_lines"]
    # every probe starts on the line through its point: the stand-off (2 mm) or, for the
    # second touch, 1 mm back off from rs274's trip point (the end point, 1 mm past)
    starts = np.array([a for a, _b in probes])
    per = 2 if second else 1
    want = np.repeat(P + R * N, per, axis=0) + np.repeat(N, per, axis=0) * (
        np.tile([2.0, 0.0] if second else [2.0], len(ids))[:, None])
    assert_allclose(starts, want, atol=2 * PRINTED, rtol=0)
    # traverses: horizontal ones at the safe height 10 + R + clearance, vertical ones down
    # to the retract point (clearance or stand-off out along the normal) and back up
    trav = [(a, b) for kind, a, b in moves if kind == "STRAIGHT_TRAVERSE"][1:]
    safe = 10 + R + clearance
    assert len(trav) == 3 * len(ids)        # per point: across, down, up
    ends = np.array([b for a, b in trav[1::3]])
    assert_allclose(ends, P + (R + max(clearance, 2.0)) * N, atol=PRINTED, rtol=0)
    assert ("G1 " in text.split("(point 1 ")[1].split("G38.2")[0]) == (clearance > 2.0)
    for a, b in trav:
        assert (abs(a[2] - safe) < 1e-9 and abs(b[2] - safe) < 1e-9) or \
            np.allclose(a[:2], b[:2], atol=1e-9)
    # the summary's traverse length is rs274's (after the first move from the origin to Z)
    got = sum(np.linalg.norm(b - a) for a, b in trav[1:])
    assert_allclose(summary["travel"]["traverse"], got, atol=1e-3 * len(trav))
    print("rs274: %d probe moves, largest angle to -normal %.5f deg, traverse %.1f mm"
          % (len(probes), worst, got))


def _fanuc_words(line):
    return {m.group(1): m.group(2) for m in re.finditer(r"([XYZF])(\[[^\]]*\]|[-0-9.]+)", line)}


def test_fanuc_program_by_parsing(tmp_path):
    """No Fanuc interpreter here: the program is parsed and its geometry checked."""
    ids, P, N = dome_plan(12)
    s = settings(dialect="fanuc", second_touch=True, touch_feed=60.0)
    prog = tmp_path / "probe.nc"
    summary = write_probe_program(str(prog), ids, P, N, s)
    lines = prog.read_text().splitlines()
    assert lines[0] == "%" and lines[-1] == "%"
    assert lines[1] == "O1000 (SURFCOMP PROBING PROGRAM, DIALECT FANUC)"
    assert all(ln == ln.upper() for ln in lines)
    assert "(PLAN SHA256 0123456789ABCDEF0123456789ABCDEF)" in lines
    assert any(ln.startswith("(TIP RADIUS 1.5000 MM, 12 POINTS") for ln in lines)
    body = lines[lines.index("POPEN") + 1:lines.index("PCLOS")]
    assert "M30" in lines[lines.index("PCLOS"):]
    here, point, touches, prints = None, -1, [], []
    for ln in body:
        w = _fanuc_words(ln)
        if ln.startswith("(POINT "):
            point += 1
            assert ln.startswith("(POINT %d %s)" % (point + 1, ids[point]))
        elif ln.startswith("G31"):
            end = np.array([float(w[a]) for a in "XYZ"])
            assert_allclose(end, P[point] + (R - 1.0) * N[point], atol=PRINTED, rtol=0)
            d = (end - here) / np.linalg.norm(end - here)
            assert np.degrees(np.arccos(min(1.0, -d @ N[point]))) < 0.01
            touches.append((point, float(w["F"])))
            here = end          # as rs274 does: the trip point taken at the end
        elif ln.startswith("DPRNT"):
            assert ln == "DPRNT[#5061[44]*#5062[44]*#5063[44]*0*0*0*0*0*0]"
            prints.append(point)
        elif ln.startswith(("G00", "G01")):
            new = here.copy() if here is not None else np.zeros(3)
            for k, a in enumerate("XYZ"):
                if a in w:
                    v = w[a]
                    new[k] = (here[k] + float(v[6:-1]) if v.startswith("[#506") else float(v))
                    if v.startswith("[#506"):
                        assert v.startswith("[#%d" % (5061 + k))
            here = new
    assert [p for p, _f in touches] == sorted(2 * list(range(12)))
    assert [f for _p, f in touches] == [60.0, 12.0] * 12     # slower second touch
    assert prints == list(range(12)) and summary["log_lines"] == 12


@pytest.mark.parametrize("change, words", [
    (dict(normals=np.array([[0, 0, 1.01]])), ("P00", "unit length")),
    (dict(normals=np.array([[0, 0.6, -0.8]])), ("P00", "points down")),
    (dict(points=np.array([[0, 0, 10.5]])), ("P00", "above safe_z 10")),
    (dict(points=np.array([[np.nan, 0, 0]])), ("P00", "not finite")),
    (dict(ids=["a", "b"]), ("2 ids",)),
    (dict(settings=settings(dialect="heidenhain")), ("dialect 'heidenhain'",)),
    (dict(settings=settings(touch_feed=2000.0)), ("touch_feed 2000",)),
    (dict(settings=settings(overtravel=0.0)), ("overtravel 0",)),
    (dict(settings=settings(safe_z=None)), ("safe_z",)),
    (dict(settings=settings(work_offset="G92")), ("work_offset 'G92'",)),
    (dict(settings=settings(log_file="a)b")), ("log_file",)),
    (dict(settings=settings(second_touch=True, backoff=3.0)), ("backoff 3",)),
    (dict(settings=settings(log_file="")), ("log_file ''",)),
    (dict(settings=settings(second_feed=7.0)), ("second_feed 7 mm/min", "second_touch")),
    (dict(settings=settings(backoff=1.5)), ("backoff 1.5 mm", "second_touch")),
    (dict(settings=settings(log_file="x.log", dialect="fanuc")),
     ("log_file 'x.log'", "dialect fanuc")),
])
def test_bad_plans_and_settings_write_nothing(tmp_path, change, words):
    case = dict(ids=["P00"], points=np.array([[0, 0, 9.0]]), normals=np.array([[0, 0, 1.0]]),
                settings=settings())
    case.update(change)
    prog = tmp_path / "probe.ngc"
    prog.write_text("old\n")
    with pytest.raises(InputError) as err:
        write_probe_program(str(prog), case["ids"], case["points"], case["normals"],
                            case["settings"])
    for w in words:
        assert w in str(err.value)
    assert prog.read_text() == "old\n" and sorted(p.name for p in tmp_path.iterdir()) == \
        ["probe.ngc"]


@pytest.mark.parametrize("change, text", [
    (dict(touch_feed=2000.0), "--touch-feed 2000 mm/min is above --feed 1000 mm/min"),
    (dict(second_touch=True, backoff=3.0), "--backoff 3 mm is larger than --stand-off 2 mm"),
    (dict(tool=0), "--tool 0: expected a whole number from 1 to 9999"),
    (dict(dialect="siemens"), "--dialect 'siemens' is not known"),
    (dict(work_offset="G92"), "--work-offset 'G92' is not known"),
    (dict(log_file=""), "--probe-log '': expected the name of the file LinuxCNC writes"),
    (dict(log_file="a;b"), "--probe-log 'a;b': a file name in a G-code comment"),
    (dict(second_feed=7.0), "--second-feed 7 mm/min applies to the second touch only "
                            "(expected --second-touch with it, or no --second-feed)"),
    (dict(backoff=1.5), "--backoff 1.5 mm applies to the second touch only (expected "
                        "--second-touch with it, or no --backoff)"),
    (dict(log_file="x.log", dialect="fanuc"),
     "--probe-log 'x.log' applies to --dialect linuxcnc only (expected no --probe-log with "
     "--dialect fanuc"),
])
def test_refusals_name_the_options(change, text):
    """A setting that cannot be used or would not take effect is refused with a message
    whose options the command line shows as its flags."""
    from surfcomp.cli.option_flags import shown

    with pytest.raises(InputError) as err:
        settings(**change).validate()
    assert text in shown(err.value)


def test_program_options_from_the_command_line(tmp_path):
    """The options as the plan command adds them, through its own parser (the tip radius,
    stand-off and clearance are the plan's)."""
    parser = argparse.ArgumentParser()
    plan_cli.add_parser(parser.add_subparsers())
    ids, P, N = dome_plan(8)
    prog = tmp_path / "p.ngc"
    base = ["plan", str(tmp_path / "n.step"), "-o", str(tmp_path / "plan.csv")]
    args = parser.parse_args(base + ["--program", str(prog), "--tip-radius", "1.5", "--tool", "7",
                              "--work-offset", "G55", "--clearance", "4", "--stand-off", "2",
                              "--overtravel", "1", "--feed", "800", "--touch-feed", "40",
                              "--probe-log", "run1.txt"])
    lines = write_from_args(args, ids, P, N, 10.0, HASH)
    text = prog.read_text()
    assert "T7 M6\nG43 H7\nG55\n" in text and "(PROBEOPEN run1.txt)" in text
    assert " F40\n" in text and " F800\n" in text
    assert lines[0].startswith("Program:      %s (linuxcnc, 8 points, tip radius 1.5 mm, G55, "
                               "probe log run1.txt, 8 lines" % prog)
    assert lines[-1] == "wrote %s" % prog
    moves = rs274_moves(prog, tmp_path, tool=7, diameter=3.0)
    check_probe_moves(moves, P, N, 1.5, 1.0)
    _text, path = program_text(ids, P, N, ProbeSettings(
        tip_radius=1.5, safe_z=10.0, clearance=4.0, stand_off=2.0, overtravel=1.0))
    total = float(re.search(r"Travel: +([0-9.]+) mm", lines[1]).group(1))
    pos, _kinds = path.polyline()
    assert abs(total - np.linalg.norm(np.diff(pos, axis=0), axis=1).sum()) < 0.05
    assert write_from_args(parser.parse_args(base), ids, P, N, 10.0, HASH) == []
    with pytest.raises(SystemExit):
        parser.parse_args(base + ["--dialect", "siemens"])
