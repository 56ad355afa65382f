# SPDX-License-Identifier: LGPL-2.1-or-later
"""Measurement planning: where to probe the nominal face, and in which order (no FreeCAD).

Layouts (``layout``):

``grid`` (``count`` = U x V)
    U x V points along the face's parameter lines, over its parameter box drawn in from
    each side by the margin (converted to parameters on that side).
``xy`` (``count`` = U x V)
    A U x V grid in the machine's XY plane over the XY extent of the part of the face the
    margin allows, clipped to the face: each node is the face point straight below or
    above it (the vertical line's intersection, by Newton's method from the nearest face
    sample); nodes with no face under them are clipped.
``adaptive`` (``points`` = N)
    N points, denser where the slope changes fast (mirror paper 2019, section 2.3):
    :mod:`surfcomp.core.measurement.planning_adaptive`.
``uniform`` (``points`` = N)
    N points spread evenly: the adaptive layout's rows with a constant density (its twin
    for comparisons at equal point counts).

Every point then passes the same checks, and a point that fails one is dropped with its
reason (:class:`Drop`):

* ``outside``: not on the trimmed face;
* ``margin``: closer than ``tip_radius + edge_margin`` (mm, in space) to the trim
  boundary or a hole;
* ``tilt``: its outward normal leans more than ``max_tilt`` from the spindle axis +Z;
* ``approach``: the stylus ball would meet the face on the feed moves along the normal
  from the retract point to the touch;
* ``descent``: the ball would come closer than ``clearance`` to the face on the rapid
  descent from the safe height to the retract point (and the rapid climb back): the rapid
  moves keep the clearance (:mod:`surfcomp.core.measurement.planning_reach`); the rest of
  a solid is checked by the app layer, passed in as ``extra_check``.

A stylus ball larger than the face's smallest concave radius cannot touch the face where it
is most concave: such a plan is refused. The kept points are visited in the order that keeps
the travel between retract positions short (serpentine rows or nearest neighbour,
:func:`surfcomp.core.measurement.planning_reach.visiting_order`), and numbered ``P1``, ``P2``, ...
in that order.
"""

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from ...errors import InputError, note
from ..choices import PLAN_LAYOUTS as LAYOUTS
from ..choices import PLAN_ORDERS as ORDERS
from ..choices import POINT_LAYOUTS  # noqa: F401
from ..limits import MAX_PLAN_POINTS
from ..option_tables import PLAN
from ..progress import report
from ..surface import bspline
from .planning_adaptive import adaptive_layout
from .planning_reach import (
    approach_paths,
    blocked_by_cloud,
    tilt_degrees,
    visiting_order,
)

#: most points a plan may have
MAX_POINTS = MAX_PLAN_POINTS
#: face samples for the curvature check, the self-occlusion check and the xy seeds
FACE_SAMPLES = 40000
#: the reasons a point is dropped, in the order they are checked, and what they say
REASONS = {
    "outside": "not on the trimmed face",
    "margin": "closer than the margin to the boundary or a hole",
    "tilt": note("normal leans more than ", ("max_tilt",), " from +Z"),
    "approach": "the stylus meets the face on the approach along the normal",
    "descent": note("the rapid descent from the safe height comes closer than ",
                    ("clearance",), " to the face"),
}


@dataclass(frozen=True)
class PlanSettings:
    """The probe and its clearances (mm, degrees)."""

    tip_radius: float = PLAN["tip_radius"].default
    edge_margin: float = PLAN["edge_margin"].default
    max_tilt: float = PLAN["max_tilt"].default
    stand_off: float = PLAN["stand_off"].default
    clearance: float = PLAN["clearance"].default

    @property
    def retract(self):
        """Distance (mm) along the normal, from the ball centre at contact, where the rapid
        descent ends and the move along the normal starts: the larger of the stand-off and
        the clearance, as the probing program moves (:mod:`surfcomp.io.probe_path`)."""
        return max(self.stand_off, self.clearance)

    @property
    def margin(self):
        """Least distance (mm) of a point from the boundary: tip radius plus edge margin."""
        return self.tip_radius + self.edge_margin

    def check(self):
        """Refuse values out of range, naming the option."""
        # the probe starts its touch off the face and moves at a safe height above the part:
        # stand-off and clearance above 0, as the probing program needs them
        for name in ("tip_radius", "edge_margin", "stand_off", "clearance"):
            val = getattr(self, name)
            above = name != "edge_margin"
            if not (np.isfinite(val) and (val > 0 if above else val >= 0)):
                raise InputError("%s %r: expected a finite length %s 0 mm"
                                 % (name, val, "above" if above else ">="), options=(name,))
        if not (np.isfinite(self.max_tilt) and 0 <= self.max_tilt <= 90):
            raise InputError("max_tilt %r: expected an angle from 0 to 90 degrees"
                             % (self.max_tilt,), options=("max_tilt",))
        return self


@dataclass
class Drop:
    """A layout point left out: ``index`` in the layout, its ``reason`` key (``REASONS``)
    and where it is (``u``, ``v``, ``point`` (3,) in mm)."""

    index: int
    reason: str
    u: float
    v: float
    point: tuple


@dataclass
class Plan:
    """Measurement points in visiting order.

    Attributes
    ----------
    ids : list of str
        ``P1`` .. ``PN`` in visiting order.
    u, v : ndarray (N,)
        Face parameters.
    points, normals : ndarray (N, 3)
        Nominal surface points (mm) and outward unit normals.
    layout : str
    requested : int
        Points the layout placed before the checks.
    dropped : list of Drop
    order : str
        ``serpentine`` or ``nearest``.
    travel : float
        Length (mm) of the path through the retract positions in visiting order.
    top_z, safe_z : float
        The part's top (mm) and the ball centre's safe height above it (``top_z + tip_radius +
        clearance``: the ball ``clearance`` above the top, as the probing program moves).
    min_concave_radius : float
        Smallest concave radius (mm) of the face (inf: nowhere concave).
    """

    ids: list
    u: np.ndarray
    v: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    layout: str
    requested: int
    settings: PlanSettings
    dropped: list = field(default_factory=list)
    order: str = "serpentine"
    travel: float = 0.0
    top_z: float = 0.0
    safe_z: float = 0.0
    min_concave_radius: float = np.inf
    info: dict = field(default_factory=dict)

    def __len__(self):
        return len(self.ids)

    def standoff_points(self):
        """Stylus ball centres at the retract positions (N, 3), mm: where the probing
        program's rapid descent ends (:attr:`PlanSettings.retract` out along the normal)."""
        s = self.settings
        return self.points + (s.tip_radius + s.retract) * self.normals

    def drop_counts(self):
        """``{reason: count}`` in the order of ``REASONS`` (reasons with drops only)."""
        out = {}
        for d in self.dropped:
            out[d.reason] = out.get(d.reason, 0) + 1
        keys = list(REASONS) + sorted(set(out) - set(REASONS))
        return {k: out[k] for k in keys if k in out}


def parse_count(text, option="count"):
    """``'12x8'`` -> (12, 8): whole numbers >= 1 whose product is at most ``MAX_POINTS``."""
    parts = str(text).lower().replace("*", "x").split("x")
    try:
        n, m = (int(t) for t in parts)
    except ValueError:
        raise InputError("%s %r: expected UxV, e.g. 12x8" % (option, text),
                         options=(option,)) from None
    if n < 1 or m < 1:
        raise InputError("%s %r: expected at least 1 point in each direction" % (option, text),
                         options=(option,))
    if n * m > MAX_POINTS:
        raise InputError("%s %r: %d points, expected at most %d"
                         % (option, text, n * m, MAX_POINTS), options=(option,))
    return n, m


def check_points(count, option="points"):
    """A point count: a whole number from 1 to ``MAX_POINTS``."""
    if int(count) != count or not 1 <= count <= MAX_POINTS:
        raise InputError("%s %r: expected a whole number from 1 to %d"
                         % (option, count, MAX_POINTS), options=(option,))
    return int(count)


# ---------------------------------------------------------------------- face facts
def _face_cloud(domain):
    """``(us, vs, points (M, 3), inside (M,))`` of the face's sample grid."""
    us, vs = domain.samples(FACE_SAMPLES)
    U, V = np.meshgrid(us, vs, indexing="ij")
    D = bspline.evaluate_grid(domain.surface, us, vs, order=2)
    ins = domain.inside(U.ravel(), V.ravel())
    flat = tuple(d.reshape(-1, 3) for d in D)
    return U.ravel(), V.ravel(), flat, ins


def min_concave_radius(domain, flat, ins):
    """``(radius, point)``: the face's smallest concave radius (mm) over its samples and
    where it is; ``(inf, None)`` where the face is nowhere concave."""
    from .planning_face import curvatures_from

    k1, _ = curvatures_from(tuple(f[ins] for f in flat), domain.outward)
    if not k1.size or k1.min() >= 0:
        return np.inf, None
    k = int(np.argmin(k1))
    return float(-1.0 / k1[k]), tuple(float(x) for x in flat[0][ins][k])


# ---------------------------------------------------------------------- layouts
def _grid_layout(domain, count, margin):
    """U x V nodes along the parameter lines over the box drawn in by ``margin``: each side
    drawn in by the margin over the rate at which distance grows across it, then further
    while a node of its outer row is nearer than the margin to the box's border curves."""
    from .planning_face import FaceDomain

    (u0, u1), (v0, v1) = domain.surface.u_range, domain.surface.v_range
    t = np.linspace(0.0, 1.0, 65)

    def rate(along_u, at):
        uu = np.full(t.shape, at) if along_u else u0 + (u1 - u0) * t
        vv = v0 + (v1 - v0) * t if along_u else np.full(t.shape, at)
        _, Su, Sv = bspline.derivatives(domain.surface, uu, vv, 1)
        d, o = (Su, Sv) if along_u else (Sv, Su)
        # distance across the side per unit parameter: |d| sin(angle between d and o)
        return max(float((np.linalg.norm(np.cross(d, o), axis=1) / np.maximum(
            np.linalg.norm(o, axis=1), 1e-300)).min()), 1e-300)

    rates = [rate(True, u0), rate(True, u1), rate(False, v0), rate(False, v1)]
    inset = [1.02 * margin / r for r in rates]
    border = FaceDomain(domain.surface, domain.outward)
    nu, nv = count
    for _ in range(8):
        us = _spread(u0 + inset[0], u1 - inset[1], nu)
        vs = _spread(v0 + inset[2], v1 - inset[3], nv)
        sides = [(us[:1], vs), (us[-1:], vs), (us, vs[:1]), (us, vs[-1:])]
        short = []
        for a, b in sides:
            A, B = np.meshgrid(a, b, indexing="ij")
            S = bspline.evaluate(domain.surface, A.ravel(), B.ravel())
            # a hair beyond the margin, so the checks' rounding keeps the nodes
            want = margin * (1 + 1e-6) + 1e-9
            short.append(want - float(border.boundary_distance(S, want).min()))
        if max(short) <= 0:
            break
        inset = [i + 1.05 * s / r if s > 0 else i for i, s, r in zip(inset, short, rates)]
    U, V = np.meshgrid(us, vs, indexing="ij")
    rows = np.broadcast_to(np.arange(nv), U.shape)
    return dict(u=U.ravel(), v=V.ravel(), row=rows.ravel(), along=U.ravel())


def _spread(lo, hi, n):
    """``n`` values from ``lo`` to ``hi`` (one: the middle; an empty range: all in its
    middle, so the margin check drops them)."""
    if n == 1 or lo >= hi:
        return np.full(n, 0.5 * (lo + hi))
    return np.linspace(lo, hi, n)


def _xy_layout(domain, count, cloud, allowed_cloud):
    """U x V nodes of a grid in XY over the allowed samples' XY extent, on the face."""
    U, V, flat, ins = cloud
    S = flat[0]
    xy_ok = S[allowed_cloud, :2]
    if not len(xy_ok):
        return dict(u=np.zeros(0), v=np.zeros(0), row=np.zeros(0, int), along=np.zeros(0),
                    clipped=np.zeros(0, int), nodes=0)
    lo, hi = xy_ok.min(axis=0), xy_ok.max(axis=0)
    nx, ny = count
    xs = _spread(lo[0], hi[0], nx)
    ys = _spread(lo[1], hi[1], ny)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    target = np.stack([X.ravel(), Y.ravel()], axis=1)
    on = np.flatnonzero(ins)
    tree = cKDTree(S[on, :2])
    spacing = 2.0 * _cloud_spacing(S[on, :2])
    # the seed: the highest of the nearest samples (the probe comes from above)
    near, ks = tree.query(target, k=min(16, len(on)))
    near, ks = near.reshape(len(target), -1), ks.reshape(len(target), -1)
    z = np.where(near <= spacing, S[on, 2][np.minimum(ks, len(on) - 1)], -np.inf)
    k = ks[np.arange(len(target)), np.argmax(z, axis=1)]
    dist = near[:, 0]
    u, v = U[on][k].copy(), V[on][k].copy()
    u, v, conv = _newton_xy(domain.surface, u, v, target)
    hit = conv & (dist <= spacing) & domain.inside(u, v)
    rows = np.broadcast_to(np.arange(ny), X.shape).ravel()
    return dict(u=u[hit], v=v[hit], row=rows[hit], along=target[hit, 0],
                clipped=np.flatnonzero(~hit), nodes=len(target))


def _cloud_spacing(xy):
    """Typical distance (mm) between neighbouring samples ``xy`` (M, 2)."""
    if len(xy) < 2:
        return 0.0
    d, _ = cKDTree(xy).query(xy[:: max(1, len(xy) // 2000)], k=2)
    return float(np.max(d[:, 1]))


def _newton_xy(surface, u, v, target, steps=12):
    """Parameters whose surface point lies at ``target`` (N, 2) in XY: ``(u, v, converged)``."""
    (u0, u1), (v0, v1) = surface.u_range, surface.v_range
    for _ in range(steps):
        S, Su, Sv = bspline.derivatives(surface, u, v, 1)
        r = target - S[:, :2]
        a, b, c, d = Su[:, 0], Sv[:, 0], Su[:, 1], Sv[:, 1]
        det = a * d - b * c
        with np.errstate(divide="ignore", invalid="ignore"):
            du = np.where(det != 0, (d * r[:, 0] - b * r[:, 1]) / det, 0.0)
            dv = np.where(det != 0, (a * r[:, 1] - c * r[:, 0]) / det, 0.0)
        u = np.clip(u + du, u0, u1)
        v = np.clip(v + dv, v0, v1)
    S = bspline.evaluate(surface, u, v)
    return u, v, np.linalg.norm(S[:, :2] - target, axis=1) < 1e-6


# ---------------------------------------------------------------------- the plan
def _allowed(domain, settings):
    """``allowed(u, v, S, Su, Sv)``: on the face, clear by the margin, tilt within limits."""
    cos_tilt = np.cos(np.radians(settings.max_tilt))

    def allowed(u, v, S, Su, Sv):
        n = np.cross(Su, Sv) * domain.outward
        nz = n[:, 2] / np.maximum(np.linalg.norm(n, axis=1), 1e-300)
        ok = domain.inside(u, v) & (nz >= cos_tilt - 1e-12)
        if np.any(ok):
            ok[ok] = domain.boundary_distance(S[ok], settings.margin) >= settings.margin
        return ok

    return allowed


def _screen(domain, u, v, settings, safe_z, cloud):
    """Check every layout point: ``(keep (N,) bool, reason per point (N,) or '')``."""
    reason = np.full(len(u), "", dtype=object)
    todo = np.ones(len(u), dtype=bool)

    def fail(mask, key):
        reason[todo & mask] = key
        todo[:] &= ~mask

    fail(~domain.inside(u, v), "outside")
    S, n = domain.frame(u, v)
    dist = np.full(len(u), np.inf)
    dist[todo] = domain.boundary_distance(S[todo], settings.margin)
    fail(dist < settings.margin, "margin")
    fail(tilt_degrees(n) > settings.max_tilt + 1e-9, "tilt")
    touch, standoff, top = approach_paths(S, n, settings.tip_radius, settings.retract,
                                          safe_z)
    cl = cloud[2][0][cloud[3]]
    tree = cKDTree(cl)
    idx = np.flatnonzero(todo)
    blocked = np.zeros(len(u), dtype=bool)
    blocked[idx] = blocked_by_cloud(standoff[idx], touch[idx], cl, settings.tip_radius, tree)
    fail(blocked, "approach")
    idx = np.flatnonzero(todo)
    blocked[:] = False
    # the rapid moves keep the ball the clearance away: its centre R + clearance
    blocked[idx] = blocked_by_cloud(top[idx], standoff[idx], cl,
                                    settings.tip_radius + settings.clearance, tree)
    fail(blocked, "descent")
    return todo, reason, S, n, touch, standoff, top


def plan_points(domain, layout, count=None, settings=None, top_z=None, order="auto",
                extra_check=None, progress=None):
    """Place, check and order measurement points on a face (module docstring).

    Parameters
    ----------
    domain : FaceDomain
    layout : {'grid', 'xy', 'adaptive', 'uniform'}
    count : (int, int) or int
        ``(U, V)`` for ``grid`` and ``xy``; the number of points for ``adaptive`` and
        ``uniform``.
    settings : PlanSettings
    top_z : float, optional
        The part's top (mm); default the face's highest sample.
    order : {'auto', 'serpentine', 'nearest'}
    extra_check : callable, optional
        ``extra_check(points, normals, touch, standoff, top) -> list of (key, bool (N,))``:
        further reasons to drop points (the app's check against the solid), applied in order.

    Returns
    -------
    Plan

    Raises
    ------
    InputError
        Bad counts or settings, a tip radius larger than the smallest concave radius, or no
        point left.
    """
    settings = (settings or PlanSettings()).check()
    if layout not in LAYOUTS:
        raise InputError("layout %r: expected one of %s" % (layout, ", ".join(LAYOUTS)),
                         options=("layout",))
    if order not in ORDERS:
        raise InputError("order %r: expected one of %s" % (order, ", ".join(ORDERS)),
                         options=("order",))
    report(progress, 0.0, "sampling the face")
    cloud = _face_cloud(domain)
    radius, where = min_concave_radius(domain, cloud[2], cloud[3])
    if settings.tip_radius > radius:
        raise InputError("tip_radius %g mm is larger than the face's smallest concave radius "
                         "%.4g mm (at %.3f, %.3f, %.3f): the stylus ball cannot touch the face "
                         "there (expected a tip radius of at most %.4g mm)"
                         % ((settings.tip_radius, radius) + where + (radius,)),
                         options=("tip_radius",))
    if top_z is None:
        top_z = float(cloud[2][0][cloud[3], 2].max()) if cloud[3].any() else 0.0
    safe_z = float(top_z) + settings.tip_radius + settings.clearance
    allowed = _allowed(domain, settings)
    report(progress, 0.2, "placing the %s layout" % layout)
    info = {}
    if layout == "grid":
        lay = _grid_layout(domain, parse_count("%sx%s" % tuple(count)), settings.margin)
    elif layout == "xy":
        ok = np.zeros(len(cloud[0]), dtype=bool)
        ok[cloud[3]] = allowed(cloud[0][cloud[3]], cloud[1][cloud[3]],
                               *(f[cloud[3]] for f in cloud[2][:3]))
        lay = _xy_layout(domain, parse_count("%sx%s" % tuple(count)), cloud, ok)
        info["clipped"] = int(len(lay["clipped"]))
    else:
        lay = adaptive_layout(domain, check_points(count), allowed,
                              uniform=layout == "uniform")
        info.update(kappa_mean=lay["kappa_mean"], rows=lay["rows"])
    requested = lay.get("nodes", len(lay["u"]))
    report(progress, 0.5, "checking %d points" % len(lay["u"]))
    keep, reason, S, n, touch, standoff, top = _screen(domain, lay["u"], lay["v"], settings,
                                                       safe_z, cloud)
    if extra_check is not None and keep.any():
        idx = np.flatnonzero(keep)
        for key, bad in extra_check(S[idx], n[idx], touch[idx], standoff[idx], top[idx]):
            hit = idx[np.asarray(bad, dtype=bool)]
            hit = hit[keep[hit]]
            reason[hit] = key
            keep[hit] = False
    dropped = [Drop(int(i), str(reason[i]), float(lay["u"][i]), float(lay["v"][i]),
                    tuple(float(x) for x in S[i])) for i in np.flatnonzero(~keep)]
    if not keep.any():
        raise InputError(_nothing_left(layout, requested, dropped, info),
                         options=("max_tilt", "edge_margin", "tip_radius", "clearance"))
    report(progress, 0.8, "ordering %d points" % int(keep.sum()))
    idx = np.flatnonzero(keep)
    tour, name, travel = visiting_order(standoff[idx], lay["row"][idx], lay["along"][idx],
                                        order)
    idx = idx[tour]
    report(progress, 1.0, "done")
    return Plan(ids=["P%d" % (k + 1) for k in range(len(idx))], u=lay["u"][idx],
                v=lay["v"][idx], points=S[idx], normals=n[idx], layout=layout,
                requested=int(requested), settings=settings, dropped=dropped, order=name,
                travel=travel, top_z=float(top_z), safe_z=safe_z,
                min_concave_radius=radius, info=info)


def _nothing_left(layout, requested, dropped, info):
    counts = {}
    for d in dropped:
        counts[d.reason] = counts.get(d.reason, 0) + 1
    why = "; ".join("%d %s" % (c, REASONS.get(k, k)) for k, c in counts.items())
    clipped = info.get("clipped", 0)
    if clipped:
        why = ("%d nodes have no face under them; " % clipped) + why
    return ("no reachable point on the face: the %s layout placed %d point(s) and every one "
            "was dropped (%s); expected at least one point that a 3-axis probe reaches "
            "(a larger max_tilt, a smaller edge_margin, tip_radius or clearance, or another "
            "face)"
            % (layout, requested, why or "none placed"))
