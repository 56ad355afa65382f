# SPDX-License-Identifier: LGPL-2.1-or-later
"""A fold's edge vector and the boundary refinement of a corrected region face (issue 30;
no FreeCAD)."""

import numpy as np
import pytest

from surfcomp.core.compensation import region_build, region_edges
from surfcomp.core.surface.bspline import evaluate_grid
from tests.pure.surfaces import wavy_patch


def _fold(phi, convex):
    """Two faces on the +x side of an edge along y, their outward normals 180 - 2 phi
    apart, leaning towards the faces (a fold: the normals' sum points into them) or away
    (a knife edge)."""
    s = -1.0 if convex else 1.0
    K = len(phi)
    na = np.stack([s * np.sin(phi), np.zeros(K), np.cos(phi)], axis=1)
    nb = np.stack([s * np.sin(phi), np.zeros(K), -np.cos(phi)], axis=1)
    inward = np.tile([1.0, 0.0, 0.0], (K, 1))
    return region_build.miters(na, nb, inward, inward)


def test_a_fold_shrinks_its_vector_through_zero():
    """Where the normals' sum and the in-face directions cancel (sin phi = KNIFE_SHARE),
    the fold's vector passes through zero, never longer than the knife limit, instead of
    turning round between two samples (a step of twice the limit); a knife edge keeps the
    full limit."""
    limit = region_edges.knife_limit(region_build.MITER_ANGLE)
    phi = np.linspace(0.0, 0.2, 801)          # 0.00025 rad a sample
    m, exact = _fold(phi, convex=False)
    np.testing.assert_allclose(exact, 0.0, atol=1e-12)
    np.testing.assert_allclose(m[:, 1:], 0.0, atol=1e-15)
    assert m[0, 0] == pytest.approx(-limit, abs=1e-12)      # the in-face directions' side
    assert m[-1, 0] == pytest.approx(limit, abs=1e-12)      # the normals' side
    zero = np.argmin(np.abs(np.sin(phi) - region_build.KNIFE_SHARE))
    assert abs(m[zero, 0]) < 0.01
    # each step: the change of the bisector's sum (2 cos(phi) dphi) over its floor 0.1
    assert np.max(np.abs(np.diff(m[:, 0]))) <= limit * 2 * 0.00025 / 0.1 + 1e-12
    assert np.max(np.linalg.norm(m, axis=1)) <= limit + 1e-12
    m, _ = _fold(phi, convex=True)
    np.testing.assert_allclose(m[:, 0], -limit, atol=1e-12)


def test_a_boundary_curve_is_refined_where_it_misses_the_displacement():
    """A correction that varies fast along one boundary (a 0.4 mm wide bump on v = 1):
    the knot spans there are halved until the boundary curve follows it within EDGE_TOL
    halfway between the fit samples, within the pole budget; without the refinement it
    misses by more."""
    surf = wavy_patch()

    def field(x):
        return 0.02 * np.exp(-((x[:, 0] - 13.0) / 0.4) ** 2) * np.exp(-((x[:, 1] - 30.0)
                                                                          / 3.0) ** 2)

    def miss(built):
        u = np.linspace(0.0, 1.0, 4001)
        v = np.array([1.0])
        P, Su, Sv = evaluate_grid(surf, u, v, order=1)
        n = np.cross(Su, Sv)
        n /= np.linalg.norm(n, axis=2, keepdims=True)
        want = P - field(P.reshape(-1, 3)).reshape(P.shape[:2])[..., None] * n
        return np.max(np.linalg.norm(evaluate_grid(built.surface, u, v) - want, axis=2))

    rounds = region_build.REFINE_ROUNDS
    try:
        region_build.REFINE_ROUNDS = 0
        plain = region_build.corrected_surface(surf, 1, field, knot_step=3.0)
    finally:
        region_build.REFINE_ROUNDS = rounds
    refined = region_build.corrected_surface(surf, 1, field, knot_step=3.0)
    assert miss(plain) > 10 * region_build.EDGE_TOL
    assert miss(refined) <= 2 * region_build.EDGE_TOL      # between the check points too
    assert refined.poles[0] > plain.poles[0] and refined.poles[1] == plain.poles[1]
    assert refined.poles[0] * refined.poles[1] <= region_build.MIN_BUDGET


def test_an_edge_turning_sharp_within_a_mm_eases_over_the_length_given():
    """An edge whose exactness drops from 1 to 0 within 1 mm (its angle crossing the knife
    limit, from s = 15 to 16 mm) and a second edge that stays exact: eased over 4 mm, the
    first never rises above what it was, changes by at most 1/40 from one 0.1 mm sample to
    the next (a 4 mm wide average of values in [0, 1]), is 1 up to twice the length before
    the drop and 0 from its end on, and passes 0.5 about halfway; the second stays 1."""
    s = np.arange(0.0, 30.0001, 0.1)
    K = len(s)
    points = np.concatenate([np.stack([s, np.zeros(K), np.zeros(K)], axis=1),
                             np.stack([s, np.ones(K), np.zeros(K)], axis=1)])
    edge = np.repeat([0, 1], K)
    exact = np.r_[1.0 - region_edges.smoothstep(s - 15.0), np.ones(K)]
    out = region_edges.eased(exact, edge, points, 4.0)
    first, second = out[:K], out[K:]
    assert np.all(first <= exact[:K] + 1e-12)
    np.testing.assert_allclose(second, 1.0, atol=1e-12)
    assert np.max(np.abs(np.diff(first))) <= 1.0 / 40.0 + 1e-9
    np.testing.assert_allclose(first[s <= 15.0 - 8.0 + 1e-9], 1.0, atol=1e-12)
    np.testing.assert_allclose(first[s >= 16.0 - 1e-9], 0.0, atol=1e-12)
    assert 0.3 < first[np.argmin(np.abs(s - 11.5))] < 0.7      # halfway down the ramp
