# SPDX-License-Identifier: LGPL-2.1-or-later
"""Surface points by whichever evaluator the installed scipy allows (scipy's NdBSpline where
it exists, else the hand-written one) agree with the hand-written reference evaluation."""

import numpy as np
import pytest
import scipy.interpolate

from surfcomp.core.simulation.presets import werner_surface
from surfcomp.core.surface import bspline as bs
from surfcomp.core.surface import bspline_nd
from surfcomp.core.surface.bspline_basis import SCIPY_FROM
from tests.pure.surfaces import quarter_cylinder, random_surface


def reference(surf, u, v):
    """The hand-written evaluation (basis functions and the poles of each point)."""
    Pw = bs._homogeneous(surf) if surf.weights is not None else surf.poles
    return bs._ders_chunk(surf, Pw, u, v, 0)[(0, 0)]


def test_evaluator_chosen_by_what_scipy_has():
    has = hasattr(scipy.interpolate, "NdBSpline")
    assert (bspline_nd.ndbspline() is not None) == has
    s = werner_surface()
    assert (bspline_nd.point_evaluator(s, s.poles) is not None) == has
    assert (bspline_nd.point_evaluator(s, s.poles, SCIPY_FROM) is not None) == has
    # below the threshold the hand-written evaluation runs (no scipy.interpolate import)
    assert bspline_nd.point_evaluator(s, s.poles, SCIPY_FROM - 1) is None


@pytest.mark.parametrize("make", [werner_surface,
                                  lambda: random_surface(np.random.default_rng(7)),
                                  lambda: random_surface(np.random.default_rng(8), rational=True),
                                  quarter_cylinder],
                         ids=["example", "double-knot", "rational", "cylinder"])
def test_points_equal_the_reference(make):
    """Inside, on the domain's ends and beyond them (extrapolated end pieces), in more than
    one chunk: within 1e-12 of the face's size."""
    s = make()
    rng = np.random.default_rng(3)
    (u0, u1), (v0, v1) = s.u_range, s.v_range
    n = 120000                           # over SCIPY_FROM: the compiled path where it exists
    u = rng.uniform(u0 - 0.05 * (u1 - u0), u1 + 0.05 * (u1 - u0), n)
    v = rng.uniform(v0 - 0.05 * (v1 - v0), v1 + 0.05 * (v1 - v0), n)
    u[:4], v[:4] = [u0, u1, u0, u1], [v0, v0, v1, v1]
    got = bs.evaluate(s, u.reshape(600, 200), v.reshape(600, 200)).reshape(-1, 3)
    want = reference(s, u, v)
    size = np.abs(want).max()
    assert np.abs(got - want).max() <= 1e-12 * size
    corners = bs.evaluate(s, u[:4], v[:4])
    np.testing.assert_allclose(corners, want[:4], rtol=0, atol=1e-12 * size)
