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
from tests.pure.surfaces import bezier_knots, quarter_cylinder, random_surface

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
