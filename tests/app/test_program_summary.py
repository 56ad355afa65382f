# SPDX-License-Identifier: LGPL-2.1-or-later
"""The direct program route's summary claims what was done: with a zero correction it
said '26232 points displaced' of the example's program while moving none."""

import numpy as np
import pytest

from surfcomp.app.nominal import load_nominal
from tests.app.helpers import EXAMPLE_STEP, grid_on_face, write_cmm_csv
from tests.app.test_program_warnings import R, _program, _run


@pytest.fixture(scope="module")
def pass_and_zero(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("summary")
    nom = load_nominal(EXAMPLE_STEP)
    P, N, _, _ = grid_on_face(nom, 6, 5)
    meas = tmp / "zero.csv"
    write_cmm_csv(meas, P, N, np.zeros((6, 5)))
    program = tmp / "finish.ngc"
    _program(nom, program)
    return program, meas


def test_a_zero_correction_moves_and_displaces_nothing(pass_and_zero, tmp_path):
    program, meas = pass_and_zero
    out = tmp_path / "moved.ngc"
    run = _run("compensate", EXAMPLE_STEP, str(meas), "--program", str(program), "--tool",
               "ball:%g" % R, "-o", str(out), "--quiet")
    assert run.returncode == 0, run.stderr
    assert out.read_bytes() == program.read_bytes()
    moved = [ln for ln in run.stdout.splitlines() if ln.startswith("Moved:")]
    assert moved and moved[0].startswith("Moved:        0 moves (0 lines changed, 0 added")
    assert "largest move 0.00 um" in moved[0]
    assert "displaced" not in run.stdout and "the displacement computed at " in moved[0]
