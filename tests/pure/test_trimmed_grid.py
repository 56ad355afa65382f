# SPDX-License-Identifier: LGPL-2.1-or-later
"""The grid form of the trimmed-domain integrals: the same rule as point by point, and the
correction integral against an analytic B-spline integral."""

import numpy as np
import pytest

from surfcomp.core.surface import bspline
from surfcomp.core.surface.bspline import Surface
from surfcomp.core.surface.trimmed import (
    _layer,
    correction_integral,
    domain_integral,
    knots_of,
    tensor_integral,
    whole_domain,
)
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
    # the square is the whole parameter domain: the tensor rule, its panels broken at the
    # correction's knots both ways, is exact (cubic pieces, 3 Gauss points)
    nominal = _plane(size)
    got = correction_integral(nominal, corrected, 1, _square(400))
    assert got == pytest.approx(exact, rel=1e-12)
    assert exact == pytest.approx(0.025 * size * size, rel=0.05)
    # over a trimmed region, Green's rule: exact in u; what is left is the midpoint rule
    # along the sides in v (random poles: a rough correction)
    def func(u, v):
        return _layer(bspline.derivatives(nominal, u, v, order=2),
                      bspline.evaluate(corrected, u, v), 1)

    knots = knots_of(nominal, corrected)
    fine = domain_integral(func, _square(4000), knots=knots)
    assert fine == pytest.approx(exact, rel=1e-7)
    coarse = domain_integral(func, _square(400), knots=knots)
    assert coarse == pytest.approx(exact, rel=1e-5)
    assert abs(coarse - exact) > 1e3 * abs(got - exact)


def test_whole_domain_is_a_loop_around_the_rectangle():
    rect = ((0.0, 1.0), (0.0, 1.0))
    assert whole_domain(_square(400), *rect)
    assert whole_domain([p[::-1] for p in _square(50)[::-1]], *rect)      # clockwise
    assert whole_domain(_square(2), *rect)
    # a hole, a smaller rectangle, a disc, a loop beyond the domain: not the whole domain
    assert not whole_domain(_square(400) + [_circle((0.5, 0.5), 0.1, reverse=True)], *rect)
    assert not whole_domain([0.5 * p for p in _square(400)], *rect)
    assert not whole_domain([_circle((0.5, 0.5), 0.5)], *rect)
    assert not whole_domain([2.0 * p - 0.5 for p in _square(400)], *rect)
    # half the border traced there and back: on the border, but no area
    half = _square(50)[:2]
    assert not whole_domain(half + [p[::-1] for p in half[::-1]], *rect)
    # the domain's own range matters, not the unit square
    assert not whole_domain(_square(400), (0.0, 2.0), (0.0, 1.0))


def test_tensor_rule_of_a_polynomial():
    """Degree 5 in u and in v per panel is exact."""
    def grid(us, vs):
        return us[:, None] ** 5 * vs[None, :] ** 4 + 3.0 * us[:, None] * vs[None, :]

    got = tensor_integral(grid, (0.0, 2.0), (-1.0, 1.0), (np.array([0.3]), np.array([0.1])))
    exact = 2 ** 6 / 6 * 2 / 5 + 3 * 2 ** 2 / 2 * 0.0
    assert got == pytest.approx(exact, rel=1e-13)
