# SPDX-License-Identifier: LGPL-2.1-or-later
"""Direct program compensation against the CAM route (issue 27), real OpenCamLib, no mocks.

Set-up (as tests/app/test_path_regen.py): a Job with a 3D Surface operation (6 mm ball end
mill, line pattern, 3 mm step-over, 1 mm samples, every sample kept) on a nominal face,
posted with 4 decimals (FINISH.ngc); the compensation of a measurement file (refine 1)
replaces the nominal and the operation regenerates on the corrected face (CAM.ngc).
``compensate --program FINISH.ngc --tool ball:3`` moves the nominal program directly
(DIRECT.ngc). Both programs are read by LinuxCNC's rs274 and compared as surfaces
(:mod:`tests.program_compare`): each contact point of DIRECT.ngc against the tip surface of
CAM.ngc, along the normal. Stated tolerance: the operation's own (its mesh deflection) plus
1 um.

* The example face and its measurements, mesh deflection 1 um: measured max 0.71 um,
  median 0.12 um over 520 points (CAM.ngc vs the nominal program: 44.9 um).
* The BladeX suction side turned so that its mean normal is +Z, a synthetic smooth error
  of 10..30 um on a 60 x 13 grid, mesh deflection 4 um: max 3.07 um, median 0.32 um over
  2285 points (CAM.ngc vs the nominal program: up to 30 um).

A measurement file of zero deviations moves nothing: the output is the input, byte for
byte, and rs274's moves are the same.
"""

import os
import re
import subprocess
import sys

import FreeCAD
import numpy as np
import Part
import pytest

from surfcomp.app import cam, cam_job, features, replace, reports
from surfcomp.app.nominal import load_nominal
from tests.app.cam_example import POST_ARGS, R, with_dressup
from tests.app.helpers import (
    EXAMPLE_CSV,
    EXAMPLE_STEP,
    ROOT,
    grid_on_face,
    run_in_process,
    write_cmm_csv,
)
from tests.program_compare import feed_points, surface_distance
from tests.pure.test_gcode_rs274 import rs274

#: the operation's mesh deflection (mm) plus 1 um
AGREE = 0.001 + 0.001


def run_cli(*args):
    env = dict(os.environ, PYTHONPATH=ROOT)
    return subprocess.run([sys.executable, "-m", "surfcomp", *args], capture_output=True,
                          text=True, env=env, cwd=ROOT, timeout=600)


@pytest.fixture(scope="module")
def programs(cam_example):
    """FINISH.ngc (nominal) and CAM.ngc (regenerated on the corrected face) of the example,
    the corrected surface, the dressup's results (tests/app/cam_example.py: one Path
    computation each, shared with test_path_regen.py)."""
    ex = cam_example
    return ex.tmp, ex.finish, ex.regen, ex.corrected, ex.found


BLADE = os.path.join(ROOT, "tests", "data", "real", "cad", "BladeX", "upper.iges")
#: the blade's operation meshes within 4 um (1 um would take 6 GB and minutes)
BLADE_DEFLECTION = 0.004


def turned_blade(path):
    """The BladeX suction side turned so that its mean normal is +Z (a 3-axis machine
    reaches it from above), written to ``path`` (STEP)."""
    face = Part.read(BLADE).Faces[0]
    ts = np.linspace(0.0, 1.0, 40)
    mean = np.mean([tuple(face.normalAt(u, v)) for u in ts for v in ts], axis=0)
    rot = FreeCAD.Rotation(FreeCAD.Vector(*mean), FreeCAD.Vector(0, 0, 1))
    face = face.transformGeometry(FreeCAD.Placement(FreeCAD.Vector(), rot).toMatrix())
    face.exportStep(str(path))
    return str(path)


def cam_programs(tmp, step, csv, deflection, refine=1, dressup=None):
    """FINISH.ngc of the 3D Surface operation on the face of ``step``, CAM.ngc regenerated
    on the compensation of ``csv`` (document route), and the corrected surface. With
    ``dressup`` (a dict), the Job is first posted with a surface correction dressup on the
    operation (DRESSUP.ngc; the dressup's results and whether the operation's path stayed
    as it was go into the dict), and the dressup is deleted again."""
    cam.setup_workbench()
    doc = FreeCAD.newDocument("directprog")
    nom = doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(step)
    doc.recompute()
    job = cam_job.create_job(doc, [nom])
    tc = cam_job.ball_end_tool_controller(job, 2 * R)
    cam_job.surface_operation(job, nom, ["Face1"], tc, step_over=50.0, sample_interval=1.0,
                              linear_deflection=deflection)
    m = features.make_measurement(doc, csv)
    comp = features.make_compensation(doc, nom, "Face1", m)
    comp.Refine = refine
    doc.recompute()
    # Path's stock follows the model clone's bounding box, tight once the operation has
    # meshed the clone: settle it, so that only the compensation changes the program
    # (tests/app/cam_example.py settles it before the operation exists)
    cam_job.model_clone(job, nom).touch()
    doc.recompute()
    finish = tmp / "FINISH.ngc"
    finish.write_text(cam_job.post_process(job, "linuxcnc", POST_ARGS))
    if dressup is not None:
        with_dressup(doc, job, comp, tmp, dressup)
    replace.replace(doc, comp)
    doc.recompute()
    regen = tmp / "CAM.ngc"
    regen.write_text(cam_job.post_process(job, "linuxcnc", POST_ARGS))
    corrected = reports.corrected_surface(comp)
    FreeCAD.closeDocument(doc.Name)
    return finish, regen, corrected


def agreement(tmp, step, csv, finish, regen, corrected):
    """Distances (mm) of the directly moved program from the regenerated one, and of the
    nominal program from it; the command's standard output."""
    out = tmp / "DIRECT.ngc"
    run = run_in_process("compensate", step, csv, "--refine", "1", "--program", str(finish),
                         "--tool", "ball:%g" % R, "-o", str(out), "--quiet")
    assert run.returncode == 0, run.stderr
    assert "wrote %s" % out in run.stdout
    nominal = load_nominal(step)
    direct = feed_points(rs274(out, tmp)[0])
    cam_pts = feed_points(rs274(regen, tmp)[0])
    before = feed_points(rs274(finish, tmp)[0])
    d, _shift = surface_distance(nominal.surface, nominal.outward, R, direct, cam_pts,
                                 carry=corrected)
    # the nominal program lies the whole correction off: a window of 0.1 mm takes it in
    d0, _ = surface_distance(nominal.surface, nominal.outward, R, before, cam_pts,
                             carry=corrected, window=0.1)
    return d, d0, run.stdout


@pytest.fixture(scope="module")
def blade(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("blade")
    step = turned_blade(tmp / "blade.step")
    nominal = load_nominal(step)
    P, N, U, V = grid_on_face(nominal, 60, 13)
    csv = str(tmp / "blade.csv")
    write_cmm_csv(csv, P, N, 0.02 * np.sin(3 * U) * np.cos(2 * V) + 0.01)
    return (tmp, step, csv) + cam_programs(tmp, step, csv, BLADE_DEFLECTION)


@pytest.mark.scale
def test_direct_program_agrees_with_the_cam_route_on_the_blade(blade):
    tmp, step, csv, finish, regen, corrected = blade
    d, d0, _out = agreement(tmp, step, csv, finish, regen, corrected)
    print("blade: %d points, max %.3f um, median %.3f um; nominal program %.1f um"
          % (d.size, np.abs(d).max() * 1e3, np.median(np.abs(d)) * 1e3,
             np.abs(d0).max() * 1e3))
    assert d.size > 2000
    assert np.abs(d).max() <= BLADE_DEFLECTION + 0.001
    assert np.abs(d0).max() > 0.02


def test_direct_program_agrees_with_the_cam_route(programs):
    tmp, finish, regen, corrected, _found = programs
    d, d0, out = agreement(tmp, EXAMPLE_STEP, EXAMPLE_CSV, finish, regen, corrected)
    print("example: %d points, max %.3f um, median %.3f um; nominal program %.1f um"
          % (d.size, np.abs(d).max() * 1e3, np.median(np.abs(d)) * 1e3,
             np.abs(d0).max() * 1e3))
    assert d.size > 450
    assert np.abs(d).max() <= AGREE
    assert np.median(np.abs(d)) <= 0.5e-3
    # the correction itself is tens of um: the comparison can fail
    assert np.abs(d0).max() > 0.03
    # what the run says it did
    moved = int(re.search(r"Moved: +(\d+) moves", out).group(1))
    assert moved > 450
    assert finish.read_text() != (tmp / "DIRECT.ngc").read_text()


def test_zero_correction_gives_the_same_moves(programs, tmp_path):
    tmp, finish, _regen, _corrected, _found = programs
    zero = tmp_path / "zero.csv"
    rows = [ln for ln in open(EXAMPLE_CSV).read().splitlines() if not ln.startswith("#")]
    head, body = rows[0], rows[1:]
    zero.write_text("\n".join([head] + [",".join(r.split(",")[:-1] + ["0.0"])
                                        for r in body]) + "\n")
    out = tmp_path / "same.ngc"
    run = run_in_process("compensate", EXAMPLE_STEP, str(zero), "--program", str(finish),
                         "--tool", "ball:3", "-o", str(out), "--quiet")
    assert run.returncode == 0, run.stderr
    assert out.read_bytes() == finish.read_bytes()
    assert rs274(out, tmp_path)[1] == rs274(finish, tmp_path)[1]


@pytest.mark.parametrize("args, message", [
    (("--tool", "flat:3"), "only ball-end cutters"),
    (("--tool", "ball:5"), "cuts .* into the nominal face"),
    (("--tool", "ball:3", "--blend", "0"), "--blend 0.0"),
])
def test_bad_input_exits_2_and_writes_nothing(programs, tmp_path, args, message):
    _tmp, finish, _regen, _corrected, _found = programs
    out = tmp_path / "out.ngc"
    run = run_cli("compensate", EXAMPLE_STEP, EXAMPLE_CSV, "--program", str(finish), *args,
                  "-o", str(out), "--quiet")
    assert run.returncode == 2 and re.search(message, run.stderr), run.stderr
    assert not out.exists()
    assert os.listdir(tmp_path) == []


def test_the_program_is_never_overwritten(programs):
    _tmp, finish, _regen, _corrected, _found = programs
    text = finish.read_bytes()
    run = run_cli("compensate", EXAMPLE_STEP, EXAMPLE_CSV, "--program", str(finish), "--tool",
                  "ball:3", "-o", str(finish))
    assert run.returncode == 2 and "--program" in run.stderr, run.stderr
    assert finish.read_bytes() == text


def test_the_dressup_posts_the_moved_program_without_cam(programs):
    """The Job posts the operation moved by the "Surface correction" dressup: the
    operation itself is not recomputed, and the posted program agrees with the one
    regenerated on the corrected face as the command line's does."""
    tmp, finish, regen, corrected, found = programs
    assert not {"Invalid", "Error"} & set(found["state"]) and found["radius"] == R
    assert found["op_kept"] and not found["touched"]
    assert found["ops"] == ["DressupSurfaceCorrection"]
    assert found["moved"] > 450 and found["contact"] > 450
    assert found["no_base"] == [0, 0, 0.0, 0]
    assert 0.03 < found["max_move"] < 0.05
    nominal = load_nominal(EXAMPLE_STEP)
    posted = feed_points(rs274(tmp / "DRESSUP.ngc", tmp)[0])
    cam_pts = feed_points(rs274(regen, tmp)[0])
    d, _ = surface_distance(nominal.surface, nominal.outward, R, posted, cam_pts,
                            carry=corrected)
    print("dressup: %d points, max %.3f um, median %.3f um"
          % (d.size, np.abs(d).max() * 1e3, np.median(np.abs(d)) * 1e3))
    assert d.size > 450
    assert np.abs(d).max() <= AGREE
