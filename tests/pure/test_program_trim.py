# SPDX-License-Identifier: LGPL-2.1-or-later
"""The direct route honours the face's trim (issue 27): on the example surface trimmed to
an outer boundary inside it and a square hole, a constant correction moves the contact
points inside the trimmed face as on the untrimmed surface, fades out over the blend
beyond the outer boundary and across the hole's edge without a step, and moves nothing
where the ball is farther than the blend from the face."""

import numpy as np
import pytest

from surfcomp.core.compensation.program_offset import BallOffset
from surfcomp.core.compensation.program_trim import Trim
from surfcomp.core.simulation.presets import werner_surface
from tests.toolpath_checks import drop_cutter

R = 3.0
SURF = werner_surface()          # 45 x 45 mm, u ~ x / 45, v ~ y / 45
T = 0.02
BLEND = 1.0


def loop(a, b, n=41):
    """A square loop [a, b]^2 in (u, v), counter-clockwise."""
    t = np.linspace(a, b, n)
    return [np.column_stack([t, np.full(n, a)]), np.column_stack([np.full(n, b), t]),
            np.column_stack([t[::-1], np.full(n, b)]), np.column_stack([np.full(n, a), t[::-1]])]


PIECES = loop(0.1, 0.9) + [p[::-1] for p in loop(0.4, 0.6)][::-1]


def constant(u, v):
    return np.full(np.shape(u), T)


@pytest.fixture(scope="module")
def row():
    """Tips of a drop-cutter row at 0.05 mm through the middle of the hole."""
    xs = np.arange(-2.0, 47.0, 0.05)
    xy = np.column_stack([xs, np.full(xs.size, 22.5)])
    z, _ = drop_cutter(SURF, 1, xy, np.full(xs.size, 5.0), R)
    return np.column_stack([xy, z])


def test_whole_domain_is_no_trim():
    assert Trim.of(SURF, loop(0.0, 1.0)) is None
    assert Trim.of(SURF, PIECES) is not None


def test_trim_fades_the_correction_out_without_a_step(row):
    trim = Trim(SURF, PIECES)
    plain = BallOffset(SURF, 1, R, constant, BLEND).displace(row)
    cut = BallOffset(SURF, 1, R, constant, BLEND, trim=trim).displace(row)
    pr = BallOffset(SURF, 1, R, constant, BLEND).projector.project(row + [0, 0, R])
    out = trim.outside(pr.u, pr.v)
    # inside the trimmed face: as on the whole surface (the contact there, moved by T)
    assert (~out).sum() > 300
    np.testing.assert_array_equal(cut.move[~out], plain.move[~out])
    np.testing.assert_allclose(np.linalg.norm(cut.move[~out], axis=1), T, rtol=0, atol=1e-12)
    # outside: the clearance is measured from the boundary; nothing where it exceeds the blend
    far = out & (cut.gap >= BLEND)
    near = out & (cut.gap > 0) & (cut.gap < BLEND)
    assert far.sum() > 50 and near.sum() > 20
    assert np.abs(cut.move[far]).max() == 0.0
    assert np.abs(plain.move[far]).max() > 0.9 * T        # the untrimmed route moved them
    size = np.linalg.norm(cut.move, axis=1)
    assert 0 < size[near].min() < size[near].max() < T
    assert not cut.interior[out].any()
    # no step: neighbouring points 0.05 mm apart move by nearly the same (the blend's
    # steepest slope 1.5 / BLEND per mm of clearance)
    jump = np.linalg.norm(np.diff(cut.move, axis=0), axis=1)
    assert jump.max() < 1.5 * T / BLEND * 0.05 * 1.2
    # the row crosses the outer boundary once on each side and the hole's edge twice
    assert np.count_nonzero(np.diff(out.astype(int))) == 4


def test_closest_boundary_point_is_on_the_boundary():
    trim = Trim(SURF, PIECES)
    X = np.array([[22.5, 22.5, 4.0], [1.0, 22.5, 3.5]])
    x, u, v, d = trim.closest(X)
    # the hole's edge at u = 0.4 or 0.6 (or v), the outer boundary at u = 0.1
    assert min(abs(u[0] - 0.4), abs(u[0] - 0.6), abs(v[0] - 0.4), abs(v[0] - 0.6)) < 1e-9
    assert abs(u[1] - 0.1) < 1e-9
    np.testing.assert_allclose(d, np.linalg.norm(X - x, axis=1), rtol=0, atol=1e-12)
