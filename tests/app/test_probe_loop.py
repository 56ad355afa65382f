# SPDX-License-Identifier: LGPL-2.1-or-later
"""The on-machine probing loop on the example face: plan -> program -> LinuxCNC's rs274 ->
probe log of a known deformed face -> ``compensate --plan --tip-radius``.

The part is the example face extruded 20 mm down, written as STEP; ``plan --program``
places an 8 x 9 grid on its B-spline face and writes the plan and the probing program in
one run; the program is read by rs274; the traverses are checked against the solid with
OpenCASCADE; the log is computed by moving the tip sphere along
every STRAIGHT_PROBE segment rs274 printed until it first touches the deformed face.
"""

import hashlib
import json
import re
import subprocess
import sys

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import brentq

from surfcomp.io.plan_join import read_plan
from surfcomp.io.probe_program import ProbeSettings, write_probe_program
from tests.app.helpers import EXAMPLE_STEP, ROOT, realised_by_occt, run_in_process
from tests.probe_checks import check_probe_moves, rs274_moves

R = 1.0
CLEARANCE = 3.0
OVERTRAVEL = 1.0


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "surfcomp", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def loop(tmp_path_factory):
    """Plan, program and rs274's moves on the example face."""
    tmp = tmp_path_factory.mktemp("probe_loop")
    import FreeCAD
    import Part

    solid = Part.read(EXAMPLE_STEP).Faces[0].extrude(FreeCAD.Vector(0, 0, -20))
    assert solid.isValid() and solid.ShapeType == "Solid"
    part = tmp / "part.step"
    solid.exportStep(str(part))
    faces = Part.read(str(part)).Faces
    face = next("Face%d" % (k + 1) for k, f in enumerate(faces)
                if f.Surface.TypeId == "Part::GeomBSplineSurface")
    plan, prog = tmp / "plan.csv", tmp / "probe.ngc"
    out = run_in_process("plan", part, "--face", face, "-o", plan, "--count", "8x9",
                         "--tip-radius", R, "--clearance", CLEARANCE, "--stand-off", 2,
                         "--program", prog, "--quiet")
    assert out.returncode == 0, out.stderr
    assert "paths checked against the part's other faces" in out.stdout
    p = read_plan(str(plan))
    assert len(p) == 72
    sha = hashlib.sha256(plan.read_bytes()).hexdigest()
    head = prog.read_text().split("G38.2")[0]
    # the hash in two comments (a LinuxCNC comment holds at most 32 characters of it)
    halves = re.findall(r"\(plan sha256(?: cont)? ([0-9a-f]+)\)", head)
    assert "".join(halves) == sha and "linuxcnc" in head and "tip radius 1" in head, head
    travel = float(re.search(r"Travel: +([0-9.]+) mm", out.stdout).group(1))
    moves = rs274_moves(prog, tmp, diameter=2 * R)
    return dict(tmp=tmp, P=p.points, N=p.normals, ids=p.ids, plan=plan, solid=solid,
                moves=moves, travel=travel, prog=prog)


def test_program_probes_the_plan_and_keeps_clear_of_the_solid(loop):
    probes, worst = check_probe_moves(loop["moves"], loop["P"], loop["N"], R, OVERTRAVEL)
    assert len(probes) == 72
    import FreeCAD
    import Part

    # the first traverse starts at rs274's origin, not at a position of the program
    trav = [(a, b) for kind, a, b in loop["moves"] if kind == "STRAIGHT_TRAVERSE"][1:]
    dist = np.array([loop["solid"].distToShape(Part.LineSegment(
        FreeCAD.Vector(*a), FreeCAD.Vector(*b)).toShape())[0] for a, b in trav])
    # tip centres: the ball's surface stays CLEARANCE from the part (rs274's 4 decimals)
    assert dist.min() >= R + CLEARANCE - 1e-4, dist.min()
    print("72 probe moves, largest angle to -normal %.5f deg; %d traverses, nearest %.4f mm "
          "from the solid (ball surface %.4f mm); travel %.1f mm"
          % (worst, len(trav), dist.min(), dist.min() - R, loop["travel"]))


def deformed_face(amplitude=0.02):
    """The example face with its poles moved up by a smooth field (about +-20 um)."""
    import FreeCAD
    import Part

    surf = Part.read(EXAMPLE_STEP).Faces[0].Surface.copy()
    for i in range(1, surf.NbUPoles + 1):
        for j in range(1, surf.NbVPoles + 1):
            p = surf.getPole(i, j)
            dz = amplitude * np.sin(p.x / 45 * np.pi) * np.cos(p.y / 45 * 1.5 * np.pi) + 0.005
            surf.setPole(i, j, FreeCAD.Vector(p.x, p.y, p.z + dz))
    return surf


def sphere_touch(surf, a, b):
    """The centre where a ball of radius R moving from a to b first touches ``surf``."""
    import FreeCAD

    u = (b - a) / np.linalg.norm(b - a)

    def gap(s):
        c = FreeCAD.Vector(*(a + s * u))
        return (c - surf.value(*surf.parameter(c))).Length - R

    # the gap is a distance minus R, so it shrinks by at most the step: a step of the gap
    # itself cannot pass the first touch (sphere tracing); closer than 0.05 mm, steps of
    # 0.05 mm bracket it
    length = np.linalg.norm(b - a)
    s, g = 0.0, gap(0.0)
    assert g > 0.0, "the ball starts in the face"
    while g > 0.0:
        assert s < length, "the ball does not touch the face between a and b"
        s, t = min(s + max(g, 0.05), length), s
        g = gap(s)
    return a + brentq(gap, t, s, xtol=1e-12) * u


def write_log(path, centres):
    """A LinuxCNC probe log of tip centres (its layout: 9 axes, 6 decimals)."""
    path.write_text("".join("%.6f %.6f %.6f 0.000000 0.000000 0.000000 0.000000 0.000000 "
                            "0.000000\n" % tuple(c) for c in centres))


@pytest.fixture(scope="module")
def probed(loop):
    """The deformed face, the probe log of the program on it and the deformation along
    the planned normals, found independently (ray and face)."""
    import Part

    surf = deformed_face()
    probes = [(a, b) for kind, a, b in loop["moves"] if kind == "STRAIGHT_PROBE"]
    log = loop["tmp"] / "probe.log"
    write_log(log, [sphere_touch(surf, a, b) for a, b in probes])
    truth = -realised_by_occt(Part.Face(surf), loop["P"], loop["N"], reach=0.5)
    return dict(surf=surf, log=log, truth=truth)


def test_round_trip_recovers_the_correction(loop, probed):
    tmp, log, truth = loop["tmp"], probed["log"], probed["truth"]
    cmm = tmp / "truth.csv"
    cmm.write_text("id,x_nom,y_nom,z_nom,i,j,k,dev\n" + "".join(
        "%s,%.9f,%.9f,%.9f,%.12f,%.12f,%.12f,%.9f\n" % ((i,) + tuple(p) + tuple(n) + (d,))
        for i, p, n, d in zip(loop["ids"], loop["P"], loop["N"], truth)))
    out = run_in_process("compensate", EXAMPLE_STEP, log, "--plan", loop["plan"],
                         "--tip-radius", R, "--report", tmp / "probe.json", "--html",
                         tmp / "probe.html", "--quiet")
    assert out.returncode == 0, out.stderr
    assert "<b>%s</b>" % loop["plan"] in (tmp / "probe.html").read_text()
    assert "Plan:         %s" % loop["plan"] in out.stdout and "8 x 9" in out.stdout.replace(
        "9 x 8", "8 x 9")
    ref = run_in_process("compensate", EXAMPLE_STEP, cmm, "--report", tmp / "truth.json",
                         "--quiet")
    assert ref.returncode == 0, ref.stderr
    got, want = (json.loads((tmp / n).read_text()) for n in ("probe.json", "truth.json"))
    assert got["inputs"]["plan"]["sha256"] == hashlib.sha256(
        loop["plan"].read_bytes()).hexdigest()
    dev = np.array(got["points"]["deviation"])
    assert_allclose(dev, truth, atol=1e-4, rtol=0)
    assert np.abs(truth).max() > 0.015          # a real deformation, not a zero
    corr, corr_ref = (np.array(r["points"]["correction"]) for r in (got, want))
    assert_allclose(corr, corr_ref, atol=1e-4, rtol=0)
    print("round trip: deviation recovered within %.4f um, correction within %.4f um "
          "(largest deviation %.1f um)" % (np.abs(dev - truth).max() * 1e3,
                                           np.abs(corr - corr_ref).max() * 1e3,
                                           np.abs(truth).max() * 1e3))


def test_a_log_that_does_not_fit_exits_2_and_writes_nothing(loop):
    tmp = loop["tmp"]
    centres = loop["P"] + (R + 0.01) * loop["N"]
    log = tmp / "short.log"
    log.write_text("".join("%.6f %.6f %.6f 0 0 0 0 0 0\n" % tuple(c) for c in centres[:-1]))
    report = tmp / "never.json"
    out = run_cli("inspect", EXAMPLE_STEP, log, "--plan", loop["plan"], "--tip-radius", R,
                  "--report", report, "--quiet")
    assert out.returncode == 2 and not report.exists()
    rows = read_plan(str(loop["plan"])).lines     # the plan's own line of each point
    assert "%s:%d: planned point %s has no probe line" % (loop["plan"], rows[-1],
                                                           loop["ids"][-1]) in out.stderr
    swapped = centres[[1, 0] + list(range(2, 72))]
    log.write_text("".join("%.6f %.6f %.6f 0 0 0 0 0 0\n" % tuple(c) for c in swapped))
    out = run_cli("compensate", EXAMPLE_STEP, log, "--plan", loop["plan"], "--tip-radius", R,
                  "--report", report, "--quiet")
    assert out.returncode == 2 and not report.exists()
    assert "%s:1: probe line 1 (" % log in out.stderr and "--max-offset 1 mm" in out.stderr
    bad_plan = tmp / "bad_plan.csv"
    lines = loop["plan"].read_text().splitlines()
    lines[rows[4] - 1] = lines[rows[4] - 1].replace(",", ",x", 1)
    bad_plan.write_text("\n".join(lines) + "\n")
    out = run_cli("inspect", EXAMPLE_STEP, log, "--plan", bad_plan, "--report", report,
                  "--quiet")
    assert out.returncode == 2 and not report.exists()
    assert "%s:%d:2: column 'x_nom' holds 'x" % (bad_plan, rows[4]) in out.stderr, out.stderr
    out = run_cli("inspect", EXAMPLE_STEP, log, "--touches", "2", "--quiet")
    assert out.returncode == 2 and ("--touches applies to a probe log read with a "
                                    "measurement plan (--plan)") in out.stderr, out.stderr


def test_job_file_with_a_plan(loop, probed):
    """The freecadcmd job route takes the plan as the key ``plan`` (relative to the job
    file) and gives the command line's deviations."""
    from surfcomp.cli.jobfile import run_job_file

    tmp = loop["tmp"]
    job = tmp / "job.json"
    job.write_text(json.dumps({"command": "inspect", "nominal": EXAMPLE_STEP,
                               "measurements": probed["log"].name, "plan": "plan.csv",
                               "tip_radius": R, "report": "job_report.json"}))
    assert run_job_file(str(job)) == 0
    rep = json.loads((tmp / "job_report.json").read_text())
    assert rep["inputs"]["plan"]["path"] == str(loop["plan"])
    assert_allclose(rep["points"]["deviation"], probed["truth"], atol=1e-4, rtol=0)


def test_second_touch_round_trip(loop, probed):
    """A second-touch program: rs274 reads it, and the log of two lines per point (the
    first touch, then the touch from 1 mm back off the first trip point) is read back with
    --touches 2."""
    tmp = loop["tmp"]
    s = ProbeSettings(tip_radius=R, safe_z=loop["solid"].BoundBox.ZMax, clearance=CLEARANCE,
                      stand_off=2.0, overtravel=OVERTRAVEL, second_touch=True, backoff=1.0)
    prog = tmp / "probe2.ngc"
    summary = write_probe_program(str(prog), loop["ids"], loop["P"], loop["N"], s)
    probes, worst = check_probe_moves(rs274_moves(prog, tmp, diameter=2 * R), loop["P"],
                                      loop["N"], R, OVERTRAVEL)
    assert len(probes) == summary["log_lines"] == 144
    centres = []
    for k in range(72):
        a, b = probes[2 * k]
        first = sphere_touch(probed["surf"], a, b)
        # on the machine the second touch starts 1 mm back from the first trip point
        # (rs274 has no probe: it backs off from the end point instead)
        centres += [first, sphere_touch(probed["surf"], first + 1.0 * loop["N"][k], b)]
    log = tmp / "probe2.log"
    write_log(log, centres)
    out = run_in_process("inspect", EXAMPLE_STEP, log, "--plan", loop["plan"], "--tip-radius",
                         R, "--touches", 2, "--report", tmp / "probe2.json", "--quiet")
    assert out.returncode == 0, out.stderr
    dev = np.array(json.loads((tmp / "probe2.json").read_text())["points"]["deviation"])
    assert_allclose(dev, probed["truth"], atol=1e-4, rtol=0)
    out = run_cli("inspect", EXAMPLE_STEP, log, "--plan", loop["plan"], "--tip-radius", R,
                  "--quiet")
    assert out.returncode == 2 and "%s:73: probe line 73 has no planned point" % log \
        in out.stderr


def test_plan_and_program_are_written_together_or_not_at_all(tmp_path):
    """A program setting no program can be made with (a second-touch back-off beyond the
    stand-off) fails the whole plan run: exit 2, neither the plan nor the program."""
    plan, prog = tmp_path / "plan.csv", tmp_path / "probe.ngc"
    out = run_cli("plan", EXAMPLE_STEP, "-o", plan, "--count", "4x4", "--program", prog,
                  "--second-touch", "--backoff", 3, "--stand-off", 2, "--quiet")
    assert out.returncode == 2, out.stderr
    assert "--backoff 3 mm is larger than --stand-off 2 mm" in out.stderr, out.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    out = run_cli("plan", EXAMPLE_STEP, "-o", plan, "--count", "4x4", "--program", plan,
                  "--quiet")
    assert out.returncode == 2 and not plan.exists(), out.stderr


@pytest.mark.parametrize("count, clearance, stand_off, kept, descent", [
    ("25x25", 5.0, 2.0, 555, 45),
    ("10x10", 2.0, 1.0, 90, 2),
])
def test_rapid_moves_keep_the_clearance_beside_a_wall(tmp_path, count, clearance, stand_off,
                                                      kept, descent):
    """The example part with a 50 mm high wall along its x = 45 side: a rapid plunge from
    the safe height (above the wall's top) to a floor point near the wall passed 1.80 mm
    (0.018 mm with --clearance 2) from the wall. The points whose rapid moves would come
    closer than --clearance to the solid are dropped and counted; every rapid move rs274
    reads keeps the ball --clearance from the solid (less the 1 um check tolerance and
    rs274's 4 printed decimals), and the closest one is at the clearance, not far above."""
    import FreeCAD
    import Part

    V = FreeCAD.Vector
    solid = Part.read(EXAMPLE_STEP).Faces[0].extrude(V(0, 0, -20)).fuse(
        Part.makeBox(5, 45, 50, V(45, 0, -20))).removeSplitter()
    part = tmp_path / "wall.step"
    solid.exportStep(str(part))
    solid = Part.read(str(part))
    face = next("Face%d" % (k + 1) for k, f in enumerate(solid.Faces)
                if f.Surface.TypeId == "Part::GeomBSplineSurface")
    plan, prog = tmp_path / "plan.csv", tmp_path / "probe.ngc"
    out = run_in_process("plan", part, "--face", face, "-o", plan, "--count", count,
                         "--clearance", clearance, "--stand-off", stand_off, "--program",
                         prog, "--quiet")
    assert out.returncode == 0, out.stderr
    moves = rs274_moves(prog, tmp_path, diameter=2 * R)
    trav = [(a, b) for kind, a, b in moves if kind == "STRAIGHT_TRAVERSE"][1:]
    gap = np.array([solid.distToShape(Part.LineSegment(V(*a), V(*b)).toShape())[0]
                    for a, b in trav if np.linalg.norm(b - a) > 1e-9]) - R
    assert gap.min() >= clearance - 1e-3 - 1e-4, gap.min()
    assert gap.min() <= clearance + 0.05, gap.min()
    assert ("Dropped:   %d the rapid descent from the safe height comes closer than "
            "--clearance to another face of the part" % descent) in out.stdout, out.stdout
    assert len(read_plan(str(plan))) == kept
