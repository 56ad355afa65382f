# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp plan``: the plan read back by the measurement readers, bad input
(exit 2, nothing written), and reach against a solid with a roof over part of the face."""

import hashlib
import os
import subprocess
import sys

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.app.nominal import load_nominal
from surfcomp.errors import MeasurementFileError
from surfcomp.io.measurements import read_measurements
from surfcomp.io.pointfiles import read_point_file
from tests.app.helpers import EXAMPLE_STEP, ROOT, run_in_process


def run_plan(*args):
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "surfcomp", "plan", *map(str, args),
                           "--quiet"], cwd=ROOT, capture_output=True, text=True, timeout=300,
                          env=env)


def plan_in_process(*args):
    """``plan ARGS --quiet`` in this process (tests/app/helpers.py), for the runs whose
    plan a test checks."""
    return run_in_process("plan", *args, "--quiet")


def test_plan_round_trip_through_the_measurement_reader(tmp_path):
    out = plan_in_process(EXAMPLE_STEP, "-o", tmp_path / "plan.csv", "--layout", "grid",
                          "--count", "9x7", "--tip-radius", "1.5", "--edge-margin", "1")
    assert out.returncode == 0, out.stderr
    # a plan is no measurement: the reader accepts its nominal points without deviations
    # only when told it reads a plan
    with pytest.raises(MeasurementFileError, match="no deviation"):
        read_measurements(tmp_path / "plan.csv")
    ms = read_measurements(tmp_path / "plan.csv", plan=True)
    assert ms.ids == ["P%d" % k for k in range(1, 64)]
    assert ms.deviation is None and ms.measured is None and ms.units == "mm"
    # the points lie on the nominal face (6 decimals written), the normals are its outward
    # unit normals (9 decimals), and every point is 2.5 mm or more from the border
    nom = load_nominal(EXAMPLE_STEP)
    import FreeCAD
    import Part

    for p, n in zip(ms.nominal, ms.normal):
        d, pairs, info = nom.face.distToShape(Part.Vertex(FreeCAD.Vector(*p)))
        assert d < 1e-6
        u, v = nom.face.Surface.parameter(FreeCAD.Vector(*p))
        occ = nom.face.normalAt(u, v)
        assert_allclose(n, (occ.x, occ.y, occ.z), atol=2e-6)
        edge = min(nom.face.Edges, key=lambda e: e.distToShape(Part.Vertex(
            FreeCAD.Vector(*p)))[0])
        assert edge.distToShape(Part.Vertex(FreeCAD.Vector(*p)))[0] >= 2.5 - 1e-6
    # the printed hash is the file's
    sha = hashlib.sha256((tmp_path / "plan.csv").read_bytes()).hexdigest()
    assert "SHA-256 %s" % sha in out.stdout
    # the printed travel is the path through the retract positions (r + max(stand-off 2,
    # clearance 5) mm out, where the probing program's rapid descent ends)
    so = ms.nominal + 6.5 * ms.normal
    travel = np.linalg.norm(np.diff(so, axis=0), axis=1).sum()
    line = next(t for t in out.stdout.splitlines() if t.startswith("Order:"))
    assert float(line.split("travel ")[1].split(" mm")[0]) == pytest.approx(travel, abs=0.06)


def test_plan_xyzijk_read_as_pcdmis(tmp_path):
    out = plan_in_process(EXAMPLE_STEP, "-o", tmp_path / "plan.xyz", "--format", "xyzijk",
                          "--layout", "adaptive", "--points", "50")
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "plan.xyz").read_text().startswith("XYZIJK    METRIC\n")
    pts = read_point_file(tmp_path / "plan.xyz", fmt="auto")
    csv = plan_in_process(EXAMPLE_STEP, "-o", tmp_path / "plan.csv", "--layout", "adaptive",
                          "--points", "50")
    assert csv.returncode == 0, csv.stderr
    ms = read_measurements(tmp_path / "plan.csv", plan=True)
    assert len(pts.measured) == 50
    assert_allclose(pts.measured, ms.nominal, atol=0)
    assert_allclose(pts.normal, ms.normal, atol=1e-12)


def _header(path, start):
    return next(ln for ln in path.read_text().splitlines() if ln.startswith(start))


@pytest.mark.parametrize("order", ["nearest", "serpentine", "auto"])
def test_plan_header_says_what_the_visiting_order_is(tmp_path, order):
    """The header names the order the rows are in and says what it is; a nearest-neighbour
    plan is one (every next retract position, 6 mm out along the normal, is the nearest
    one not visited yet, within 1 um)."""
    out = plan_in_process(EXAMPLE_STEP, "-o", tmp_path / "plan.csv", "--count", "10x10",
                          "--order", order)
    assert out.returncode == 0, out.stderr
    line = _header(tmp_path / "plan.csv", "# visiting order")
    travel = float(line.split("travel ")[1].split(" mm")[0])
    want = {"nearest": "nearest (greedy nearest neighbour from the first point of the "
                       "serpentine)",
            "serpentine": "serpentine (row by row, every other row reversed)",
            "auto": "serpentine (row by row, every other row reversed; order auto: the "
                    "shorter of serpentine and nearest)"}[order]
    assert line == "# visiting order %s, travel %.3f mm between retract positions" % (
        want, travel)
    assert "row order" not in line
    ms = read_measurements(tmp_path / "plan.csv", plan=True)
    so = ms.nominal + 6.0 * ms.normal       # tip radius 1 + clearance 5
    assert travel == pytest.approx(np.linalg.norm(np.diff(so, axis=0), axis=1).sum(),
                                   abs=2e-3)
    if order == "nearest":
        for k in range(len(so) - 1):
            rest = np.linalg.norm(so[k + 1:] - so[k], axis=1)
            assert rest[0] <= rest.min() + 1e-3


@pytest.mark.parametrize("args,message", [
    (("--count", "0x5"), "--count '0x5': expected at least 1 point in each direction"),
    (("--count", "1001x1000"), "1001000 points, expected at most 1000000"),
    (("--layout", "adaptive", "--points", "0"), "--points 0: expected a whole number"),
    (("--layout", "adaptive", "--points", "1000001"), "--points 1000001: expected a whole"),
    (("--tip-radius", "60"), "--tip-radius 60 mm is larger than the face's smallest concave "
                             "radius 55.8"),
    (("--edge-margin", "30"), "no reachable point on the face: the grid layout placed 100 "
                              "point(s) and every one was dropped (100 closer than the "
                              "margin to the boundary"),
    (("--max-tilt", "0"), "no reachable point"),
])
def test_bad_input_exit_2_nothing_written(tmp_path, args, message):
    target = tmp_path / "plan.csv"
    dropped = tmp_path / "dropped.csv"
    out = run_plan(EXAMPLE_STEP, "-o", target, "--dropped", dropped, *args)
    assert out.returncode == 2, out.stdout + out.stderr
    assert message in out.stderr
    assert not target.exists() and not dropped.exists()
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("args,message", [
    (("--probe-log", ""), "--probe-log '': expected the name of the file LinuxCNC writes the "
                          "probe log to"),
    (("--second-feed", "7", "--backoff", "1.5"),
     "--second-feed 7 mm/min applies to the second touch only (expected --second-touch"),
    (("--backoff", "1.5"), "--backoff 1.5 mm applies to the second touch only"),
    (("--probe-log", "x.log", "--dialect", "fanuc"),
     "--probe-log 'x.log' applies to --dialect linuxcnc only"),
    (("--touch-feed", "2000"), "--touch-feed 2000 mm/min is above --feed 1000 mm/min"),
    (("--tool", "0"), "--tool 0: expected a whole number from 1 to 9999"),
])
def test_probe_options_that_cannot_take_effect_are_refused(tmp_path, args, message):
    target, prog = tmp_path / "plan.csv", tmp_path / "probe.ngc"
    out = run_plan(EXAMPLE_STEP, "-o", target, "--program", prog, *args)
    assert out.returncode == 2, out.stdout + out.stderr
    assert message in out.stderr
    assert os.listdir(tmp_path) == []


def test_program_options_without_program_are_refused(tmp_path):
    out = run_plan(EXAMPLE_STEP, "-o", tmp_path / "plan.csv", "--dialect", "fanuc")
    assert out.returncode == 2, out.stdout + out.stderr
    assert ("--dialect is an option of the probing program: expected --program PROBE.ngc "
            "with it, or no --dialect") in out.stderr
    out = run_plan(EXAMPLE_STEP, "-o", tmp_path / "plan.csv", "--second-touch", "--probe-log",
                   "a.log")
    assert out.returncode == 2, out.stdout + out.stderr
    assert "--second-touch, --probe-log are options of the probing program" in out.stderr
    assert os.listdir(tmp_path) == []


# ------------------------------------------------------------------ a solid with a roof
def _roofed_solid(path, roof_bottom):
    """A 60 x 40 x 10 mm block with a 5 mm wall at x = 40..45 and a roof from x = 20 to 45
    whose underside is at z = ``roof_bottom``: the floor x = 0..40 at z = 10 lies partly
    under it. Writes a STEP file; returns the floor's face name."""
    import FreeCAD
    import Part

    V = FreeCAD.Vector
    base = Part.makeBox(60, 40, 10)
    wall = Part.makeBox(5, 40, roof_bottom + 5 - 10, V(40, 0, 10))
    roof = Part.makeBox(25, 40, 5, V(20, 0, roof_bottom))
    solid = base.fuse([wall, roof]).removeSplitter()
    solid.exportStep(str(path))
    back = Part.read(str(path))
    k = next(i for i, f in enumerate(back.Faces)
             if abs(f.BoundBox.ZMin - 10) < 1e-9 and abs(f.BoundBox.ZMax - 10) < 1e-9
             and abs(f.BoundBox.XMax - 40) < 1e-6 and abs(f.BoundBox.XMin) < 1e-6)
    return "Face%d" % (k + 1)


_DESCENT = ("the rapid descent from the safe height comes closer than --clearance to another "
            "face of the part")


@pytest.mark.parametrize("roof_bottom,reason,text", [
    (25.0, "part-descent", _DESCENT),
    (12.5, "part-approach", "on the approach along the normal"),
])
def test_solid_roof_hides_the_floor(tmp_path, roof_bottom, reason, text):
    """Floor points under the roof are dropped (the ball, r 1 mm, meets the roof on the way
    down from the safe height, or, with the roof 2.5 mm above the floor, already on the
    approach from the 2 mm stand-off). The rapid descent keeps the ball the clearance (5 mm)
    from the roof's edge (x = 20): floor points up to x = 20 - 1 - 5 = 14 are kept, those
    from there to the ball radius from the edge are dropped as closer than the clearance;
    the plan's top Z is the roof's top."""
    step = tmp_path / "roofed.step"
    face = _roofed_solid(step, roof_bottom)
    out = plan_in_process(step, "--face", face, "-o", tmp_path / "plan.csv", "--count",
                          "41x9", "--dropped", tmp_path / "dropped.csv", "--tip-radius", "1",
                          "--edge-margin", "0.5", "--stand-off", "2")
    assert out.returncode == 0, out.stderr
    assert "paths checked against the part's other faces" in out.stdout
    assert "Safe Z:    %.4f mm (part top %.4f" % (roof_bottom + 11, roof_bottom + 5) in out.stdout
    ms = read_measurements(tmp_path / "plan.csv", plan=True)
    assert_allclose(ms.nominal[:, 2], 10.0, atol=1e-9)
    assert ms.nominal[:, 0].min() >= 1.5 - 1e-6
    rows = np.genfromtxt(tmp_path / "dropped.csv", delimiter=",", dtype=None, names=True,
                         encoding="utf-8")
    under = (rows["x"] > 20.0) & (rows["x"] < 38.5)
    assert under.sum() >= 9 * 18
    assert all(text in r for r in rows["reason"][under])
    line = next(t for t in out.stdout.splitlines() if t.startswith("Dropped:") and text in t)
    assert int(line.split()[1]) == (rows["reason"] == rows["reason"][under][0]).sum()
    near = (rows["x"] > 14.0) & (rows["x"] < 19.0)
    assert near.sum() >= 9 * 5 and all(r == _DESCENT for r in rows["reason"][near])
    # the kept floor points up to x = 14 are all there: 41 columns 0.92 mm apart from 1.53
    xs = np.unique(np.round(ms.nominal[:, 0], 6))
    assert len(ms.nominal) == 9 * len(xs) and xs.size == 14
    assert 14.0 - 0.93 < xs.max() <= 14.0 + 1e-3


# ------------------------------------------------------------------ simulate with a plan
def run_simulate(*args):
    return subprocess.run([sys.executable, "-m", "surfcomp", "simulate", *map(str, args),
                           "--quiet"], cwd=ROOT, capture_output=True, text=True, timeout=600)


def test_simulate_at_a_written_plan(tmp_path):
    import json

    plan = tmp_path / "plan.csv"
    assert plan_in_process(EXAMPLE_STEP, "-o", plan, "--layout", "adaptive",
                           "--points", "120").returncode == 0
    out = run_in_process("simulate", EXAMPLE_STEP, "--plan", plan, "--grid", "15x15",
                         "--replicas", "1", "--methods", "none,filtered", "--json",
                         tmp_path / "s.json", "--quiet")
    assert out.returncode == 0, out.stderr
    assert "Measured:  120 points of %s" % plan in out.stdout
    d = json.loads((tmp_path / "s.json").read_text())
    assert d["inputs"]["plan"]["points"] == 120
    assert (d["inputs"]["plan"]["sha256"]
            == hashlib.sha256(plan.read_bytes()).hexdigest())
    methods = {m["label"]: m for m in d["methods"]}
    assert methods["filtered"]["replicas"][0]["grid"]["count"] == 120
    assert methods["filtered"]["replicas"][0]["all"]["count"] == 29 * 29
    # what the sets are, as counted (before: "grid = nodes only" for the plan's points)
    assert d["probed_points"] == 120
    assert d["where"] == ("all = the evaluation grid's points; grid = the 120 probed points "
                          "of the plan; between = the evaluation grid's points between its "
                          "nodes")
    # the example's default model: about 16.5 um before, well under a quarter after
    before = methods["none"]["replicas"][0]["all"]["std"]
    assert 0.014 < before < 0.019
    assert methods["filtered"]["replicas"][0]["all"]["std"] < 0.25 * before


def test_simulate_refuses_a_plan_of_another_face(tmp_path):
    plan = tmp_path / "plan.csv"
    assert plan_in_process(EXAMPLE_STEP, "-o", plan, "--count", "4x4").returncode == 0
    lines = plan.read_text().splitlines()
    k = next(i for i, t in enumerate(lines) if t.startswith("P3,"))
    f = lines[k].split(",")
    f[3] = "%.6f" % (float(f[3]) + 0.5)
    lines[k] = ",".join(f)
    plan.write_text("\n".join(lines) + "\n")
    out = run_simulate(EXAMPLE_STEP, "--plan", plan, "--grid", "9x9", "--replicas", "1",
                       "--json", tmp_path / "s.json")
    assert out.returncode == 2
    assert "%s:%d: point P3 lies 0.4" % (plan, k + 1) in out.stderr
    assert not (tmp_path / "s.json").exists()


@pytest.mark.parametrize("args,message", [
    (("--compare-layouts", "20", "--html", "x.html"), "--html shows the maps of grid"),
    (("--compare-layouts", "0"), "--compare-layouts 0: expected a whole number"),
    (("--layout", "adaptive", "--count", "3x3"), "--layout adaptive takes --points N"),
    (("--layout", "grid", "--points", "9"), "--layout grid takes --count UxV"),
    (("--points", "9"), "--count and --points go with --layout"),
])
def test_simulate_plan_options_refused(tmp_path, args, message):
    out = run_simulate("--preset", "mirror2019-s1", *args)
    assert out.returncode == 2 and message in out.stderr, out.stderr


def test_plate_with_a_hole_keeps_the_margin(tmp_path):
    """A 40 x 30 x 5 mm plate with a 10 mm hole through it: the top face is trimmed by the
    hole; every kept point lies at least tip radius + edge margin (1.5 mm) from the hole's
    edge and the plate's border, measured with OpenCASCADE against the face's edges, and
    none lies in the hole."""
    import FreeCAD
    import Part

    V = FreeCAD.Vector
    plate = Part.makeBox(40, 30, 5).cut(Part.makeCylinder(5, 5, V(20, 15, 0)))
    step = tmp_path / "plate.step"
    plate.exportStep(str(step))
    back = Part.read(str(step))
    k = next(i for i, f in enumerate(back.Faces)
             if abs(f.BoundBox.ZMin - 5) < 1e-9 and abs(f.BoundBox.ZMax - 5) < 1e-9)
    out = plan_in_process(step, "--face", "Face%d" % (k + 1), "-o", tmp_path / "plan.csv",
                          "--count", "30x22", "--tip-radius", "1", "--edge-margin", "0.5")
    assert out.returncode == 0, out.stderr
    ms = read_measurements(tmp_path / "plan.csv", plan=True)
    top = back.Faces[k]
    edges = Part.Compound(top.Edges)
    dist = np.array([edges.distToShape(Part.Vertex(V(*p)))[0] for p in ms.nominal])
    assert dist.min() >= 1.5 - 1e-3
    assert np.all(np.hypot(ms.nominal[:, 0] - 20, ms.nominal[:, 1] - 15) >= 6.5 - 1e-3)
    # the nodes in and around the hole were dropped, and said so
    assert "not on the trimmed face" in out.stdout
    assert "closer than the margin to the boundary or a hole" in out.stdout
    assert 500 < len(ms.nominal) < 660
