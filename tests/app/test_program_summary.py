# SPDX-License-Identifier: LGPL-2.1-or-later
"""The direct program route's summary claims what was done: with a zero correction it
said '26232 points displaced' of the example's program while moving none."""

import numpy as np
import pytest

from surfcomp.app.nominal import load_nominal
from tests.app.test_program_warnings import (
    EXAMPLE_STEP,
    R,
    _program,
    _run,
    grid_on_face,
    write_cmm_csv,
)


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


@pytest.mark.parametrize("given, warned", [(3.0, False), (2.9, True), (3.1, True)])
def test_the_contact_line_names_the_radius_the_points_fit(tmp_path, given, warned):
    """A 3 mm ball's raster given as ball:2.9 is within the refusal's 10 um on the example's
    slopes; the summary said 'the radius fits within 100 um', now it names the 3 mm the
    points fit and warns."""
    from types import SimpleNamespace

    from surfcomp.app.program_route import summary_lines
    from tests.pure.test_program_offset import raster, run, wave

    _out, po = run(raster(radius=3.0), wave, tmp_path, radius=given)
    stats = SimpleNamespace(min=0.0, max=0.0, rms=0.0)
    lines = summary_lines(SimpleNamespace(statistics={"correction": stats}), po,
                          SimpleNamespace(program="prog.ngc", tolerance=5e-4, blend=1.0))
    contact = [ln for ln in lines if ln.startswith("Contact:")][0]
    fitted = float(contact.split("fit a ball of radius ")[1].split(" mm")[0])
    assert abs(fitted - 3.0) < 0.01, contact
    assert "from the %g mm given" % given in contact and "fits within" not in contact
    warnings = [ln for ln in lines if ln.startswith("warning: ")]
    assert bool(warnings) == warned, lines
    if warned:
        assert warnings[0].startswith("warning: prog.ngc: the program's cutter-location "
                                      "points fit a ball of radius 3.0")
        assert "not the %g mm given" % given in warnings[0]


def test_the_programs_warnings_go_to_standard_error_with_its_name(pass_and_zero, tmp_path):
    """As the compensation's (and ``-o``'s): they were printed on standard output, without
    the file they are about."""
    program, meas = pass_and_zero
    bare = tmp_path / "bare.ngc"
    bare.write_text(program.read_text().replace("G21 G90 G17", "G90 G17"))
    out = tmp_path / "moved.ngc"
    run = _run("compensate", EXAMPLE_STEP, str(meas), "--program", str(bare), "--tool",
               "ball:%g" % R, "-o", str(out), "--quiet")
    assert run.returncode == 0, run.stderr
    assert not any(ln.startswith("warning") for ln in run.stdout.splitlines()), run.stdout
    assert "warning: %s: no G20/G21 before the first move (line 2): millimetres assumed" \
        % bare in run.stderr.splitlines(), run.stderr
