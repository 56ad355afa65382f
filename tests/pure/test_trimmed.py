# SPDX-License-Identifier: LGPL-2.1-or-later
"""Integrals and the inside test over trimmed (u, v) regions, against analytic values."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.surface.bspline import Surface
from surfcomp.core.surface.trimmed import correction_integral, domain_integral, inside, knots_of


def _circle(c, r, n=2000, reverse=False):
    t = np.linspace(0.0, 2 * np.pi, n)
    if reverse:
        t = t[::-1]
    return np.stack([c[0] + r * np.cos(t), c[1] + r * np.sin(t)], axis=1)


def _square_pieces(u0, u1, v0, v1, n=50):
    """A square's four sides as separate pieces, counter-clockwise (like a face's edges)."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    corners = np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1], [u0, v0]])
    return [a + s * (b - a) for a, b in zip(corners[:-1], corners[1:])]


def test_area_of_a_disc_and_an_annulus():
    ones = lambda u, v: np.ones_like(u)             # noqa: E731
    # a polygon of 2000 points inscribed in the circle: pi r^2 (1 - (2 pi / n)^2 / 6)
    poly = np.pi * 0.35 ** 2 * (1 - (2 * np.pi / 1999) ** 2 / 6)
    disc = domain_integral(ones, [_circle((0.5, 0.5), 0.35)])
    assert disc == pytest.approx(poly, rel=2e-5)
    # a hole runs the other way round and is subtracted; all pieces reversed: the same
    hole = np.pi * 0.01 * (1 - (2 * np.pi / 1999) ** 2 / 6)
    ring = domain_integral(ones, [_circle((0.5, 0.5), 0.35),
                                  _circle((0.45, 0.55), 0.1, reverse=True)])
    assert ring == pytest.approx(poly - hole, rel=2e-5)
    back = domain_integral(ones, [_circle((0.5, 0.5), 0.35, reverse=True),
                                  _circle((0.45, 0.55), 0.1)])
    assert back == pytest.approx(ring, rel=1e-12)


def test_polynomial_over_a_square_is_exact():
    # the panels hold polynomials of degree <= 5 in u exactly (3 Gauss points); along the
    # straight sides the midpoint rule in v is exact for F linear in v
    f = lambda u, v: u ** 5 * v + 3 * u * v       # noqa: E731
    got = domain_integral(f, _square_pieces(0.0, 2.0, 0.0, 1.0, n=2))
    exact = 2 ** 6 / 6 / 2 + 3 * 2 ** 2 / 2 / 2
    assert got == pytest.approx(exact, rel=1e-12)


def test_a_shared_grid_sees_the_difference_of_two_regions():
    """Two discs whose radii differ by 1e-6: on one grid the difference of the integrals
    is the ring's, 2 pi r dr, to 1e-3 (alone each is only good to ~1e-5 of pi r^2)."""
    f = lambda u, v: 1.0 + u * v                 # noqa: E731
    r, dr = 0.3, 1e-6
    box = (0.19, 0.81, 0.19, 0.81)
    a = domain_integral(f, [_circle((0.5, 0.5), r)], box=box)
    b = domain_integral(f, [_circle((0.5, 0.5), r + dr)], box=box)
    # the ring's integral of 1 + u v: (1 + 0.25) 2 pi r dr (u v averages 0.25 on the ring)
    assert b - a == pytest.approx(1.25 * 2 * np.pi * r * dr, rel=2e-3)


def test_inside_follows_the_even_odd_rule():
    pieces = _square_pieces(0.0, 1.0, 0.0, 1.0) + [_circle((0.5, 0.5), 0.2)]
    rng = np.random.default_rng(3)
    uv = rng.uniform(-0.2, 1.2, (5000, 2))
    got = inside(pieces, uv[:, 0], uv[:, 1])
    in_square = np.all((uv > 0) & (uv < 1), axis=1)
    in_hole = np.hypot(uv[:, 0] - 0.5, uv[:, 1] - 0.5) < 0.2
    # points closer than the polygon's chord error to the hole's circle may go either way
    near = np.abs(np.hypot(uv[:, 0] - 0.5, uv[:, 1] - 0.5) - 0.2) < 1e-6
    assert np.array_equal(got[~near], (in_square & ~in_hole)[~near])
    assert got.shape == (5000,) and inside(pieces, np.zeros((2, 3)), np.zeros((2, 3))).shape \
        == (2, 3)


def _plane(size=10.0):
    """z = 0 over [0, size]^2 as a bilinear B-spline with u, v in [0, 1]."""
    P = np.zeros((2, 2, 3))
    P[1, :, 0] = size
    P[:, 1, 1] = size
    k = np.array([0.0, 0.0, 1.0, 1.0])
    return Surface(P, k, k, 1, 1)


def test_correction_integral_of_an_offset_plane():
    """A plane moved by 0.01 against its normal over a disc of radius 3 mm: 0.01 pi 9."""
    nominal = _plane()
    moved = Surface(nominal.poles - [0.0, 0.0, 0.01], nominal.knots_u, nominal.knots_v, 1, 1)
    disc = [_circle((0.5, 0.5), 0.3)]
    got = correction_integral(nominal, moved, 1, disc)
    assert got == pytest.approx(0.01 * np.pi * 9.0, rel=2e-5)
    # outward = -1 (a reversed face): the same surfaces remove material on the other side
    assert correction_integral(nominal, moved, -1, disc) == pytest.approx(-got, rel=1e-12)
    ku, kv = knots_of(nominal, moved)
    assert_allclose(ku, [0.0, 1.0]) and assert_allclose(kv, [0.0, 1.0])


def test_correction_integral_of_a_sphere_cap():
    """A sphere of radius 2 (quadratic rational patch, one octant) moved inwards by 0.1: the
    layer's volume is (R^3 - (R - d)^3) / 3 per steradian, 1.4 % less than d R^2."""
    w = np.sqrt(0.5)
    R, d = 2.0, 0.1
    # one octant: u along the meridian from the pole, v around the axis (NURBS book 8.1)
    arc = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    wa = np.array([1.0, w, 1.0])
    P = np.zeros((3, 3, 3))
    W = np.zeros((3, 3))
    for i in range(3):
        x, z = arc[i, 0], arc[i, 2]
        for j, (cx, cy, wj) in enumerate(((1, 0, 1), (1, 1, w), (0, 1, 1))):
            P[i, j] = [x * cx, x * cy, z]
            W[i, j] = wa[i] * wj
    k = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    outer = Surface(R * P, k, k, 2, 2, W)
    inner = Surface((R - d) * P, k, k, 2, 2, W)
    square = _square_pieces(0.0, 1.0, 0.0, 1.0, n=400)
    octant = np.pi / 2                                # steradians
    got = correction_integral(outer, inner, 1, square)
    assert got == pytest.approx(octant * (R ** 3 - (R - d) ** 3) / 3, rel=1e-6)
    assert got < 0.99 * octant * d * R ** 2


def test_a_ray_along_a_seam_that_closes_to_rounding_counts_it_once():
    """A circle's pcurve sampled from its seam at (0.85, 0.5) ends 1e-12 from where it began:
    points on the face at the seam's v were counted outside (the ray met the seam twice),
    which the file route's trim warning hid behind OCCT's distance and the direct route
    (its face from the reader child, no OCCT) reported as 2.7 mm beyond the face."""
    from surfcomp.core.surface.trimmed import inside, snap_ends

    t = np.linspace(0.0, 2.0 * np.pi, 400)
    circle = np.column_stack([0.5 + 0.35 * np.cos(t), 0.5 + 0.35 * np.sin(t)])
    circle[-1, 1] = 0.5 + 1e-12
    u = np.array([0.675, 0.7625, 0.2, 0.95])
    v = np.full(4, 0.5 + 1e-13)
    assert list(inside([circle], u, v)) == [True, True, True, False]
    snapped = snap_ends([circle])[0]
    assert np.array_equal(snapped[-1], snapped[0]) and circle[-1, 1] == 0.5 + 1e-12
