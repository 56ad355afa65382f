# SPDX-License-Identifier: LGPL-2.1-or-later
"""The numeric B-spline engine against analytic and library references (no FreeCAD).

References: de Casteljau's algorithm (written here, independent of the engine),
scipy.interpolate.BSpline for 1-D basis functions, exact planes, bilinear
patches and circles, dense least squares on the explicit Kronecker product.
"""

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.interpolate import BSpline

from surfcomp.core.surface import bspline as bs
from surfcomp.core.surface.bspline import Surface
from surfcomp.errors import GeometryError, GridError

# --------------------------------------------------------------------------- helpers

def casteljau(ctrl, t):
    """Bezier curve (ctrl along axis 0, any trailing shape) at scalar t."""
    c = np.array(ctrl, dtype=float)
    while c.shape[0] > 1:
        c = (1.0 - t) * c[:-1] + t * c[1:]
    return c[0]


def bezier_surface_point(Pw, u, v):
    """Homogeneous Bezier surface point by de Casteljau along v, then u."""
    rows = np.array([casteljau(Pw[i], v) for i in range(Pw.shape[0])])
    return casteljau(rows, u)


def bezier_homog_derivs(Pw, u, v):
    """A, Au, Av of a homogeneous Bezier patch via hodographs (deg * differences)."""
    pu, pv = Pw.shape[0] - 1, Pw.shape[1] - 1
    A = bezier_surface_point(Pw, u, v)
    Au = bezier_surface_point(pu * (Pw[1:] - Pw[:-1]), u, v)
    Av = bezier_surface_point(pv * (Pw[:, 1:] - Pw[:, :-1]), u, v)
    return A, Au, Av


def bezier_knots(p):
    return np.r_[np.zeros(p + 1), np.ones(p + 1)]


def random_surface(rng, nu=7, nv=6, pu=3, pv=2, rational=False, interior_double=True):
    ku = np.r_[np.zeros(pu + 1), np.sort(rng.uniform(0.05, 0.95, nu - pu - 1)), np.ones(pu + 1)]
    if interior_double and nu - pu - 1 >= 2:
        ku[pu + 2] = ku[pu + 1]  # a double interior knot
    kv = np.r_[np.zeros(pv + 1), np.sort(rng.uniform(0.05, 0.95, nv - pv - 1)), np.ones(pv + 1)]
    kv = kv * 3.0 - 1.0  # v domain [-1, 2]
    gu, gv = np.meshgrid(np.linspace(0, 100, nu), np.linspace(0, 60, nv), indexing="ij")
    poles = np.stack([gu, gv, 10 * np.sin(gu / 30) * np.cos(gv / 20)], axis=2)
    poles += rng.normal(scale=3.0, size=poles.shape)
    w = rng.uniform(0.5, 2.0, (nu, nv)) if rational else None
    return Surface(poles, ku, kv, pu, pv, w)


def quarter_cylinder(R=25.0, H=40.0):
    """Rational quadratic x linear quarter cylinder around the z axis."""
    ring = np.array([[R, 0, 0], [R, R, 0], [0, R, 0]], float)
    poles = np.stack([ring, ring + [0, 0, H]], axis=1)  # (3, 2, 3)
    w = np.array([[1, 1], [np.sqrt(0.5)] * 2, [1, 1]])
    return Surface(poles, bezier_knots(2), bezier_knots(1), 2, 1, w)


# --------------------------------------------------------------------------- spans, basis

def test_find_spans_known_values_and_domain_end():
    k = np.array([0, 0, 0, 1, 2, 2, 3, 3, 3], float)  # degree 2, 6 poles
    t = np.array([0.0, 0.5, 1.0, 1.9, 2.0, 2.5, 3.0, -1.0, 4.0])
    assert bs.find_spans(k, 2, 6, t).tolist() == [2, 2, 3, 3, 5, 5, 5, 2, 5]


@pytest.mark.parametrize("p", [1, 2, 3, 4, 5])
def test_basis_matrix_matches_scipy(p):
    rng = np.random.default_rng(p)
    inner = np.sort(rng.uniform(0, 1, 6))
    inner[3] = inner[2]  # double knot
    k = np.r_[np.zeros(p + 1), inner, np.ones(p + 1)]
    n = k.size - p - 1
    t = np.r_[rng.uniform(0, 1, 200), 0.0, 1.0]
    for d in range(min(p, 3) + 1):
        B = bs.basis_matrix(k, p, n, t, d).toarray()
        ref = np.array([BSpline(k, np.eye(n)[j], p)(t, nu=d) for j in range(n)]).T
        assert_allclose(B, ref, atol=1e-9 * max(1.0, np.abs(ref).max()))
    assert_allclose(bs.basis_matrix(k, p, n, t).sum(axis=1).A.ravel(), 1.0, atol=1e-14)


def test_basis_functions_derivatives_above_degree_are_zero():
    k = bezier_knots(2)
    ders, spans = bs.basis_functions(k, 2, np.array([0.2, 0.7]), nderiv=4)
    assert ders.shape == (5, 2, 3)
    assert_allclose(ders[3:], 0.0, atol=0)
    assert_allclose(ders[2], [[2, -4, 2], [2, -4, 2]], atol=1e-13)  # Bernstein 2nd derivatives


def test_greville_known_values():
    k = np.array([0, 0, 0, 0, 1, 2, 3, 3, 3, 3], float)
    assert_allclose(bs.greville(k, 3), [0, 1 / 3, 1, 2, 8 / 3, 3], atol=1e-15)
    assert_allclose(bs.greville(np.array([0, 0, .4, 1, 1.]), 1), [0, .4, 1], atol=1e-15)


# --------------------------------------------------------------------------- evaluation

def test_bilinear_patch_exact():
    P = np.array([[[0, 0, 0], [0, 10, 1]], [[20, 0, 2], [20, 10, 7]]], float)
    s = Surface(P, bezier_knots(1), bezier_knots(1), 1, 1)
    rng = np.random.default_rng(1)
    u, v = rng.uniform(0, 1, (2, 50))
    ref = ((1 - u) * (1 - v))[:, None] * P[0, 0] + ((1 - u) * v)[:, None] * P[0, 1] \
        + (u * (1 - v))[:, None] * P[1, 0] + (u * v)[:, None] * P[1, 1]
    S, Su, Sv, Suu, Suv, Svv = bs.derivatives(s, u, v, order=2)
    assert_allclose(S, ref, atol=1e-12)
    assert_allclose(Su, (1 - v)[:, None] * (P[1, 0] - P[0, 0]) + v[:, None] * (P[1, 1] - P[0, 1]),
                    atol=1e-12)
    assert_allclose(Sv, (1 - u)[:, None] * (P[0, 1] - P[0, 0]) + u[:, None] * (P[1, 1] - P[1, 0]),
                    atol=1e-12)
    assert_allclose(Suu, 0, atol=1e-12)
    assert_allclose(Svv, 0, atol=1e-12)
    assert_allclose(Suv, np.broadcast_to(P[1, 1] - P[1, 0] - P[0, 1] + P[0, 0], Suv.shape),
                    atol=1e-12)


def test_plane_normals_and_shape():
    P = np.zeros((4, 3, 3))
    P[..., 0], P[..., 1] = np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij")
    P[..., 2] = 5.0
    s = Surface(P, np.r_[0, 0, 0, .5, 1, 1, 1], np.r_[0, 0, 1, 2, 2.], 2, 1)
    u, v = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 2, 5), indexing="ij")
    n = bs.normals(s, u, v)
    assert n.shape == (4, 5, 3)
    assert_allclose(n, np.broadcast_to([0, 0, 1.0], n.shape), atol=1e-14)
    assert_allclose(bs.evaluate(s, u, v)[..., 2], 5.0, atol=1e-13)


@pytest.mark.parametrize("rational", [False, True])
@pytest.mark.parametrize("degrees", [(3, 2), (4, 4), (1, 5)])
def test_bezier_patch_matches_de_casteljau(rational, degrees):
    pu, pv = degrees
    rng = np.random.default_rng(pu * 10 + pv + rational)
    P = rng.uniform(-50, 50, (pu + 1, pv + 1, 3))
    w = rng.uniform(0.3, 3.0, (pu + 1, pv + 1)) if rational else None
    s = Surface(P, bezier_knots(pu), bezier_knots(pv), pu, pv, w)
    Pw = np.concatenate([P * (1 if w is None else w[..., None]),
                         (np.ones((pu + 1, pv + 1)) if w is None else w)[..., None]], axis=2)
    u, v = rng.uniform(0, 1, (2, 40))
    u[:2], v[:2] = [0.0, 1.0], [1.0, 0.0]
    S, Su, Sv = bs.derivatives(s, u, v, order=1)
    for i in range(u.size):
        A, Au, Av = bezier_homog_derivs(Pw, u[i], v[i])
        ref = A[:3] / A[3]
        assert_allclose(S[i], ref, atol=1e-11)
        assert_allclose(Su[i], (Au[:3] - Au[3] * ref) / A[3], atol=1e-9)
        assert_allclose(Sv[i], (Av[:3] - Av[3] * ref) / A[3], atol=1e-9)
    assert_allclose(bs.evaluate(s, u, v), S, atol=0)


@pytest.mark.parametrize("rational", [False, True])
def test_second_derivatives_match_finite_differences(rational):
    s = random_surface(np.random.default_rng(4), rational=rational)
    rng = np.random.default_rng(5)
    u, v = rng.uniform(0.02, 0.98, 30), rng.uniform(-0.9, 1.9, 30)
    S, Su, Sv, Suu, Suv, Svv = bs.derivatives(s, u, v, order=2)
    h = 1e-4

    def fd(fun, du, dv):  # 4th-order central difference of a first derivative
        return (-fun(u + 2 * h * du, v + 2 * h * dv) + 8 * fun(u + h * du, v + h * dv)
                - 8 * fun(u - h * du, v - h * dv) + fun(u - 2 * h * du, v - 2 * h * dv)) / (12 * h)

    d1u = lambda a, b: bs.derivatives(s, a, b)[1]  # noqa: E731
    d1v = lambda a, b: bs.derivatives(s, a, b)[2]  # noqa: E731
    ev = lambda a, b: bs.evaluate(s, a, b)  # noqa: E731
    # stay inside one knot span for the finite differences
    ok = (np.abs(u[:, None] - s.knots_u[None, :]).min(axis=1) > 3 * h) & \
         (np.abs(v[:, None] - s.knots_v[None, :]).min(axis=1) > 3 * h)
    assert ok.sum() >= 20
    scale = np.abs(Suu).max()
    assert_allclose(fd(ev, 1, 0)[ok], Su[ok], atol=1e-8 * np.abs(Su).max())
    assert_allclose(fd(ev, 0, 1)[ok], Sv[ok], atol=1e-8 * np.abs(Sv).max())
    assert_allclose(fd(d1u, 1, 0)[ok], Suu[ok], atol=1e-7 * scale)
    assert_allclose(fd(d1u, 0, 1)[ok], Suv[ok], atol=1e-7 * scale)
    assert_allclose(fd(d1v, 0, 1)[ok], Svv[ok], atol=1e-7 * np.abs(Svv).max())


def test_rational_quarter_cylinder_is_exact():
    R = 25.0
    s = quarter_cylinder(R)
    rng = np.random.default_rng(7)
    u, v = rng.uniform(0, 1, (2, 500))
    S, Su, Sv, Suu, Suv, Svv = bs.derivatives(s, u, v, order=2)
    assert_allclose(np.hypot(S[:, 0], S[:, 1]), R, atol=1e-12)
    assert_allclose(S[:, 2], 40.0 * v, atol=1e-12)
    # tangent to the circle, vertical ruling
    assert_allclose(np.einsum("ij,ij->i", Su[:, :2], S[:, :2]), 0, atol=1e-10)
    assert_allclose(Sv, np.broadcast_to([0, 0, 40.0], Sv.shape), atol=1e-12)
    # curvature of the circle from Su, Suu: |C' x C''| / |C'|^3 = 1/R
    kappa = np.linalg.norm(np.cross(Su, Suu), axis=1) / np.linalg.norm(Su, axis=1) ** 3
    assert_allclose(kappa, 1.0 / R, rtol=1e-12)
    assert_allclose(Suv, 0, atol=1e-12)
    assert_allclose(Svv, 0, atol=1e-12)
    n = bs.normals(s, u, v)
    assert_allclose(n[:, :2], S[:, :2] / R, atol=1e-12)  # outward radial (Su x Sv)
    assert_allclose(n[:, 2], 0, atol=1e-14)


def test_degenerate_normals_collapsed_edge():
    # a curved patch whose u = 0 edge collapses into one point (apex of a cone-like cap)
    rng = np.random.default_rng(3)
    nu, nv = 4, 5
    ang = np.linspace(0, np.pi / 2, nv)
    r = np.linspace(0, 30, nu)
    P = np.stack([r[:, None] * np.cos(ang), r[:, None] * np.sin(ang),
                  10 - 0.01 * r[:, None] ** 2 + 0 * ang], axis=2)
    P[1, :, 2] = 10.0  # first row level with the apex: the tangent plane there is z = 10
    P[2:] += rng.normal(scale=0.2, size=P[2:].shape)
    s = Surface(P, bezier_knots(3), np.r_[0, 0, 0, .3, .6, 1, 1, 1.], 3, 2)
    v = np.linspace(0, 1, 9)
    u = np.zeros_like(v)
    _, Su, Sv = bs.derivatives(s, u, v)
    assert_allclose(Sv, 0, atol=1e-12)  # really degenerate there
    n = bs.normals(s, u, v)
    assert np.all(np.isfinite(n))
    # Su x Sv orientation: +z for this layout (u radial, v counter-clockwise)
    assert_allclose(n, np.broadcast_to([0, 0, 1.0], n.shape), atol=1e-7)
    # the same as the limit of the regular normals a small step inside
    assert_allclose(n, bs.normals(s, u + 1e-6, v), atol=1e-5)


def test_fully_degenerate_surface_raises():
    P = np.zeros((2, 2, 3))
    P[1, :, 0] = 1.0  # a line: Su x Sv = 0 everywhere
    s = Surface(P, bezier_knots(1), bezier_knots(1), 1, 1)
    with pytest.raises(GeometryError, match="degenerate"):
        bs.normals(s, np.array([0.5]), np.array([0.5]))


@pytest.mark.parametrize("rational", [False, True])
@pytest.mark.parametrize("rows", [23, 3])
def test_evaluate_grid_matches_pointwise(rational, rows):
    """Both contraction orders: along v first, and along u first for a few rows (blocks
    of the dense check grid)."""
    s = random_surface(np.random.default_rng(11), nu=9, nv=7, rational=rational)
    us = np.linspace(0, 1, rows)
    vs = np.linspace(-1, 2, 17 if rows > 3 else 40)
    U, V = np.meshgrid(us, vs, indexing="ij")
    for order in (0, 1, 2):
        grid = bs.evaluate_grid(s, us, vs, order=order)
        grid = (grid,) if order == 0 else grid
        pts = bs.derivatives(s, U, V, order=order)
        assert len(grid) == len(pts)
        for g, p in zip(grid, pts):
            assert g.shape == U.shape + (3,)
            assert_allclose(g, p, atol=1e-10 * max(1.0, np.abs(p).max()))


def test_chunked_evaluation_agrees(monkeypatch):
    s = random_surface(np.random.default_rng(12), rational=True)
    rng = np.random.default_rng(13)
    u, v = rng.uniform(0, 1, (3000,)), rng.uniform(-1, 2, (3000,))
    whole = bs.derivatives(s, u.reshape(60, 50), v.reshape(60, 50), order=2)
    monkeypatch.setattr(bs, "CHUNK_VALUES", 1)  # chunks of 1024 points
    parts = bs.derivatives(s, u.reshape(60, 50), v.reshape(60, 50), order=2)
    for a, b in zip(whole, parts):
        assert a.shape == (60, 50, 3)
        assert_allclose(a, b, atol=0)


def test_shape_and_order_errors():
    s = random_surface(np.random.default_rng(1))
    with pytest.raises(ValueError, match="same shape"):
        bs.evaluate(s, np.zeros(3), np.zeros(4))
    with pytest.raises(ValueError, match="order"):
        bs.derivatives(s, 0.5, 0.5, order=3)


# --------------------------------------------------------------------------- knot insertion

@pytest.mark.parametrize("rational", [False, True])
def test_insert_knots_keeps_geometry(rational):
    s = random_surface(np.random.default_rng(21), rational=rational)
    new_u = [0.1, 0.1, 0.33, 0.77, 0.5]
    new_v = [-0.5, 0.0, 1.5, 1.5]
    r = bs.insert_knots(s, new_u, new_v)
    assert r.shape == (s.shape[0] + 5, s.shape[1] + 4)
    assert r.u_range == s.u_range and r.v_range == s.v_range
    rng = np.random.default_rng(22)
    u, v = rng.uniform(0, 1, 400), rng.uniform(-1, 2, 400)
    u[:3], v[:3] = [0, 1, 0.1], [-1, 2, 1.5]
    for a, b in zip(bs.derivatives(s, u, v, 1), bs.derivatives(r, u, v, 1)):
        assert_allclose(a, b, atol=1e-12 * max(1.0, np.abs(a).max()))
    assert_allclose(bs.evaluate(s, u, v), bs.evaluate(r, u, v), atol=1e-12)


def test_refine_knots_matches_scipy_curve():
    rng = np.random.default_rng(23)
    k = np.r_[0, 0, 0, 0, 0.4, 1, 1, 1, 1.0]
    c = rng.normal(size=5)
    k2, c2 = bs.refine_knots(k, 3, c, [0.2, 0.4, 0.9])
    t = np.linspace(0, 1, 101)
    assert_allclose(BSpline(k2, c2, 3)(t), BSpline(k, c, 3)(t), atol=1e-14)
    assert k2.tolist() == [0, 0, 0, 0, 0.2, 0.4, 0.4, 0.9, 1, 1, 1, 1]


def test_refine_knots_rejects_bad_knots():
    k = np.r_[0, 0, 0, 0.5, 0.5, 1, 1, 1.0]
    with pytest.raises(ValueError, match="multiplicity"):
        bs.refine_knots(k, 2, np.zeros(5), [0.5])
    with pytest.raises(ValueError, match="outside"):
        bs.refine_knots(k, 2, np.zeros(5), [1.0])


# --------------------------------------------------------------------------- fitting

@pytest.mark.parametrize("rational", [False, True])
def test_interpolate_grid_recovers_poles(rational):
    s = random_surface(np.random.default_rng(31), nu=12, nv=8, rational=rational)
    gu, gv = bs.greville(s.knots_u, 3), bs.greville(s.knots_v, 2)
    X = bs.evaluate_grid(s, gu, gv)
    P = bs.interpolate_grid(gu, gv, X, s.knots_u, s.knots_v, 3, 2, weights=s.weights)
    assert_allclose(P, s.poles, atol=1e-9)
    # and the fitted surface really passes through the points
    fit = Surface(P, s.knots_u, s.knots_v, 3, 2, s.weights)
    assert_allclose(bs.evaluate_grid(fit, gu, gv), X, atol=1e-10)


@pytest.mark.parametrize("rational", [False, True])
def test_zero_displacement_refit_in_refined_space_gives_nominal_back(rational):
    s = random_surface(np.random.default_rng(32), nu=10, nv=7, rational=rational)
    # refine: mid points of every non-empty span
    ku, kv = np.unique(s.knots_u), np.unique(s.knots_v)
    r = bs.insert_knots(s, 0.5 * (ku[1:] + ku[:-1]), 0.5 * (kv[1:] + kv[:-1]))
    us, vs = np.linspace(0, 1, 4 * r.shape[0]), np.linspace(-1, 2, 4 * r.shape[1])
    X = bs.evaluate_grid(s, us, vs)  # dense samples of the nominal, zero displacement
    P = bs.fit_grid_lsq(us, vs, X, r.knots_u, r.knots_v, 3, 2, weights=r.weights)
    assert_allclose(P, r.poles, atol=1e-9)


def test_fit_grid_lsq_equals_dense_kronecker_least_squares():
    rng = np.random.default_rng(33)
    ku = np.r_[0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1.0]
    kv = np.r_[0, 0, 0, 0.5, 1, 1, 1.0]
    us, vs = np.sort(rng.uniform(0, 1, 15)), np.sort(rng.uniform(0, 1, 11))
    us[[0, -1]], vs[[0, -1]] = [0, 1], [0, 1]
    X = rng.normal(size=(15, 11, 3))
    P = bs.fit_grid_lsq(us, vs, X, ku, kv, 3, 2)
    Bu = bs.basis_matrix(ku, 3, 6, us).toarray()
    Bv = bs.basis_matrix(kv, 2, 4, vs).toarray()
    ref, *_ = np.linalg.lstsq(np.kron(Bu, Bv), X.reshape(-1, 3), rcond=None)
    assert_allclose(P, ref.reshape(6, 4, 3), atol=1e-10)


def test_fit_errors():
    ku = np.r_[0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1.0]
    kv = np.r_[0, 0, 1, 1.0]
    with pytest.raises(GridError, match="shape"):
        bs.fit_grid_lsq(np.linspace(0, 1, 10), np.linspace(0, 1, 3), np.zeros((10, 4, 3)),
                        ku, kv, 3, 1)
    with pytest.raises(GridError, match="support"):  # no samples in (0.3, 1]
        bs.fit_grid_lsq(np.linspace(0, 0.29, 10), np.linspace(0, 1, 3), np.zeros((10, 3, 3)),
                        ku, kv, 3, 1)
    X = np.zeros((10, 3, 3))
    X[2, 1, 0] = np.nan
    with pytest.raises(GridError, match="NaN"):
        bs.fit_grid_lsq(np.linspace(0, 1, 10), np.linspace(0, 1, 3), X, ku, kv, 3, 1)
    with pytest.raises(GridError, match="as many grid parameters as poles"):
        bs.interpolate_grid(np.linspace(0, 1, 10), np.linspace(0, 1, 2), np.zeros((10, 2, 3)),
                            ku, kv, 3, 1)
    with pytest.raises(GridError, match="singular"):  # two equal parameters
        bs.interpolate_grid(np.r_[0, 0.1, 0.1, 0.5, 0.8, 1], np.linspace(0, 1, 2),
                            np.zeros((6, 2, 3)), ku, kv, 3, 1)


# --------------------------------------------------------------------------- projection
# (surfcomp.core.surface.projection; its OCCT comparison is tests/app/test_projection_occt.py)

from scipy.optimize import least_squares  # noqa: E402

from surfcomp.core.surface import projection as pj  # noqa: E402
from surfcomp.errors import Cancelled  # noqa: E402


def sphere_octant(R=10.0):
    """Exact rational octant of a sphere; its u = 0 edge collapses into the pole (0, 0, R)."""
    s = np.sqrt(0.5)
    mer = np.array([[0, R], [R, R], [R, 0]], float)  # (x, z) of the meridian poles
    wm = np.array([1, s, 1])
    rot = lambda x, z: [[x, 0, z], [x, x, z], [0, x, z]]  # noqa: E731
    poles = np.array([rot(x, z) for x, z in mer], float)
    w = wm[:, None] * wm[None, :]
    return Surface(poles, bezier_knots(2), bezier_knots(2), 2, 2, w)


def reference_projection(surf, P, n_grid=120, n_starts=6):
    """Closest point by brute force: a dense grid, then scipy least_squares from the
    best few grid points (bounded trust-region reflective), best result kept."""
    us = np.linspace(*surf.u_range, n_grid)
    vs = np.linspace(*surf.v_range, n_grid)
    G = bs.evaluate_grid(surf, us, vs).reshape(-1, 3)
    lo = [surf.u_range[0], surf.v_range[0]]
    hi = [surf.u_range[1], surf.v_range[1]]
    out = []
    for p in P:
        best = None
        for k in np.argsort(np.sum((G - p) ** 2, axis=1))[:n_starts]:
            x0 = [us[k // n_grid], vs[k % n_grid]]
            fun = lambda x, p=p: bs.evaluate(surf, x[:1], x[1:])[0] - p  # noqa: E731

            def jac(x):
                _, Su, Sv = bs.derivatives(surf, x[:1], x[1:])
                return np.stack([Su[0], Sv[0]], axis=1)
            sol = least_squares(fun, x0, jac=jac, bounds=(lo, hi), xtol=1e-15, ftol=1e-15,
                                gtol=1e-15, method="trf")
            if best is None or sol.cost < best.cost:
                best = sol
        out.append(_polish_foot(surf, p, best.x, lo, hi))
    uv = np.array(out)
    return uv[:, 0], uv[:, 1], bs.evaluate(surf, uv[:, 0], uv[:, 1])


def _polish_foot(surf, p, x, lo, hi, steps=40):
    """Newton on the foot-point condition g = Su.(S - p) = Sv.(S - p) = 0 from
    least_squares' answer, the parameters on a bound held there.

    least_squares stops on its cost, the squared distance, whose rounding leaves the foot
    undetermined to about the square root of the machine epsilon (1e-7 mm here), and
    where it stops depends on the BLAS kernel. The root of g is fixed to rounding level.
    g's Jacobian comes from central differences of the exact g: an approximate Jacobian
    slows Newton down but does not move its root. Asserts that g vanished.
    """
    def grad(y):
        S, Su, Sv = bs.derivatives(surf, y[:1], y[1:])
        r = S[0] - p
        return np.array([Su[0] @ r, Sv[0] @ r]), np.stack([Su[0], Sv[0]])

    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    x = np.clip(np.asarray(x, float), lo, hi)
    span = hi - lo
    h = 1e-6 * span
    for _ in range(steps):
        free = (np.minimum(x - lo, hi - x) > 1e-12 * span)
        g, J = grad(x)
        if not free.any():
            break
        H = np.empty((2, 2))
        for k in range(2):
            e = np.zeros(2)
            e[k] = h[k]
            H[:, k] = (grad(x + e)[0] - grad(x - e)[0]) / (2 * h[k])
        idx = np.flatnonzero(free)
        step = np.zeros(2)
        step[idx] = -np.linalg.solve(H[np.ix_(idx, idx)], g[idx])
        x = np.clip(x + step, lo, hi)
        if np.all(np.abs(step) <= 1e-15 * span):
            break
    g, J = grad(x)
    free = (np.minimum(x - lo, hi - x) > 1e-12 * span)
    scale = np.linalg.norm(J, axis=1)
    assert np.all(np.abs(g[free]) <= 1e-12 * scale[free] * max(1.0, np.linalg.norm(
        bs.evaluate(surf, x[:1], x[1:])[0] - p))), "reference foot did not converge"
    return x


def test_project_plane_inside_and_outside():
    P = np.array([[[0, 0, 0], [0, 20, 0]], [[10, 0, 0], [10, 20, 0]]], float)
    s = Surface(P, bezier_knots(1), bezier_knots(1), 1, 1)
    rng = np.random.default_rng(40)
    X = np.c_[rng.uniform(0, 10, 50), rng.uniform(0, 20, 50), rng.uniform(-2, 2, 50)]
    r = pj.project(s, X)
    assert_allclose(r.distance, X[:, 2], atol=1e-12, rtol=0)
    assert_allclose(r.foot, np.c_[X[:, :2], np.zeros(50)], atol=1e-12, rtol=0)
    assert_allclose(r.u, X[:, 0] / 10, atol=1e-13, rtol=0)
    assert_allclose(r.normal, np.broadcast_to([0, 0, 1.0], (50, 3)), atol=1e-15, rtol=0)
    assert r.converged.all() and not r.outside.any()
    # beyond the x = 0 edge: closest point on the edge, flagged, plain distance with sign
    Y = np.c_[-rng.uniform(0.5, 3, 20), rng.uniform(1, 19, 20), rng.uniform(-2, 2, 20)]
    r = pj.project(s, Y)
    assert r.outside.all()
    assert_allclose(r.u, 0.0, atol=0, rtol=0)
    assert_allclose(r.foot, np.c_[np.zeros(20), Y[:, 1], np.zeros(20)], atol=1e-12, rtol=0)
    assert_allclose(r.distance, np.sign(Y[:, 2]) * np.hypot(Y[:, 0], Y[:, 2]), atol=1e-12, rtol=0)


def test_project_rational_quarter_cylinder_exact():
    R, H = 25.0, 40.0
    s = quarter_cylinder(R, H)
    rng = np.random.default_rng(41)
    n = 400
    th = rng.uniform(0.02, np.pi / 2 - 0.02, n)
    # from 0.1 R (concave side, distance close to the radius of curvature) to 1.5 R
    rho = np.r_[rng.uniform(0.1 * R, 1.5 * R, n - 100), R + rng.uniform(-1, 1, 100)]
    z = rng.uniform(0, H, n)
    X = np.c_[rho * np.cos(th), rho * np.sin(th), z]
    r = pj.project(s, X)
    assert r.converged.all() and not r.outside.any()
    assert_allclose(r.distance, rho - R, atol=1e-9, rtol=0)
    assert_allclose(r.foot, np.c_[R * np.cos(th), R * np.sin(th), z], atol=1e-9, rtol=0)
    assert_allclose(r.normal, np.c_[np.cos(th), np.sin(th), np.zeros(n)], atol=1e-9, rtol=0)
    assert_allclose(bs.evaluate(s, r.u, r.v), r.foot, atol=1e-9, rtol=0)
    # angles below 0: the closest point is on the straight edge at angle 0 (x = R, y = 0)
    th2 = rng.uniform(-0.6, -0.05, 50)
    rho2 = rng.uniform(0.5 * R, 1.5 * R, 50)
    z2 = rng.uniform(0, H, 50)
    Y = np.c_[rho2 * np.cos(th2), rho2 * np.sin(th2), z2]
    r = pj.project(s, Y)
    assert r.outside.all()
    assert_allclose(r.foot, np.c_[np.full(50, R), np.zeros(50), z2], atol=1e-9, rtol=0)
    expect = np.sign(Y[:, 0] - R) * np.hypot(Y[:, 0] - R, Y[:, 1])
    assert_allclose(r.distance, expect, atol=1e-9, rtol=0)


@pytest.mark.reference_solver
@pytest.mark.parametrize("rational", [False, True])
def test_project_random_surface_matches_least_squares_reference(rational):
    s = random_surface(np.random.default_rng(42), nu=8, nv=7, pu=3, pv=2, rational=rational)
    rng = np.random.default_rng(43)
    u, v = rng.uniform(0, 1, 60), rng.uniform(-1, 2, 60)
    u[:10] = rng.uniform(0, 0.01, 10)  # near the boundary
    S, Su, Sv = bs.derivatives(s, u, v)
    d = rng.uniform(-1, 1, 60)
    X = S + d[:, None] * bs.normals(s, u, v)
    X[50:] += rng.normal(scale=5.0, size=(10, 3))  # arbitrary points, some outside
    r = pj.project(s, X)
    ru, rv, rf = reference_projection(s, X)
    assert r.converged.all()
    dist_ref = np.linalg.norm(X - rf, axis=1)
    assert_allclose(np.abs(r.distance), dist_ref, atol=1e-12, rtol=0)
    # the reference converges to rounding level (5e-13 mm on Haswell and SkylakeX kernels)
    assert_allclose(r.foot, rf, atol=1e-11, rtol=0)
    assert_allclose(r.distance[:50], d[:50], atol=1e-9, rtol=0)  # constructed along the normal
    on_edge = (np.minimum(ru - 0, 1 - ru) < 1e-12) | (np.minimum(rv + 1, 2 - rv) < 1e-12)
    assert (r.outside == on_edge).all()


@pytest.mark.reference_solver
def test_project_concave_points_pick_the_global_minimum():
    # a wavy bicubic (z = 5 cos(2 pi x / 40)): points above the troughs, close to the
    # curvature centres, and points between two crests with two competing minima
    xs, ys = np.linspace(0, 80, 17), np.linspace(0, 20, 5)
    k = np.r_[0, 0, 0, np.linspace(0, 1, 15), 1, 1, 1]  # 17 poles, cubic
    kv = np.r_[0, 0, 0, 0, 0.5, 1, 1, 1, 1]
    gu, gv = bs.greville(k, 3), bs.greville(kv, 3)
    X, Y = np.meshgrid(80 * gu, 20 * gv, indexing="ij")
    pts = np.stack([X, Y, 5 * np.cos(2 * np.pi * X / 40)], axis=2)
    P = bs.interpolate_grid(gu, gv, pts, k, kv, 3, 3)
    s = Surface(P, k, kv, 3, 3)
    rng = np.random.default_rng(44)
    n = 40
    x = np.r_[rng.uniform(17, 23, n // 2), rng.uniform(57, 63, n // 2)]  # above troughs
    y = rng.uniform(2, 18, n)
    z = -5 + rng.uniform(5.0, 9.0, n)  # trough radius of curvature ~8.1 mm
    Q = np.c_[x, y, z]
    r = pj.project(s, Q)
    ru, rv, rf = reference_projection(s, Q, n_grid=160, n_starts=6)
    assert r.converged.all()
    assert_allclose(np.abs(r.distance), np.linalg.norm(Q - rf, axis=1), atol=1e-12, rtol=0)
    # close to a curvature centre the distance is flat in the foot position; the polished
    # reference still fixes the foot to 1.4e-13 mm
    assert_allclose(r.foot, rf, atol=1e-11, rtol=0)
    assert len(xs) == 17 and len(ys) == 5


def test_project_degenerate_pole_of_a_sphere():
    R = 10.0
    s = sphere_octant(R)
    rng = np.random.default_rng(45)
    h = rng.uniform(-3, 3, 30)
    X = np.c_[np.zeros(30), np.zeros(30), R + h]  # right above/below the collapsed pole
    r = pj.project(s, X)
    assert r.converged.all()
    assert_allclose(r.foot, np.broadcast_to([0, 0, R], (30, 3)), atol=1e-7, rtol=0)
    assert_allclose(r.distance, h, atol=1e-9, rtol=0)
    assert_allclose(r.normal, np.broadcast_to([0, 0, 1.0], (30, 3)), atol=1e-7, rtol=0)
    # and everywhere else on the octant: radial distances, inside (concave) and outside
    th, ph = rng.uniform(0.05, 1.5, 200), rng.uniform(0.02, 1.55, 200)
    rho = rng.uniform(0.2 * R, 1.5 * R, 200)
    d = np.c_[np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)]
    r = pj.project(s, rho[:, None] * d)
    assert_allclose(r.distance, rho - R, atol=1e-9, rtol=0)
    assert_allclose(r.foot, R * d, atol=1e-8, rtol=0)


def test_project_nan_rows_max_distance_progress_and_chunks(monkeypatch):
    s = random_surface(np.random.default_rng(46), nu=6, nv=6, pu=3, pv=3)
    rng = np.random.default_rng(47)
    u, v = rng.uniform(0, 1, 3000), rng.uniform(-1, 2, 3000)
    X = bs.evaluate(s, u, v) + 0.5 * bs.normals(s, u, v)
    X[5] = np.nan
    X[7] += [500.0, 0, 0]  # far away
    calls = []
    r = pj.project(s, X, max_distance=10.0, progress=lambda f, m: calls.append(f))
    assert np.isnan(r.distance[[5, 7]]).all() and np.isnan(r.foot[[5, 7]]).all()
    assert not r.converged[[5, 7]].any() and not r.outside[[5, 7]].any()
    ok = np.ones(3000, dtype=bool)
    ok[[5, 7]] = False
    assert r.converged[ok].all()
    assert_allclose(r.distance[ok], 0.5, atol=1e-9, rtol=0)
    assert calls and calls[-1] == 1.0 and calls == sorted(calls)
    # tiny chunks and blocks give the same numbers
    monkeypatch.setattr(pj, "CHUNK", 64)
    r2 = pj.project(s, X, max_distance=10.0)
    assert_allclose(r2.distance[ok], r.distance[ok], atol=1e-12, rtol=0)
    assert_allclose(r2.foot[ok], r.foot[ok], atol=1e-12, rtol=0)

    def cancel(f, m):
        raise Cancelled("stop")
    with pytest.raises(Cancelled):
        pj.project(s, X, progress=cancel)
    with pytest.raises(pj.InputError, match="shape"):
        pj.project(s, X[:, :2])


def test_span_table_matches_derivatives():
    for rational in (False, True):
        s = random_surface(np.random.default_rng(48), nu=9, nv=6, pu=4, pv=2, rational=rational)
        rng = np.random.default_rng(49)
        u, v = rng.uniform(0, 1, 500), rng.uniform(-1, 2, 500)
        u[:2], v[:2] = [0, 1], [-1, 2]
        ref = bs.derivatives(s, u, v, order=2)
        got = pj.SpanTable(s).evaluate(u, v, 2)
        for a, b in zip(ref, got):
            assert_allclose(b.T, a, atol=1e-10 * np.abs(a).max())


def hairpin(n=60):
    """A hairpin profile (two parallel legs 2 mm apart joined by a 1 mm radius bend),
    interpolated by a cubic and extruded 10 mm along y."""
    k = np.r_[0, 0, 0, np.linspace(0, 1, n - 2), 1, 1, 1]
    g = bs.greville(k, 3)
    t = g * (40 + np.pi)
    x = np.where(t < 20, 20 - t, np.where(t < 20 + np.pi, -np.sin(t - 20), t - 20 - np.pi))
    z = np.where(t < 20, 0.0, np.where(t < 20 + np.pi, 1 - np.cos(t - 20), 2.0))
    prof = np.stack([x, np.zeros(n), z], 1)
    pts = np.stack([prof, prof + [0, 10.0, 0]], axis=1)
    kv = np.r_[0, 0, 1, 1.0]
    return Surface(bs.interpolate_grid(g, [0.0, 1.0], pts, k, kv, 3, 1), k, kv, 3, 1)


@pytest.mark.reference_solver
@pytest.mark.parametrize("samples_per_span", [1, 2, None])
def test_project_between_the_legs_of_a_hairpin(samples_per_span):
    # points 0.85..0.97 mm from the lower leg and 1.03..1.15 mm from the upper one:
    # with coarse samples the nearest sample is often on the wrong leg; the check
    # for far-apart samples within reach must find the better minimum
    s = hairpin()
    rng = np.random.default_rng(50)
    Q = np.c_[rng.uniform(5, 15, 40), rng.uniform(1, 9, 40), rng.uniform(0.85, 0.97, 40)]
    ru, rv, rf = reference_projection(s, Q)
    r = pj.Projector(s, samples_per_span=samples_per_span).project(Q)
    assert r.converged.all()
    assert_allclose(np.abs(r.distance), np.linalg.norm(Q - rf, axis=1), atol=1e-12, rtol=0)
    assert_allclose(r.foot, rf, atol=1e-11, rtol=0)
    assert_allclose(r.foot[:, 2], 0.0, atol=1e-3, rtol=0)  # on the lower leg


def test_project_generic_evaluator_fallback_agrees(monkeypatch):
    # surfaces too large for the span table use bspline.derivatives instead
    s = random_surface(np.random.default_rng(51), nu=9, nv=8, pu=3, pv=2, rational=True)
    rng = np.random.default_rng(52)
    u, v = rng.uniform(0, 1, 500), rng.uniform(-1, 2, 500)
    X = bs.evaluate(s, u, v) + rng.uniform(-1, 1, (500, 1)) * bs.normals(s, u, v)
    fast = pj.Projector(s)
    assert isinstance(fast.ev, pj.SpanTable)
    monkeypatch.setattr(pj, "MAX_TABLE_VALUES", 0)
    slow = pj.Projector(s)
    assert isinstance(slow.ev, pj.GenericEval)
    a, b = fast.project(X), slow.project(X)
    assert_allclose(b.distance, a.distance, atol=1e-9, rtol=0)
    assert_allclose(b.foot, a.foot, atol=1e-8, rtol=0)
    assert b.converged.all()


def test_band_factor_equals_sparse_lu_and_names_a_singular_matrix():
    """Collocation matrices are solved as band matrices (many right-hand sides); the
    result is SuperLU's to rounding, a wide matrix still goes to SuperLU, and a zero
    pivot raises the Schoenberg-Whitney message."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from surfcomp.core.surface import bspline_fit
    from surfcomp.core.surface.bspline_basis import basis_matrix, greville

    n = 300
    knots = np.r_[[0.0] * 4, np.linspace(0, 1, n - 2)[1:-1], [1.0] * 4]
    M = sp.csr_matrix(basis_matrix(knots, 3, n, greville(knots, 3)))
    B = np.random.default_rng(6).normal(size=(n, 7))
    want = spla.splu(sp.csc_matrix(M)).solve(B)
    np.testing.assert_allclose(bspline_fit._factor(M, "test")(B), want, rtol=0, atol=1e-12)
    np.testing.assert_allclose(bspline_fit._factor(M, "test")(B[:, 0]), want[:, 0], atol=1e-12)
    wide = sp.random(40, 40, density=0.5, random_state=1) + 10 * sp.eye(40)
    np.testing.assert_allclose(bspline_fit._factor(wide, "test")(B[:40]),
                               spla.splu(sp.csc_matrix(wide)).solve(B[:40]), atol=1e-12)
    sites = greville(knots, 3)
    sites[10] = sites[11]                                  # two equal rows
    with pytest.raises(GridError, match="singular.*Schoenberg-Whitney"):
        bspline_fit._factor(sp.csr_matrix(basis_matrix(knots, 3, n, sites)), "u matrix")
