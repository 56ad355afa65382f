# SPDX-License-Identifier: LGPL-2.1-or-later
"""The direct program route says what the compensation warns about, as ``-o`` does (on
standard error, ``warning: ...``): before, the warnings of the measurements and of the
corrected face were computed and then dropped."""

import os
import subprocess
import sys

import numpy as np

from surfcomp.app.nominal import load_nominal
from surfcomp.core.surface import bspline
from tests.app.helpers import EXAMPLE_STEP, ROOT, grid_on_face, write_cmm_csv

R = 3.0


def _run(*args):
    env = dict(os.environ, PYTHONPATH=ROOT)
    return subprocess.run([sys.executable, "-m", "surfcomp", *args], capture_output=True,
                          text=True, env=env, cwd=ROOT, timeout=600)


def _program(nominal, path):
    """A ball-end pass across the face: each tip R below the centre, the centre R along the
    outward normal from the face (a cutter-location program of the nominal, ball radius R)."""
    u0, u1 = nominal.surface.u_range
    (v0, v1), n = nominal.surface.v_range, 60
    u = np.linspace(u0 + 0.2 * (u1 - u0), u0 + 0.8 * (u1 - u0), n)
    v = np.full(n, v0 + 0.5 * (v1 - v0))
    P = bspline.evaluate(nominal.surface, u, v)
    N = bspline.normals(nominal.surface, u, v) * nominal.outward
    tips = P + R * N - np.array([0.0, 0.0, R])
    lines = ["G21 G90 G17", "G0 X%.4f Y%.4f Z%.4f" % tuple(tips[0] + [0, 0, 10]),
             "G1 Z%.4f F500" % tips[0][2]]
    lines += ["G1 X%.4f Y%.4f Z%.4f" % tuple(t) for t in tips[1:]]
    lines += ["G0 Z%.4f" % (tips[-1][2] + 10), "M30"]
    path.write_text("\n".join(lines) + "\n")


def test_the_compensations_warnings_are_shown(tmp_path):
    """A 6 x 5 grid with a point missing is used as a scattered layout, with the reason as
    a warning: the moved program is written, and the warning is on standard error."""
    nom = load_nominal(EXAMPLE_STEP)
    P, N, _, _ = grid_on_face(nom, 6, 5)
    meas = tmp_path / "holes.csv"
    write_cmm_csv(meas, P, N, np.full((6, 5), 0.01))
    lines = meas.read_text().splitlines()
    meas.write_text("\n".join(lines[:8] + lines[9:]) + "\n")
    program, out = tmp_path / "finish.ngc", tmp_path / "moved.ngc"
    _program(nom, program)
    run = _run("compensate", EXAMPLE_STEP, str(meas), "--program", str(program), "--tool",
               "ball:%g" % R, "-o", str(out), "--quiet")
    assert run.returncode == 0, run.stderr
    warned = [w for w in run.stderr.splitlines() if w.startswith("warning: ")]
    assert any("has 5 points (missing near u=" in w and "scattered layout" in w
               for w in warned), run.stderr
    assert "wrote %s" % out in run.stdout
    moved, original = out.read_text().splitlines(), program.read_text().splitlines()
    changed = sum(a != b for a, b in zip(moved, original))
    assert changed > 40 and 0 <= len(moved) - len(original) <= 5   # (measured: 2 added)
