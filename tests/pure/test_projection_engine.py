# SPDX-License-Identifier: LGPL-2.1-or-later
"""The closest-point projection engine (surfcomp.core.surface.projection) against exact
answers and converged reference solves (no FreeCAD); its OCCT comparison is
tests/app/test_projection_occt.py.
"""

import bisect

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.optimize import least_squares

from surfcomp.core.surface import bspline as bs
from surfcomp.core.surface import projection as pj
from surfcomp.core.surface.bspline import Surface
from surfcomp.errors import Cancelled
from tests.pure.surfaces import (
    bezier_knots,
    hairpin,
    quarter_cylinder,
    random_surface,
    sphere_octant,
)


def reference_projection(surf, P, n_grid=120, n_starts=6):
    """Closest point by brute force: a dense grid, then scipy least_squares from the
    best few grid points (bounded trust-region reflective), best result kept."""
    us = np.linspace(*surf.u_range, n_grid)
    vs = np.linspace(*surf.v_range, n_grid)
    G = bs.evaluate_grid(surf, us, vs).reshape(-1, 3)
    lo = [surf.u_range[0], surf.v_range[0]]
    hi = [surf.u_range[1], surf.v_range[1]]
    at = _last_point_at(surf)
    out = []
    for p in P:
        best = None
        for k in np.argsort(np.sum((G - p) ** 2, axis=1))[:n_starts]:
            x0 = [us[k // n_grid], vs[k % n_grid]]
            fun = lambda x, p=p: at(x)[0] - p  # noqa: E731
            jac = lambda x: np.stack(at(x)[1:], axis=1)  # noqa: E731
            # least_squares only finds the basin (its tolerances below 1e-10 add iterations
            # at rounding level); _polish_foot then fixes the foot to rounding level
            sol = least_squares(fun, x0, jac=jac, bounds=(lo, hi), xtol=1e-10, ftol=1e-10,
                                gtol=1e-10, method="trf")
            if best is None or sol.cost < best.cost:
                best = sol
        out.append(_polish_foot(surf, p, best.x, lo, hi))
    uv = np.array(out)
    return uv[:, 0], uv[:, 1], bs.evaluate(surf, uv[:, 0], uv[:, 1])


def _point_at(surf):
    """``at((u, v))``: the point and its u and v derivatives of ``surf`` at one parameter
    pair, by the B-spline recurrences on Python floats (The NURBS Book, A2.2): code of its
    own for the reference, and at one point some 30 times faster than
    bspline.derivatives, whose arrays are made for many points (the reference's
    least_squares evaluates some 8000 single points a test)."""
    w = np.ones(surf.shape) if surf.weights is None else np.asarray(surf.weights, float)
    hom = np.concatenate([surf.poles * w[..., None], w[..., None]], axis=2)   # (nu, nv, 4)
    ku, kv = list(map(float, surf.knots_u)), list(map(float, surf.knots_v))

    def at(x):
        iu, nu, du = _basis(ku, surf.degree_u, surf.shape[0], float(x[0]))
        iv, nv, dv = _basis(kv, surf.degree_v, surf.shape[1], float(x[1]))
        block = hom[iu:iu + len(nu), iv:iv + len(nv)].transpose(0, 2, 1)   # (u, 4, v)
        along_u = block @ nv
        A, Au, Av = nu @ along_u, du @ along_u, nu @ (block @ dv)
        S = A[:3] / A[3]
        return S, (Au[:3] - Au[3] * S) / A[3], (Av[:3] - Av[3] * S) / A[3]
    return at


def _last_point_at(surf):
    """:func:`_point_at` remembering its last answer: least_squares asks for the residual
    and the Jacobian at the same parameters one after the other."""
    at, last = _point_at(surf), {}

    def cached(x):
        key = (float(x[0]), float(x[1]))
        if key not in last:
            last.clear()
            last[key] = at(x)
        return last[key]
    return cached


def _basis(knots, p, n, t):
    """First index, values and first derivatives of the p + 1 B-splines of degree p that
    are nonzero at t (``n`` of them on ``knots``)."""
    i = min(max(bisect.bisect_right(knots, t) - 1, p), n - 1)
    left, right = [0.0] * (p + 1), [0.0] * (p + 1)
    rows = [[1.0]]                      # rows[j]: the j + 1 B-splines of degree j
    for j in range(1, p + 1):
        left[j], right[j] = t - knots[i + 1 - j], knots[i + j] - t
        row, saved = [], 0.0
        for r in range(j):
            tmp = rows[-1][r] / (right[r + 1] + left[j - r])
            row.append(saved + right[r + 1] * tmp)
            saved = left[j - r] * tmp
        rows.append(row + [saved])
    low = [0.0] + (rows[p - 1] if p else []) + [0.0]     # degree p - 1, padded
    deriv = []
    for r in range(p + 1):
        a, b = knots[i + r] - knots[i - p + r], knots[i + r + 1] - knots[i - p + r + 1]
        deriv.append(p * ((low[r] / a if a else 0.0) - (low[r + 1] / b if b else 0.0)))
    return i - p, np.array(rows[p]), np.array(deriv)


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


@pytest.fixture(scope="module")
def hairpin_reference():
    """Points 0.85..0.97 mm from the hairpin's lower leg and 1.03..1.15 mm from the upper
    one, and their reference feet (solved once for every sample density)."""
    s = hairpin()
    rng = np.random.default_rng(50)
    Q = np.c_[rng.uniform(5, 15, 40), rng.uniform(1, 9, 40), rng.uniform(0.85, 0.97, 40)]
    return s, Q, reference_projection(s, Q)[2]


@pytest.mark.reference_solver
@pytest.mark.parametrize("samples_per_span", [1, 2, None])
def test_project_between_the_legs_of_a_hairpin(hairpin_reference, samples_per_span):
    # with coarse samples the nearest sample is often on the wrong leg; the check
    # for far-apart samples within reach must find the better minimum
    s, Q, rf = hairpin_reference
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
