# SPDX-License-Identifier: LGPL-2.1-or-later
"""The direct program route reads the measurements as ``-o`` does, or refuses what it
cannot honour: before, ``--plan``/``--touches`` and the alignment's options were taken and
then ignored (the program moved as if they had not been given)."""

import os

import numpy as np
import pytest

from surfcomp.app.nominal import load_nominal
from tests.app.test_program_warnings import EXAMPLE_STEP, R, _program, _run, grid_on_face

TIP = 1.0


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """A finishing pass, a plan of 4 x 3 points, its probe log (one touch a point: tip
    centres 10 um outside the face) and the same points as a file of measured points."""
    tmp = tmp_path_factory.mktemp("inputs")
    nom = load_nominal(EXAMPLE_STEP)
    P, N, _, _ = grid_on_face(nom, 4, 3, margin=0.1)
    P, N = P.reshape(-1, 3), N.reshape(-1, 3)
    plan, log, xyz = tmp / "plan.csv", tmp / "probe.log", tmp / "measured.xyz"
    plan.write_text("id,x_nom,y_nom,z_nom,i,j,k\n" + "".join(
        "P%d,%.9f,%.9f,%.9f,%.12f,%.12f,%.12f\n" % ((k + 1,) + tuple(p) + tuple(n))
        for k, (p, n) in enumerate(zip(P, N))))
    log.write_text("".join("%.6f %.6f %.6f 0 0 0 0 0 0\n" % tuple(p + (0.01 + TIP) * n)
                           for p, n in zip(P, N)))
    xyz.write_text("".join("%.6f %.6f %.6f\n" % tuple(p + 0.01 * n) for p, n in zip(P, N)))
    program = tmp / "finish.ngc"
    _program(nom, program)
    return dict(plan=plan, log=log, xyz=xyz, program=program)


def test_a_probe_log_is_joined_to_its_plan(inputs, tmp_path):
    """Two touches a point against a log of one: ``-o`` refuses the log, and so does the
    program route (it read the log without the plan, every line a point)."""
    out = tmp_path / "moved.ngc"
    common = (EXAMPLE_STEP, str(inputs["log"]), "--plan", str(inputs["plan"]), "--tip-radius",
              str(TIP), "--touches", "2")
    run = _run("compensate", *common, "--program", str(inputs["program"]), "--tool",
               "ball:%g" % R, "-o", str(out), "--quiet")
    assert run.returncode == 2 and "planned point P7 has no probe line" in run.stderr, \
        run.stderr
    assert "expected 24 (2 per point)" in run.stderr
    assert os.listdir(tmp_path) == []
    # one touch a point: the plan's 12 points, moved by their 10 um
    run = _run("compensate", *common[:-2], "--program", str(inputs["program"]), "--tool",
               "ball:%g" % R, "-o", str(out), "--quiet")
    assert run.returncode == 0, run.stderr
    corr = run.stdout.splitlines()[0]
    low, high = (float(x) for x in corr.split(":", 1)[1].split("um")[0].split(" to "))
    np.testing.assert_allclose([low, high], [10.0, 10.0], atol=0.02)


@pytest.mark.parametrize("args", [
    ("--transform", "TRANSFORM"), ("--align", "bestfit"), ("--align-dof", "z"),
    ("--align-faces", "Face1"), ("--rps", "P1,P2,P3,P4,P5,P6")])
def test_alignment_options_are_refused(inputs, tmp_path, args):
    """The program route applies no alignment: a transform that moves the measured points
    20 um up gave the same program as none (``-o`` writes another face)."""
    shift = tmp_path / "shift.txt"
    shift.write_text("1 0 0 0\n0 1 0 0\n0 0 1 0.02\n0 0 0 1\n")
    args = tuple(str(shift) if a == "TRANSFORM" else a for a in args)
    out = tmp_path / "moved.ngc"
    run = _run("compensate", EXAMPLE_STEP, str(inputs["xyz"]), "--program",
               str(inputs["program"]), "--tool", "ball:%g" % R, *args, "-o", str(out))
    flag = args[0] if args[0] != "--align" else "--align bestfit"
    assert run.returncode == 2, run.stderr
    assert "%s cannot be combined with --program" % flag in run.stderr, run.stderr
    assert sorted(os.listdir(tmp_path)) == ["shift.txt"]
