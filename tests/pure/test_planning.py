# SPDX-License-Identifier: LGPL-2.1-or-later
"""Measurement planning on core surfaces: layouts, margins, tilt, reach, counts, order."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.cli.option_flags import flag
from surfcomp.core.measurement.planning import (
    MAX_POINTS,
    PlanSettings,
    check_points,
    parse_count,
    plan_points,
)
from surfcomp.core.measurement.planning_adaptive import turning_rate
from surfcomp.core.measurement.planning_face import FaceDomain
from surfcomp.core.measurement.planning_reach import (
    nearest_neighbour,
    serpentine,
    travel_length,
)
from surfcomp.core.simulation.presets import mirror_surface, werner_surface
from surfcomp.core.surface import bspline
from surfcomp.core.surface.bspline import Surface
from surfcomp.errors import InputError
from tests.pure.test_trimmed import _circle, _square_pieces


def _plane(size=40.0):
    """A flat 40 x 40 mm bilinear face, (u, v) = (x, y) / 40, z = 0, normal +z."""
    x = np.array([0.0, size])
    P = np.stack([*np.meshgrid(x, x, indexing="ij"), np.zeros((2, 2))], axis=-1)
    k = np.array([0.0, 0.0, 1.0, 1.0])
    return Surface(P, k, k, 1, 1)


def _edge_distance(surface, points, n=4000):
    """Distance (mm) of points from the four border curves, sampled densely (brute force)."""
    (u0, u1), (v0, v1) = surface.u_range, surface.v_range
    t = np.linspace(0.0, 1.0, n)
    border = np.concatenate([
        bspline.evaluate(surface, u0 + (u1 - u0) * t, np.full(n, v0)),
        bspline.evaluate(surface, u0 + (u1 - u0) * t, np.full(n, v1)),
        bspline.evaluate(surface, np.full(n, u0), v0 + (v1 - v0) * t),
        bspline.evaluate(surface, np.full(n, u1), v0 + (v1 - v0) * t)])
    return np.array([np.min(np.linalg.norm(border - p, axis=1)) for p in points])


# ------------------------------------------------------------------ counts and margins
@pytest.mark.parametrize("layout,count", [("grid", (12, 9)), ("xy", (12, 9)),
                                          ("adaptive", 108)])
def test_example_face_counts_margin_and_tilt(layout, count):
    """On the example face every layout keeps its points clear of the border by tip radius
    plus edge margin (measured against the border curves sampled every 11 um), within the
    tilt limit, on the surface, with unit outward normals."""
    s = werner_surface()
    st = PlanSettings(tip_radius=1.5, edge_margin=0.7)
    plan = plan_points(FaceDomain(s, 1), layout, count, st)
    assert plan.requested == 108 and len(plan) + len(plan.dropped) == 108
    if layout == "xy":
        # the XY grid spans the extreme allowed samples; nodes of its border rows that the
        # face's slanted border brings within the margin are clipped, nothing else
        assert len(plan) >= 90 and {d.reason for d in plan.dropped} <= {"margin"}
    else:
        assert not plan.dropped
    assert _edge_distance(s, plan.points).min() >= 2.2 - 1e-4
    assert_allclose(bspline.evaluate(s, plan.u, plan.v), plan.points, atol=1e-12)
    assert_allclose(np.linalg.norm(plan.normals, axis=1), 1.0, atol=1e-12)
    assert_allclose(plan.normals, bspline.normals(s, plan.u, plan.v), atol=1e-12)
    assert np.degrees(np.arccos(plan.normals[:, 2])).max() <= 60.0
    assert plan.ids == ["P%d" % k for k in range(1, len(plan) + 1)]
    if layout == "xy":
        # the nodes lie on a 12 x 9 grid in XY: 12 distinct x, 9 distinct y
        assert len(np.unique(np.round(plan.points[:, 0], 9))) == 12
        assert len(np.unique(np.round(plan.points[:, 1], 9))) == 9


def test_grid_nodes_on_parameter_lines():
    s = werner_surface()
    plan = plan_points(FaceDomain(s, 1), "grid", (5, 4), PlanSettings())
    assert len(np.unique(np.round(plan.u, 12))) == 5
    assert len(np.unique(np.round(plan.v, 12))) == 4


def test_hole_and_trim_margin_measured():
    """A 40 x 40 mm plane trimmed to a 30 x 30 mm square with a 5 mm hole: every kept point
    lies at least 1.5 mm (tip 1 + edge 0.5) from the hole's circle and the square's sides;
    the nodes in the hole are 'outside', those near it 'margin'."""
    s = _plane()
    c, r = (0.5, 0.5), 5.0 / 40.0
    polys = _square_pieces(0.125, 0.875, 0.125, 0.875) + [_circle(c, r, 400, reverse=True)]
    dom = FaceDomain(s, 1, polys)
    plan = plan_points(dom, "grid", (40, 40), PlanSettings(tip_radius=1.0, edge_margin=0.5))
    xy = plan.points[:, :2]
    to_hole = np.linalg.norm(xy - 20.0, axis=1) - 5.0
    to_side = np.min(np.stack([xy[:, 0] - 5, 35 - xy[:, 0], xy[:, 1] - 5, 35 - xy[:, 1]]),
                     axis=0)
    # the hole is a 400-gon: its sides lie up to 5 (1 - cos(pi / 399)) = 0.15 um inside
    assert to_hole.min() >= 1.5 - 2e-4 and to_side.min() >= 1.5 - 1e-9
    counts = plan.drop_counts()
    assert counts["outside"] > 0 and counts["margin"] > 0
    for d in plan.dropped:
        p = np.array(d.point[:2])
        if d.reason == "outside":
            assert (np.linalg.norm(p - 20) < 5 + 1e-3 or p.min() < 5 + 1e-9
                    or p.max() > 35 - 1e-9)
        else:
            assert d.reason == "margin"
            assert min(np.linalg.norm(p - 20) - 5, p.min() - 5, 35 - p.max()) < 1.5
    assert len(plan) + len(plan.dropped) == 1600


def test_adaptive_points_avoid_hole():
    s = _plane()
    dom = FaceDomain(s, 1, _square_pieces(0, 1, 0, 1)
                     + [_circle((0.5, 0.5), 0.2, 400, reverse=True)])
    plan = plan_points(dom, "adaptive", 400, PlanSettings(tip_radius=1.0, edge_margin=1.0))
    assert len(plan) == 400 and not plan.dropped
    assert (np.linalg.norm(plan.points[:, :2] - 20, axis=1) - 8.0).min() >= 2.0 - 2e-3
    assert plan.points[:, :2].min() >= 2.0 - 1e-9 and plan.points[:, :2].max() <= 38 + 1e-9


# ------------------------------------------------------------------ tilt and reach
def _ramp(angle_deg, size=20.0):
    """A plane through the origin tilted by ``angle_deg`` about the y axis (normal leans
    ``angle_deg`` from +z)."""
    a = np.radians(angle_deg)
    x = np.array([0.0, size])
    X, Y = np.meshgrid(x, x, indexing="ij")
    P = np.stack([X * np.cos(a), Y, X * np.sin(a)], axis=-1)
    k = np.array([0.0, 0.0, 1.0, 1.0])
    return Surface(P, k, k, 1, 1)


def test_tilt_limit():
    ok = plan_points(FaceDomain(_ramp(50.0), 1), "grid", (4, 4), PlanSettings(max_tilt=50.5))
    assert len(ok) == 16
    assert_allclose(np.degrees(np.arccos(ok.normals[:, 2])), 50.0, atol=1e-9)
    with pytest.raises(InputError, match=r"no reachable point.*16 normal leans more than"):
        plan_points(FaceDomain(_ramp(50.0), 1), "grid", (4, 4), PlanSettings(max_tilt=49.5))


def _hook(gap):
    """A profile bent back over itself, extruded 20 mm along y: floor z = 0 from x = 0 to 30,
    a wall up to z = gap, a ceiling back to x = 10 facing down (degree 1 along u)."""
    prof = np.array([[0.0, 0.0], [30.0, 0.0], [30.0, gap], [10.0, gap]])
    y = np.array([0.0, 20.0])
    P = np.zeros((4, 2, 3))
    P[:, :, 0] = prof[:, None, 0]
    P[:, :, 1] = y[None, :]
    P[:, :, 2] = prof[:, None, 1]
    ku = np.array([0.0, 0.0, 30.0, 30 + gap, 50 + gap, 50 + gap]) / (50 + gap)
    return Surface(P, ku, np.array([0.0, 0.0, 1.0, 1.0]), 1, 1)


@pytest.mark.parametrize("gap,reason,keep_to", [
    (2.5, "approach", 10.0 - np.sqrt(6.0 ** 2 - 3.5 ** 2)),
    (12.0, "descent", 4.0),
])
def test_face_hiding_itself(gap, reason, keep_to):
    """Floor points under the ceiling are dropped: with a 2.5 mm gap the ball (r 1 mm,
    stand-off 2 mm) meets the ceiling on the approach, with 12 mm on the way down; the wall
    and the ceiling lean too far. The rapid descent keeps the ball the clearance (5 mm) from
    the ceiling's edge (x = 10, z = gap): its centre 6 mm away. It runs from the safe height
    (gap + 6) down to the retract point 6 mm above the floor, so floor points up to
    x = 10 - 6 = 4 are kept under a 12 mm gap and up to x = 10 - sqrt(6^2 - 3.5^2) under a
    2.5 mm one (the retract point 3.5 mm above the edge); floor points beyond, up to the
    ball radius from the edge, are dropped as descent (the ball would pass within 5 mm)."""
    st = PlanSettings(tip_radius=1.0, edge_margin=0.5, stand_off=2.0)
    assert st.clearance == 5.0
    plan = plan_points(FaceDomain(_hook(gap), 1), "grid", (106, 5), st)
    assert np.all(plan.points[:, 2] == 0.0)
    xs = np.unique(np.round(plan.points[:, 0], 9))
    # the last kept column is the last one within keep_to (columns about 0.5 mm apart)
    assert keep_to - 0.6 < xs.max() <= keep_to + 1e-3
    assert xs.min() <= 1.5 + 0.6
    x = np.array([d.point[0] for d in plan.dropped])
    z = np.array([d.point[2] for d in plan.dropped])
    why = np.array([d.reason for d in plan.dropped])
    under = (z == 0.0) & (x > 10.0) & (x < 28.5)
    assert under.sum() >= 5 * 30 and np.all(why[under] == reason)
    near = (z == 0.0) & (x > keep_to) & (x < 9.0)     # 1 mm from the edge: approach
    assert near.sum() >= 5 * 6 and np.all(why[near] == "descent")
    assert np.all(why[z > 0] == "tilt")
    assert len(plan) == 5 * len(xs)


# ------------------------------------------------------------------ concave radius
def _trough(L=40.0, h=10.0):
    """Quadratic Bezier trough along x, z = h (1 - 2t + 2t^2): radius L^2 / (4h) = 40 mm at
    its bottom, concave seen from above."""
    x = np.array([0.0, L / 2, L])
    y = np.array([0.0, 20.0])
    X, Y = np.meshgrid(x, y, indexing="ij")
    Z = np.array([[h, h], [0.0, 0.0], [h, h]])
    ku = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    return Surface(np.stack([X, Y, Z], axis=-1), ku, np.array([0.0, 0.0, 1.0, 1.0]), 2, 1)


def test_tip_larger_than_concave_radius_refused():
    dom = FaceDomain(_trough(), 1)
    plan = plan_points(dom, "grid", (5, 3), PlanSettings(tip_radius=3.0, max_tilt=80))
    assert plan.min_concave_radius == pytest.approx(40.0, rel=1e-4)
    with pytest.raises(InputError, match=r"^tip_radius 40.5 mm is larger than the face's "
                                         r"smallest concave radius 40 mm"):
        plan_points(dom, "grid", (5, 3), PlanSettings(tip_radius=40.5, max_tilt=80))
    # seen from below the trough is convex: any ball fits
    k1, k2 = FaceDomain(_trough(), -1).curvatures([0.5], [0.5])
    assert (k1[0], k2[0]) == (0.0, pytest.approx(1 / 40.0, rel=1e-9))
    assert FaceDomain(_trough(), 1).curvatures([0.5], [0.5])[0][0] == pytest.approx(
        -1 / 40.0, rel=1e-9)


# ------------------------------------------------------------------ counts
@pytest.mark.parametrize("text", ["0x5", "5x0", "abc", "3", "1001x1000"])
def test_bad_grid_counts(text):
    with pytest.raises(InputError, match=r"^count ") as err:
        parse_count(text)
    assert err.value.shown(flag).startswith("--count %r: " % text)


@pytest.mark.parametrize("n", [0, -1, MAX_POINTS + 1, 2.5])
def test_bad_point_counts(n):
    with pytest.raises(InputError, match=r"^points ") as err:
        check_points(n)
    assert err.value.shown(flag).startswith("--points %r: expected" % n)


def test_bad_settings():
    for kw, text in ((dict(tip_radius=0.0), "--tip-radius"), (dict(max_tilt=91), "--max-tilt"),
                     (dict(edge_margin=-1), "--edge-margin"),
                     (dict(clearance=float("nan")), "--clearance"),
                     # 0 as the probing program refuses it (a plan written without one took
                     # it before: the touch starting at the face, the safe height on the top)
                     (dict(stand_off=0.0), "--stand-off 0.0: expected a finite length above"),
                     (dict(clearance=0.0), "--clearance 0.0: expected a finite length above")):
        with pytest.raises(InputError, match="^%s " % list(kw)[0]) as err:
            PlanSettings(**kw).check()
        assert err.value.shown(flag).startswith(text + " ")
    assert PlanSettings(edge_margin=0.0).check().edge_margin == 0.0


# ------------------------------------------------------------------ order and travel
def test_serpentine_and_travel():
    rows = np.array([0, 0, 0, 1, 1, 1])
    along = np.array([2.0, 0.0, 1.0, 0.0, 2.0, 1.0])
    assert serpentine(rows, along).tolist() == [1, 2, 0, 4, 5, 3]
    pts = np.array([[0, 0, 0], [3, 4, 0], [3, 4, 12.0]])
    assert travel_length(pts) == pytest.approx(17.0, abs=1e-12)
    line = np.array([[x, 0.0, 0.0] for x in (5, 1, 4, 2, 3, 0)])
    assert nearest_neighbour(line, start=5).tolist() == [5, 1, 3, 4, 2, 0]


def test_plan_travel_is_the_path_through_its_standoffs():
    s = werner_surface()
    for layout, count in (("grid", (20, 20)), ("adaptive", 300)):
        plan = plan_points(FaceDomain(s, 1), layout, count, PlanSettings())
        assert plan.travel == pytest.approx(travel_length(plan.standoff_points()), rel=1e-12)
        # no longer than the serpentine order through the same points, and short: every
        # step of the 20 x 20 grid is about a grid step (45 mm / 19)
        if layout == "grid":
            assert plan.travel < 1.15 * 399 * (45.0 - 3.2) / 19


# ------------------------------------------------------------------ adaptive density
def test_adaptive_density_follows_the_rule():
    """Mirror paper Surface one: every u-curve the same parabola, so the turning rate
    depends on u only and the rows are evenly spaced; the points per mm along each row
    follow rho = kappa_mean + kappa (equidistribution: equal integrals of rho between
    neighbours), so the arc between neighbours times rho at its middle is constant."""
    s = mirror_surface("s1")
    dom = FaceDomain(s, 1)
    plan = plan_points(dom, "adaptive", 700, PlanSettings())
    assert len(plan) == 700
    kmean = plan.info["kappa_mean"]
    rows = np.unique(np.round(plan.v, 12))
    assert len(rows) == plan.info["rows"]
    sel = np.round(plan.v, 12) == rows[len(rows) // 2]
    u = np.sort(plan.u[sel])
    P = bspline.evaluate(s, u, np.full(u.shape, rows[len(rows) // 2]))
    arc = np.linalg.norm(np.diff(P, axis=0), axis=1)
    mid = 0.5 * (u[1:] + u[:-1])
    rho = kmean + turning_rate(dom, mid, np.full(mid.shape, rows[len(rows) // 2]))
    q = arc * rho
    assert np.ptp(q) / q.mean() < 0.05
    # the densest spacing is where the normal turns fastest, and there is a real contrast
    assert arc.max() / arc.min() > 1.08
    assert mid[np.argmin(arc)] == pytest.approx(mid[np.argmax(rho)], abs=0.1)


def test_adaptive_on_a_plane_is_uniform():
    plan = plan_points(FaceDomain(_plane(), 1), "adaptive", 400, PlanSettings())
    assert len(plan) == 400
    x = np.sort(np.unique(np.round(plan.points[:, 0], 9)))
    y = np.sort(np.unique(np.round(plan.points[:, 1], 9)))
    assert len(x) == 20 and len(y) == 20
    assert np.ptp(np.diff(x)) < 1e-6 and np.ptp(np.diff(y)) < 1e-6


# ------------------------------------------------------------------ the virtual loop
def test_simulate_at_plan_points_and_the_layout_comparison():
    """The loop measured at a plan's points: the 'grid' statistics are those at the points,
    'all' the evaluation grid's; the uniform and adaptive runs share the evaluation grid's
    random draws, so the parts machined from the nominal are the same to the last bit, and
    the comparison's figures are the runs' own."""
    from surfcomp.core.simulation import presets
    from surfcomp.core.simulation import simulate as sim
    from surfcomp.core.simulation.sim_layouts import compare_layouts

    pr = presets.get_preset("mirror2019-s2")
    surf, outward = pr.surface()
    model = sim.MachiningModel(**pr.model)
    specs = sim.method_specs(["none", "filtered", "mirror"])
    cmp = compare_layouts(FaceDomain(surf, outward), model, 49, grid=(10, 8), specs=specs,
                          replicas=2, seed=3, between=2)
    uni, ada = cmp.results["uniform"], cmp.results["adaptive"]
    assert len(cmp.plans["uniform"]) == len(cmp.plans["adaptive"]) == 49
    for res in (uni, ada):
        assert res.before[0]["grid"].count == 49 and res.before[0]["all"].count == 19 * 15
    assert_allclose(uni.values("before", "std"), ada.values("before", "std"), rtol=0, atol=0)
    rows = {r[0]: r for r in cmp.rows()}
    assert set(rows) == {"filtered", "mirror"}
    assert rows["mirror"][1] == pytest.approx(uni.values("mirror", "std").mean(), abs=1e-15)
    assert rows["mirror"][3] == pytest.approx(ada.values("mirror", "std").mean(), abs=1e-15)
    # both compensate: the residual is well below the uncompensated part's
    for label in ("filtered", "mirror"):
        assert rows[label][1] < 0.7 * uni.values("none", "std").mean()
        assert rows[label][3] < 0.7 * ada.values("none", "std").mean()
    assert cmp.verdict() in ("reproduced", "not supported")
    assert "The mirror paper's claim" in cmp.table()
    with pytest.raises(InputError, match="maps of a simulation need the grid"):
        sim.simulate(surf, outward, model, grid=(10, 8), specs=specs, replicas=1,
                     points=cmp.plans["uniform"].points, keep=True)
