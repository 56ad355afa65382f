# SPDX-License-Identifier: LGPL-2.1-or-later
"""Direct program compensation against the CAM route (issue 27), real OpenCamLib, no mocks.

Set-up (as tests/app/test_path_regen.py): a Job with a 3D Surface operation (6 mm ball end
mill, line pattern, 3 mm step-over, 1 mm samples, every sample kept, mesh deflection 1 um)
on the example's nominal face, posted with 4 decimals (FINISH.ngc); the compensation of the
example measurements (refine 1) replaces the nominal and the operation regenerates on the
corrected face (CAM.ngc). ``compensate --program FINISH.ngc --tool ball:3`` moves the
nominal program directly (DIRECT.ngc).

Both programs are read by LinuxCNC's rs274 and compared as surfaces
(:mod:`tests.program_compare`): each contact point of DIRECT.ngc against the tip surface of
CAM.ngc, along the normal. Stated tolerance: the operation's own (its mesh deflection,
1 um) plus 1 um. Measured: max 1.24 um, median 0.18 um over 520 points (CAM vs the
nominal program: 44.9 um). A measurement file of zero deviations moves nothing: rs274's
moves of the output are those of the input.
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
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP, ROOT
from tests.program_compare import feed_points, surface_distance
from tests.pure.test_gcode_rs274 import rs274

R = 3.0
POST_ARGS = "--no-show-editor --no-header --precision=4"
#: the operation's mesh deflection (mm) plus 1 um
AGREE = 0.001 + 0.001


def run_cli(*args):
    env = dict(os.environ, PYTHONPATH=ROOT)
    return subprocess.run([sys.executable, "-m", "surfcomp", *args], capture_output=True,
                          text=True, env=env, cwd=ROOT, timeout=600)


@pytest.fixture(scope="module")
def programs(tmp_path_factory):
    """FINISH.ngc (nominal) and CAM.ngc (regenerated on the corrected face), the corrected
    surface; one Path computation each."""
    tmp = tmp_path_factory.mktemp("direct")
    cam.setup_workbench()
    doc = FreeCAD.newDocument("directprog")
    nom = doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(EXAMPLE_STEP)
    doc.recompute()
    job = cam_job.create_job(doc, [nom])
    tc = cam_job.ball_end_tool_controller(job, 2 * R)
    cam_job.surface_operation(job, nom, ["Face1"], tc, step_over=50.0, sample_interval=1.0,
                              linear_deflection=0.001)
    m = features.make_measurement(doc, EXAMPLE_CSV)
    comp = features.make_compensation(doc, nom, "Face1", m)
    comp.Refine = 1
    doc.recompute()
    cam_job.model_clone(job, nom).touch()
    doc.recompute()
    finish = tmp / "FINISH.ngc"
    finish.write_text(cam_job.post_process(job, "linuxcnc", POST_ARGS))
    replace.replace(doc, comp)
    doc.recompute()
    regen = tmp / "CAM.ngc"
    regen.write_text(cam_job.post_process(job, "linuxcnc", POST_ARGS))
    corrected = reports.corrected_surface(comp)
    FreeCAD.closeDocument(doc.Name)
    return tmp, finish, regen, corrected


def test_direct_program_agrees_with_the_cam_route(programs):
    tmp, finish, regen, corrected = programs
    out = tmp / "DIRECT.ngc"
    run = run_cli("compensate", EXAMPLE_STEP, EXAMPLE_CSV, "--refine", "1", "--program",
                  str(finish), "--tool", "ball:%g" % R, "-o", str(out), "--quiet")
    assert run.returncode == 0, run.stderr
    assert "wrote %s" % out in run.stdout
    nominal = load_nominal(EXAMPLE_STEP)
    direct = feed_points(rs274(out, tmp)[0])
    cam_pts = feed_points(rs274(regen, tmp)[0])
    before = feed_points(rs274(finish, tmp)[0])
    d, shift = surface_distance(nominal.surface, nominal.outward, R, direct, cam_pts,
                                carry=corrected)
    assert d.size > 450
    assert np.abs(d).max() <= AGREE
    assert np.median(np.abs(d)) <= 0.5e-3
    # the correction itself is tens of um: the comparison can fail
    d0, _ = surface_distance(nominal.surface, nominal.outward, R, before, cam_pts,
                             carry=corrected)
    assert np.abs(d0).max() > 0.03
    # what the run says it did
    moved = int(re.search(r"Moved: +(\d+) moves", run.stdout).group(1))
    assert moved > 450
    assert finish.read_text() != out.read_text()


def test_zero_correction_gives_the_same_moves(programs, tmp_path):
    tmp, finish, _regen, _corrected = programs
    zero = tmp_path / "zero.csv"
    rows = [ln for ln in open(EXAMPLE_CSV).read().splitlines() if not ln.startswith("#")]
    head, body = rows[0], rows[1:]
    zero.write_text("\n".join([head] + [",".join(r.split(",")[:-1] + ["0.0"])
                                        for r in body]) + "\n")
    out = tmp_path / "same.ngc"
    run = run_cli("compensate", EXAMPLE_STEP, str(zero), "--program", str(finish), "--tool",
                  "ball:3", "-o", str(out), "--quiet")
    assert run.returncode == 0, run.stderr
    assert out.read_bytes() == finish.read_bytes()
    assert rs274(out, tmp_path)[1] == rs274(finish, tmp_path)[1]


@pytest.mark.parametrize("args, message", [
    (("--tool", "flat:3"), "only ball-end cutters"),
    (("--tool", "ball:5"), "cuts .* into the nominal face"),
    (("--tool", "ball:3", "--blend", "0"), "--blend 0.0"),
])
def test_bad_input_exits_2_and_writes_nothing(programs, tmp_path, args, message):
    _tmp, finish, _regen, _corrected = programs
    out = tmp_path / "out.ngc"
    run = run_cli("compensate", EXAMPLE_STEP, EXAMPLE_CSV, "--program", str(finish), *args,
                  "-o", str(out), "--quiet")
    assert run.returncode == 2 and re.search(message, run.stderr), run.stderr
    assert not out.exists()
    assert os.listdir(tmp_path) == []


def test_the_program_is_never_overwritten(programs):
    _tmp, finish, _regen, _corrected = programs
    text = finish.read_bytes()
    run = run_cli("compensate", EXAMPLE_STEP, EXAMPLE_CSV, "--program", str(finish), "--tool",
                  "ball:3", "-o", str(finish))
    assert run.returncode == 2 and "--program" in run.stderr, run.stderr
    assert finish.read_bytes() == text
