# SPDX-License-Identifier: LGPL-2.1-or-later
"""Projections answered from the last foot (issue 28's speed): the same results as the
projection engine afresh, and the same best fit."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from surfcomp.core.measurement import align
from surfcomp.core.simulation.presets import werner_surface
from surfcomp.core.surface import bspline
from surfcomp.core.surface.projection import Projector
from surfcomp.core.surface.projection_newton import EVAL_BLOCK, SpanTable
from surfcomp.core.surface.projection_warm import TAYLOR_TOL, Tracker
from tests.pure.surfaces import wavy_patch


def cloud(surf, n, spread_mm, seed):
    """Points along the face's normals, ``spread_mm`` standard deviation off it."""
    rng = np.random.default_rng(seed)
    u = rng.uniform(*surf.u_range, n)
    v = rng.uniform(*surf.v_range, n)
    off = rng.normal(0.0, spread_mm, n)[:, None]
    return bspline.evaluate(surf, u, v) + bspline.normals(surf, u, v) * off


def small_motion(P, size_mm, seed):
    """``P`` moved rigidly so that no point moves more than about ``size_mm``."""
    rng = np.random.default_rng(seed)
    c = P.mean(axis=0)
    reach = np.sqrt(((P - c) ** 2).sum(axis=1).max())
    axis = rng.normal(size=3)
    R = Rotation.from_rotvec(axis / np.linalg.norm(axis) * 0.5 * size_mm / reach).as_matrix()
    t = rng.normal(size=3)
    return (P - c) @ R.T + c + 0.5 * size_mm * t / np.linalg.norm(t)


def assert_same(a, b, dist_tol, foot_tol):
    np.testing.assert_allclose(a.distance, b.distance, rtol=0, atol=dist_tol)
    np.testing.assert_allclose(a.foot, b.foot, rtol=0, atol=foot_tol)
    np.testing.assert_allclose(a.normal, b.normal, rtol=0, atol=1e-7)
    np.testing.assert_array_equal(a.outside, b.outside)
    assert a.converged.all() and b.converged.all()


@pytest.mark.parametrize("surf", [wavy_patch(), werner_surface()], ids=["wavy", "werner"])
@pytest.mark.parametrize("size", [1e-6, 1e-4, 8e-4])
def test_taylor_answers_equal_a_fresh_projection(surf, size):
    """Motions below TAYLOR_TOL are answered without evaluating the face; the distances
    are those of the engine within 1e-11 mm (the engine's own Newton tolerance leaves
    ~1e-13 mm), the feet within 1e-8 mm."""
    pj = Projector(surf, workers=2)
    P = cloud(surf, 5000, 0.05, 1)
    tr = Tracker(pj)
    assert_same(tr.project(P), pj.project(P), 0.0, 0.0)
    assert tr.counts == {"taylor": 0, "newton": 0, "fresh": 5000}
    for k in range(3):                      # always from the first call's feet
        Q = small_motion(P, size, 10 + k)
        assert_same(tr.project(Q), pj.project(Q), 1e-11, 1e-8)
    assert size < TAYLOR_TOL
    assert tr.counts == {"taylor": 15000, "newton": 0, "fresh": 5000}


def test_larger_motions_iterate_from_the_last_foot_and_far_points_start_afresh():
    """Feet that move more than TAYLOR_TOL run Newton from their last foot (exact
    evaluations; the result becomes their new base); points beyond half the smallest
    radius of curvature, and points that could not be projected, go to the engine."""
    surf = wavy_patch()
    pj = Projector(surf, workers=2)
    P = cloud(surf, 3000, 0.05, 2)
    P[:100] += bspline.normals(surf, np.full(100, 0.5), np.full(100, 0.5)) * (
        1.5 * pj.safe_distance)
    P[100] = np.nan
    tr = Tracker(pj)
    tr.project(P)
    Q, counts = P, []
    for k, size in enumerate((0.05, 0.02, 1e-5)):      # each from the last position
        Q = np.vstack([small_motion(Q[:100], size, 30 + k), [[np.nan] * 3],
                       small_motion(Q[101:], size, 20 + k)])
        a, b = tr.project(Q), pj.project(Q)
        np.testing.assert_allclose(a.distance, b.distance, rtol=0, atol=1e-10, equal_nan=True)
        np.testing.assert_allclose(a.foot, b.foot, rtol=0, atol=1e-7, equal_nan=True)
        np.testing.assert_array_equal(a.converged, b.converged)
        assert np.isnan(a.distance[100]) and not a.converged[100]
        counts.append(dict(tr.counts))
    # the far points and the NaN row afresh every time; the others by Newton at the two
    # larger motions (from the new base the second time; a few feet move less than
    # TAYLOR_TOL along the face), then by the Taylor model
    assert [c["fresh"] for c in counts] == [3000 + 101, 3000 + 202, 3000 + 303]
    assert counts[0]["newton"] >= 2899 - 10 and counts[1]["newton"] >= 2 * 2899 - 20
    assert counts[2]["newton"] == counts[1]["newton"]
    assert sum(counts[2][k] for k in ("taylor", "newton")) == 3 * 2899


def test_blocked_evaluation_equals_one_call():
    """The span table evaluates in blocks of EVAL_BLOCK points: bit for bit the values of
    one call over all points."""
    surf = werner_surface()
    ev = SpanTable(surf)
    rng = np.random.default_rng(3)
    n = 2 * EVAL_BLOCK + 123
    u, v = rng.uniform(*surf.u_range, n), rng.uniform(*surf.v_range, n)
    for order in (0, 1, 2):
        blocked = ev.evaluate(u, v, order)
        whole = ev._evaluate(u, v, order)
        assert len(blocked) == len(whole) == (1, 3, 6)[order]
        for a, b in zip(blocked, whole):
            np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(blocked[0].T, bspline.evaluate(surf, u, v), rtol=0, atol=1e-12)


def test_best_fit_from_last_feet_equals_fresh_projections():
    """The fit that answers later iterations from the last feet ends where the fit that
    projects afresh at every iteration ends (0.1 um asked; 1e-9 mm found), with 5 %
    outliers of 1 mm, noise and a 30 degree start."""
    surf = wavy_patch()
    rng = np.random.default_rng(5)
    P = cloud(surf, 60000, 2e-3, 6)
    bad = rng.choice(P.shape[0], P.shape[0] // 20, replace=False)
    P[bad] += rng.choice([-1.0, 1.0], (bad.size, 1)) * [0.0, 0.0, 1.0]
    c = P.mean(axis=0)
    R = Rotation.from_rotvec(np.radians(30.0) * np.array([0.0, 0.6, 0.8])).as_matrix()
    moved = (P - c) @ R.T + c + [5.0, -3.0, 2.0]
    ref = [align.Reference("Face1", surf)]
    warm, _ = align.best_fit(moved, ref)
    cold, _ = align.best_fit(moved, ref, warm=False)
    assert warm.converged and cold.converged
    S = bspline.evaluate_grid(surf, np.linspace(0, 1, 9), np.linspace(0, 1, 9)).reshape(-1, 3)
    assert np.abs(align.apply(warm.matrix, S) - align.apply(cold.matrix, S)).max() <= 1e-9
    np.testing.assert_allclose(warm.residual, cold.residual, rtol=0, atol=1e-9,
                               equal_nan=True)
    np.testing.assert_array_equal(warm.weight == 0, cold.weight == 0)
