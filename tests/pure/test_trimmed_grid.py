# SPDX-License-Identifier: LGPL-2.1-or-later
"""The grid form of the trimmed-domain integrals: the same rule as point by point, and the
correction integral against an analytic B-spline integral."""

import numpy as np
import pytest

from surfcomp.core.surface import bspline
from surfcomp.core.surface.bspline import Surface
from surfcomp.core.surface.trimmed import correction_integral, domain_integral, knots_of
from tests.pure.test_trimmed import _circle, _plane


def _square(n=400):
    s = np.linspace(0.0, 1.0, n)[:, None]
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]])
    return [a + s * (b - a) for a, b in zip(corners[:-1], corners[1:])]


def _knots(spans, degree=3):
    inner = np.linspace(0.0, 1.0, spans + 1)
    return np.concatenate([[0.0] * degree, inner, [1.0] * degree])


def _bumped_plane(size=20.0, spans=40, seed=5):
    """The plane over [0, size]^2 as a bicubic with ``spans`` spans a side, its poles moved
    down by random amounts of up to 50 um: ``(surface, z offsets of the poles)``."""
    rng = np.random.default_rng(seed)
    k = _knots(spans)
    n = spans + 3
    g = bspline.greville(k, 3)
    P = np.zeros((n, n, 3))
    P[..., 0] = size * g[:, None]
    P[..., 1] = size * g[None, :]
    dz = rng.uniform(0.0, 0.05, (n, n))
    P[..., 2] = -dz
    return Surface(P, k, k, 3, 3), dz


def test_the_grid_gives_the_pointwise_rule():
    """Over a disc with a hole, a B-spline integrand: the whole panels summed on the grid
    equal the point-by-point sum to rounding."""
    surf, _ = _bumped_plane(spans=12, seed=2)

    def func(u, v):
        return bspline.evaluate(surf, u, v)[..., 2] + u * v

    def grid(us, vs):
        return bspline.evaluate_grid(surf, us, vs)[..., 2] + us[:, None] * vs[None, :]

    pieces = [_circle((0.5, 0.5), 0.4, n=800),
              _circle((0.55, 0.45), 0.1, n=800, reverse=True)]
    knots = knots_of(surf)
    plain = domain_integral(func, pieces, knots=knots, panels=16)
    fast = domain_integral(func, pieces, knots=knots, panels=16, grid=grid)
    assert fast == pytest.approx(plain, rel=1e-12)
    assert abs(plain) > 1e-3                    # not a vanishing integral


def test_correction_integral_of_a_bumped_plane_is_the_spline_integral():
    """A plane moved down by a bicubic of 40 x 40 spans: the layer is the correction itself
    (no curvature), whose integral is sum(dz_ij * span integrals of the basis functions)."""
    size, spans = 20.0, 40
    corrected, dz = _bumped_plane(size, spans)
    k = corrected.knots_u
    basis = (k[4:] - k[:-4]) / 4.0                # integral of each cubic basis function
    exact = size * size * float(basis @ dz @ basis)
    # the panels break at the correction's knots, so the rule in u is exact; what is left
    # is the midpoint rule along the sides in v (random poles: a rough correction)
    got = correction_integral(_plane(size), corrected, 1, _square(4000))
    assert got == pytest.approx(exact, rel=1e-7)
    coarse = correction_integral(_plane(size), corrected, 1, _square(400))
    assert coarse == pytest.approx(exact, rel=1e-5)
    assert exact == pytest.approx(0.025 * size * size, rel=0.05)
