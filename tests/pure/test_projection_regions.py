# SPDX-License-Identifier: LGPL-2.1-or-later
"""The per-region certificate of projected feet (surfcomp.core.surface.projection_regions): it
follows the curvature towards the point, refuses where another part of the face is
within reach, and never changes a projection (same feet as the point-by-point search
for other minima on every point)."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.core.surface import bspline as bs
from surfcomp.core.surface import projection as pj
from tests.pure.surfaces import hairpin, quarter_cylinder, random_surface


def cylinder_points(surf, depth, n=60, seed=70):
    """Points at ``depth`` mm along -n (n = Su x Sv) from interior points of the face."""
    rng = np.random.default_rng(seed)
    u, v = rng.uniform(0.2, 0.8, n), rng.uniform(0.2, 0.8, n)
    return bs.evaluate(surf, u, v) - depth * bs.normals(surf, u, v)


def certified(projector, X):
    r = projector.project(X)
    return r, projector.regions().certified(r.u, r.v, r.distance)


def test_certificate_follows_the_curvature_towards_the_point():
    """Quarter cylinder of radius 1.5 mm (half the radius, 0.75 mm, is below the 1 mm the
    regions cover): towards the axis a foot is certified up to half the radius, away
    from it (the face bends away) up to the regions' reach."""
    surf = quarter_cylinder(R=1.5, H=10.0)
    P = pj.Projector(surf)
    assert P.safe_distance == pytest.approx(0.75, rel=1e-6)
    S = bs.evaluate(surf, np.array([0.5]), np.array([0.5]))[0]
    n = bs.normals(surf, np.array([0.5]), np.array([0.5]))[0]
    towards_axis = -np.sign(np.dot(n, S - [0, 0, S[2]]))      # the side of the axis, +-1
    for depth, expect in ((0.5, True), (0.74, True), (0.8, False), (1.2, False)):
        r, ok = certified(P, cylinder_points(surf, -towards_axis * depth))
        assert_allclose(np.abs(r.distance), depth, atol=1e-9)
        assert ok.all() == expect and ok.any() == expect, depth
    r, ok = certified(P, cylinder_points(surf, towards_axis * 0.95))   # outside the cylinder
    assert_allclose(np.abs(r.distance), 0.95, atol=1e-9)
    assert ok.all()


def test_certificate_refuses_another_sheet_within_reach():
    """Hairpin legs 2 mm apart: a foot on either leg of a point between them is never
    certified (the other leg is within twice its distance), whichever foot Newton found."""
    s = hairpin()
    rng = np.random.default_rng(71)
    Q = np.c_[rng.uniform(5, 15, 50), rng.uniform(1, 9, 50), rng.uniform(0.6, 1.4, 50)]
    P = pj.Projector(s)
    reg = P.regions()
    r = P.project(Q)
    assert not reg.certified(r.u, r.v, r.distance).any()
    # the foot on each leg (straight above and below the point) at its own distance
    for z in (0.0, 2.0):
        F = P.project(np.c_[Q[:, :2], np.full(len(Q), z)])
        assert_allclose(F.distance, 0.0, atol=1e-5)       # the legs are interpolated
        d = np.einsum("ij,ij->i", Q - F.foot, F.normal)
        assert_allclose(np.abs(d), np.abs(Q[:, 2] - z), atol=1e-5)
        assert not reg.certified(F.u, F.v, d).any()


@pytest.mark.parametrize("case", ["cylinder", "hairpin", "random"])
def test_certified_feet_equal_the_point_by_point_search(case, monkeypatch):
    if case == "cylinder":
        surf = quarter_cylinder(R=1.5, H=10.0)
        rng = np.random.default_rng(72)
        u, v = rng.uniform(0, 1, 3000), rng.uniform(0, 1, 3000)
        X = bs.evaluate(surf, u, v) + rng.uniform(-1.0, 1.0, (3000, 1)) * bs.normals(surf, u, v)
    elif case == "hairpin":
        surf = hairpin()
        rng = np.random.default_rng(73)
        X = np.c_[rng.uniform(-3, 18, 3000), rng.uniform(0, 10, 3000), rng.uniform(-1, 3, 3000)]
    else:
        surf = random_surface(np.random.default_rng(74), nu=9, nv=8, pu=3, pv=2, rational=True)
        rng = np.random.default_rng(75)
        u, v = rng.uniform(0, 1, 3000), rng.uniform(-1, 2, 3000)
        X = bs.evaluate(surf, u, v) + rng.uniform(-1.0, 1.0, (3000, 1)) * bs.normals(surf, u, v)
    P = pj.Projector(surf)
    a = P.project(X)
    _, ok = certified(P, X)
    if case != "hairpin":
        assert 0.2 < ok.mean() < 1.0          # both routes are taken
    monkeypatch.setattr(pj.Projector, "_certified",
                        lambda self, u, *args: np.zeros(u.size, dtype=bool))
    b = pj.Projector(surf).project(X)
    assert a.converged.all() and b.converged.all()
    assert_allclose(a.distance, b.distance, atol=1e-10, rtol=0)
    assert_allclose(a.foot, b.foot, atol=1e-8, rtol=0)
    assert (a.outside == b.outside).all()
