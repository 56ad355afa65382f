# SPDX-License-Identifier: LGPL-2.1-or-later
"""Grid detection from (u, v) and the C1 correction field."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.compensation.field import GridField
from surfcomp.core.surface.grid import grid_from_indices, grid_from_uv
from surfcomp.errors import GridError


def _uv_grid(n=7, m=10, skew=0.01):
    s, t = np.meshgrid(np.linspace(0.05, 0.95, n), np.linspace(0.02, 0.98, m), indexing="ij")
    return s + skew * np.sin(3 * t), t + skew * s ** 2


def _turned_grid(n):
    """An n x n grid turned by 20 degrees in the parameter plane (the bench's layout)."""
    t = np.linspace(0.01, 0.99, n)
    U, V = np.meshgrid(t, t, indexing="ij")
    a, c = np.radians(20.0), 0.5
    return (c + 0.68 * ((U - c) * np.cos(a) - (V - c) * np.sin(a)),
            c + 0.68 * ((U - c) * np.sin(a) + (V - c) * np.cos(a)))


def test_grid_from_uv_serpentine_shuffled_rows():
    U, V = _uv_grid()
    rng = np.random.default_rng(0)
    # serpentine: every other row reversed, then rows shuffled
    rows = [np.stack([U[:, j], V[:, j]], 1)[:: (1 if j % 2 else -1)] for j in range(U.shape[1])]
    rows = [rows[k] for k in rng.permutation(len(rows))]
    pts = np.concatenate(rows)
    g = grid_from_uv(pts[:, 0], pts[:, 1])
    assert g.shape == (7, 10)
    assert_allclose(g.take(pts[:, 0]), U, atol=0)
    assert_allclose(g.take(pts[:, 1]), V, atol=0)


def test_grid_rows_of_constant_u_and_orientation():
    U, V = _uv_grid(6, 4)
    pts = np.stack([U.ravel(), V.ravel()], 1)[::-1]
    g = grid_from_uv(pts[:, 0], pts[:, 1])
    assert g.shape == (6, 4)
    assert np.all(np.diff(g.take(pts[:, 0]), axis=0) > 0)
    assert np.all(np.diff(g.take(pts[:, 1]), axis=1) > 0)


def test_incomplete_grid_names_the_short_row():
    U, V = _uv_grid(7, 10, skew=0.0)
    u, v = np.delete(U.T.ravel(), 23), np.delete(V.T.ravel(), 23)  # row 3 (v = 0.34) loses u = 0.35
    with pytest.raises(GridError) as exc:
        grid_from_uv(u, v, lines=np.arange(u.size) + 2, source="scan.csv")
    msg = str(exc.value)
    assert msg.startswith("scan.csv: the 69 measured points do not form a complete n x m grid")
    assert "the row at v=0.34 has 6 points (missing near u=0.35)" in msg


def test_grid_from_indices_complete_duplicate_missing():
    U, V = _uv_grid(3, 4)
    r, c = np.indices((3, 4))
    g = grid_from_indices(r.ravel() + 1, c.ravel() + 1, U.ravel(), V.ravel())
    assert_allclose(g.take(U.ravel()), U, atol=0)
    lines = np.arange(12) + 5
    with pytest.raises(GridError, match=r"given twice \(also on line 5\)") as exc:
        rr = r.ravel().copy()
        rr[1] = 0
        cc = c.ravel().copy()
        cc[1] = 0
        grid_from_indices(rr, cc, U.ravel(), V.ravel(), lines, "m.csv")
    assert exc.value.line == 6
    with pytest.raises(GridError, match=r"missing \(row 2, col 3\)"):
        grid_from_indices(r.ravel()[:-1], c.ravel()[:-1], U.ravel()[:-1], V.ravel()[:-1])


def test_field_interpolates_nodes_and_never_overshoots():
    U, V = _uv_grid(7, 10, skew=0.02)
    rng = np.random.default_rng(11)
    D = rng.normal(0.0, 0.02, U.shape)  # noisy 'raw' data
    f = GridField(U, V, D)
    assert_allclose(f(U.ravel(), V.ravel()), D.ravel(), atol=1e-15)
    uu, vv = np.meshgrid(np.linspace(0, 1, 201), np.linspace(0, 1, 201), indexing="ij")
    val = f(uu, vv)
    assert val.shape == uu.shape
    assert val.max() <= D.max() + 1e-15 and val.min() >= D.min() - 1e-15


def test_field_reproduces_constant_and_linear_data():
    s, t = np.meshgrid(np.linspace(0, 1, 8), np.linspace(0, 1, 9), indexing="ij")
    lin = 0.01 + 0.02 * s - 0.03 * t
    f = GridField(s, t, lin)
    uu, vv = np.meshgrid(np.linspace(0, 1, 57), np.linspace(0, 1, 61), indexing="ij")
    assert_allclose(f(uu, vv), 0.01 + 0.02 * uu - 0.03 * vv, atol=1e-15)
    c = GridField(s, t, np.full(s.shape, -0.004))
    assert_allclose(c(uu, vv), -0.004, atol=1e-17)


def test_field_is_continuous_and_bounded_outside():
    s, t = np.meshgrid(np.linspace(0.1, 0.9, 6), np.linspace(0.1, 0.9, 6), indexing="ij")
    D = 0.02 * s
    f = GridField(s, t, D)
    u = np.linspace(0.0, 1.0, 2001)
    val = f(u, np.full(u.size, 0.5))
    assert np.max(np.abs(np.diff(val))) < 1e-4  # no jump at the border (step 0.0005 in u)
    assert val.min() >= D.min() - 1e-15 and val.max() <= D.max() + 1e-15
    # inside the measured region the linear field is exact
    inside = (u >= 0.1) & (u <= 0.9)
    assert_allclose(val[inside], 0.02 * u[inside], atol=1e-15)


@pytest.mark.parametrize("distorted", [False, True])
def test_locate_grid_matches_pointwise_locate(distorted):
    """The tensor-grid locator (separable shortcut, or coarse solve + interpolated
    Newton seeds) finds the same index coordinates as the pointwise one, inside and
    outside the measured region."""
    t = np.linspace(0.05, 0.95, 40)
    U, V = np.meshgrid(t, t ** 1.3, indexing="ij")
    if distorted:
        U = U + 0.01 * np.sin(4 * V)
        V = V + 0.008 * np.cos(3 * U)
    f = GridField(U, V, np.random.default_rng(3).normal(size=U.shape))
    us, vs = np.linspace(0, 1, 157), np.linspace(0, 1, 131)
    s, tt = f.locate_grid(us, vs)
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    s_ref, t_ref = f.locate(uu.ravel(), vv.ravel())
    assert_allclose(s, s_ref, atol=1e-6)
    assert_allclose(tt, t_ref, atol=1e-6)
    # the locator's stated accuracy, 1e-7 grid cells, times node steps of O(3) here
    assert_allclose(f.at_index(s, tt), f.at_index(s_ref, t_ref), atol=3e-6)


def test_pole_net_is_capped_for_dense_grids():
    """Coarse grids: >= 120 spans; medium: 4 spans per grid step; dense: at most
    MAX_SPANS spans, but never fewer than 2 per grid step."""
    from surfcomp.core.compensation.corrected import MAX_SPANS, _span
    from surfcomp.core.compensation.corrected_check import dense_parameters

    assert _span(1.0, 1 / 6, 4) == pytest.approx(1 / 120)
    assert _span(1.0, 1 / 99, 4) == pytest.approx(1 / 396)
    assert _span(1.0, 1 / 499, 4) == pytest.approx(1 / MAX_SPANS)
    assert _span(1.0, 1 / 999, 4) == pytest.approx(1 / 1998)

    class Box:
        u_range = v_range = (0.0, 1.0)

    assert [a.size for a in dense_parameters(Box, (45, 45))] == [177, 177]
    assert [a.size for a in dense_parameters(Box, (500, 500))] == [1997, 1997]
    assert [a.size for a in dense_parameters(Box, (1000, 1000))] == [1999, 1999]


@pytest.mark.parametrize("serpentine", [False, True])
def test_grid_turned_across_parameter_lines_from_file_order(serpentine):
    """A 5 x 7 grid turned by 25 degrees in (u, v): no rows of constant u or v, so its
    scan lines are found from the file order (raster or serpentine)."""
    s_, t_ = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 7), indexing="ij")
    a = np.radians(25.0)
    U = 0.5 + 0.6 * ((s_ - 0.5) * np.cos(a) - (t_ - 0.5) * np.sin(a))
    V = 0.5 + 0.6 * ((s_ - 0.5) * np.sin(a) + (t_ - 0.5) * np.cos(a))
    fu, fv = U.copy(), V.copy()
    if serpentine:
        fu[1::2], fv[1::2] = fu[1::2, ::-1], fv[1::2, ::-1]
    g = grid_from_uv(fu.ravel(), fv.ravel())
    assert g.shape == (5, 7) and g.rows_from.startswith("scan lines in file order")
    assert_allclose(fu.ravel()[g.index], U, atol=0)
    assert_allclose(fv.ravel()[g.index], V, atol=0)
    # a scan with one short line is not a grid: the error names the rows it found
    with pytest.raises(GridError, match="do not form a complete n x m grid"):
        grid_from_uv(fu.ravel()[:-1], fv.ravel()[:-1])


def test_locate_beyond_a_distorted_border():
    """Wavy, unevenly spaced grid lines (like points placed along curves) covering part of
    the face: the linear continuation of such a border can fold far outside, where Newton
    then fails; those points are placed by one outward step from the nearest border
    sample, so the whole face gets bounded field values."""
    rng = np.random.default_rng(5)
    curves = np.linspace(0.06, 0.94, 7) + rng.uniform(-0.02, 0.02, 7)
    U, V = [], []
    for c in curves:
        t = np.linspace(0.04, 0.96, 10) + rng.uniform(-0.03, 0.03, 10)
        U.append(c + 0.05 * np.sin(6 * t))
        V.append(t)
    U, V = np.array(U), np.array(V)
    vals = rng.normal(size=U.shape)
    f = GridField(U, V, vals)
    us = np.linspace(0, 1, 121)
    s, t = f.locate_grid(us, us)
    out = f.at_index(s, t)
    assert np.all(np.isfinite(out))
    assert out.min() >= vals.min() - 1e-12 and out.max() <= vals.max() + 1e-12
    # inside the grid the located points map back exactly
    uu, vv = np.meshgrid(us, us, indexing="ij")
    inside = (s > 0) & (s < 6) & (t > 0) & (t < 9)
    back = f._map(s[inside], t[inside], deriv=False)[0]
    # within the tensor-grid locator's 1e-7 grid cells (cells ~0.1 wide here)
    assert_allclose(back, np.stack([uu.ravel()[inside], vv.ravel()[inside]], axis=1), atol=5e-8)


@pytest.mark.parametrize("axis", [0, 1])
def test_pchip_slopes_are_scipys(axis):
    """The field's own node slopes equal PchipInterpolator's (monotone runs, sign
    changes, flat stretches, zero secants, both ends), to rounding."""
    from scipy.interpolate import PchipInterpolator

    from surfcomp.core.compensation.field import _pchip_slopes

    rng = np.random.default_rng(3)
    cases = [rng.normal(size=(40, 30, 3)), np.round(rng.normal(size=(25, 20, 2))),
             np.cumsum(rng.random((20, 12, 1)), axis=axis), rng.normal(size=(3, 3, 1))]
    for F in cases:
        x = np.arange(F.shape[axis], dtype=float)
        ref = PchipInterpolator(x, F, axis=axis).derivative()(x)
        assert_allclose(_pchip_slopes(F, axis), ref, rtol=0, atol=1e-14)
    # two nodes: the secant at both
    F = rng.normal(size=(2, 5, 1)) if axis == 0 else rng.normal(size=(5, 2, 1))
    secant = np.diff(F, axis=axis)
    assert_allclose(_pchip_slopes(F, axis), np.concatenate([secant, secant], axis=axis))


def test_linear_update_is_the_bilinear_interpolant():
    """``linear_at`` (the residual iteration's update) reproduces node values at the
    nodes, is bilinear inside a cell and holds the border value outside the grid."""
    U, V = _uv_grid(6, 5)
    f = GridField(U, V, np.zeros(U.shape))
    rng = np.random.default_rng(4)
    change = rng.normal(size=U.shape)
    s = np.array([0.0, 2.0, 2.5, 2.25, -1.0, 7.0])
    t = np.array([0.0, 3.0, 3.0, 1.75, 2.0, 4.5])
    got = f.linear_at(s, t) @ change.ravel()
    want = [change[0, 0], change[2, 3], 0.5 * (change[2, 3] + change[3, 3]),
            0.75 * 0.25 * change[2, 1] + 0.75 * 0.75 * change[2, 2]
            + 0.25 * 0.25 * change[3, 1] + 0.25 * 0.75 * change[3, 2],
            change[0, 2], change[5, 4]]
    assert_allclose(got, want, rtol=0, atol=1e-15)


def test_locate_far_beyond_a_noisy_border():
    """A grid turned across the parameter lines leaves half the face outside it; with
    node positions that carry measurement noise (1 % of a step) Newton still locates
    nearly every point many cells beyond a border on the linear continuation (its
    Jacobian holds the border slope's change along the border): 0.4 % of the samples
    fall back to the one-step placement (``_beyond``), 7 % without that term."""
    n = 60
    U, V = _turned_grid(n)
    step = 0.68 * 0.98 / (n - 1)
    rng = np.random.default_rng(7)
    U = U + rng.normal(0, 0.01 * step, U.shape)
    V = V + rng.normal(0, 0.01 * step, V.shape)
    f = GridField(U, V, np.zeros(U.shape))
    fallback = []
    beyond = f._beyond
    f._beyond = lambda uv: (fallback.append(uv.shape[0]), beyond(uv))[1]
    us = vs = np.linspace(0.0, 1.0, 162)
    s, t = f.locate_grid(us, vs)
    sc, tc = f._clamped(s, t)
    assert np.max(np.maximum(np.abs(s - sc), np.abs(t - tc))) > 15   # many cells out
    assert sum(fallback) <= 0.01 * us.size * vs.size
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    miss = np.abs(f._map(s, t, deriv=False)[0] - np.stack([uu.ravel(), vv.ravel()], 1))
    # every point but the fallbacks within locate_grid's tolerance (1e-7 cells)
    assert np.sum(miss.max(axis=1) > 1e-7 / (n - 1)) <= sum(fallback)


def test_locate_starts_points_beyond_the_border_one_linear_step_out():
    """Points nearest a border sample start Newton one linear step out, not at the
    sample: on a turned (affine) grid points up to 60 cells beyond a border are located
    exactly (the continuation is affine there too) in at most three passes; from the
    border sample, with steps limited to the distance out plus one cell, they took seven."""
    n = 40
    t = np.linspace(0.3, 0.7, n)
    S, T = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    a, h = np.radians(20.0), t[1] - t[0]
    U = 0.3 + h * (S * np.cos(a) - T * np.sin(a))
    V = 0.3 + h * (S * np.sin(a) + T * np.cos(a))
    f = GridField(U, V, np.zeros(U.shape))
    passes = []
    mapping = f._map
    f._map = lambda s, t, deriv=True: (passes.append(deriv), mapping(s, t, deriv))[1]
    rng = np.random.default_rng(2)
    s_true = rng.uniform(-60, n + 60, 400)
    t_true = rng.uniform(-10, n + 10, 400)
    u = 0.3 + h * (s_true * np.cos(a) - t_true * np.sin(a))
    v = 0.3 + h * (s_true * np.sin(a) + t_true * np.cos(a))
    s, t = f.locate(u, v)
    assert_allclose(s, s_true, rtol=0, atol=1e-9)
    assert_allclose(t, t_true, rtol=0, atol=1e-9)
    assert passes.count(False) <= 3


def test_locate_grid_in_blocks_and_dropped_caches_give_the_same_field(monkeypatch):
    """locate_grid's Newton runs in blocks of points (bounded temporaries) and the
    field's caches (patch coefficients, slopes, seed tree) can be dropped after the
    samples are placed: both leave every located point and field value as they were."""
    from surfcomp.core.compensation import field as field_module

    n = 30
    U, V = _turned_grid(n)
    vals = np.random.default_rng(9).normal(size=U.shape)
    us = np.linspace(0, 1, 47)
    whole = GridField(U, V, vals)
    s0, t0 = whole.locate_grid(us, us)
    monkeypatch.setattr(field_module, "_BLOCK", 100)
    blocks = GridField(U, V, vals)
    s1, t1 = blocks.locate_grid(us, us)
    assert_allclose(s1, s0, rtol=0, atol=0)
    assert_allclose(t1, t0, rtol=0, atol=0)
    before = whole.at_index(s0, t0)
    whole.drop_caches()
    assert not {"_coeffs", "_slope_cache", "_kd_cache"} & set(whole.__dict__)
    assert_allclose(whole.at_index(s0, t0), before, rtol=0, atol=0)
    assert_allclose(np.stack(whole.locate(U.ravel() + 1e-3, V.ravel()), 1),
                    np.stack(blocks.locate(U.ravel() + 1e-3, V.ravel()), 1), rtol=0, atol=0)
