# SPDX-License-Identifier: LGPL-2.1-or-later
"""The nominal face as the measurement planner sees it (no FreeCAD).

:class:`FaceDomain` holds a face's surface, its outward side and its trim boundary
(outer wire and holes as polylines in (u, v), as :func:`surfcomp.app.nominal.boundary_polylines`
gives them; None: the face is its whole parameter box), and answers what the planner asks
of every candidate point: is it on the trimmed face, how far (mm, in space) is it from the
boundary, what are its point, outward normal and principal curvatures.
"""

import numpy as np
from scipy.spatial import cKDTree

from ..surface import bspline
from ..surface.trimmed import inside

#: boundary points per side of an untrimmed face's parameter box
BOX_POINTS = 400
#: nearest boundary segments whose exact distance is computed per point
_NEAREST = 12


def box_polylines(surface, points=BOX_POINTS):
    """The parameter box ``u_range x v_range`` as four polylines in (u, v), counter-clockwise."""
    (u0, u1), (v0, v1) = surface.u_range, surface.v_range
    t = np.linspace(0.0, 1.0, points)
    corners = [(u0, v0), (u1, v0), (u1, v1), (u0, v1), (u0, v0)]
    out = []
    for (a, b), (c, d) in zip(corners[:-1], corners[1:]):
        out.append(np.stack([a + (c - a) * t, b + (d - b) * t], axis=1))
    return out


class FaceDomain:
    """A trimmed face for planning.

    Parameters
    ----------
    surface : bspline.Surface
        The face's surface; ``u_range x v_range`` holds the trimmed face.
    outward : {1, -1}
        +1 when the outward normal is ``Su x Sv``.
    polylines : list of (n, 2) arrays, optional
        The trim boundary in (u, v) (outer wire and holes); None: the parameter box.
    """

    def __init__(self, surface, outward=1, polylines=None):
        self.surface = surface
        self.outward = 1 if outward >= 0 else -1
        self.trimmed = polylines is not None
        self.polylines = [np.asarray(p, dtype=float) for p in
                          (polylines if polylines is not None else box_polylines(surface))]
        pts3 = [bspline.evaluate(surface, p[:, 0], p[:, 1]) for p in self.polylines]
        a = np.concatenate([p[:-1] for p in pts3])
        b = np.concatenate([p[1:] for p in pts3])
        self._seg_a, self._seg_d = a, b - a
        self._half = 0.5 * float(np.max(np.linalg.norm(b - a, axis=1))) if len(a) else 0.0
        self._tree = cKDTree(0.5 * (a + b))

    # ---------------------------------------------------------------- where points are
    def inside(self, u, v):
        """Bool array: ``(u, v)`` on the trimmed face (in the box, and inside the boundary)."""
        u = np.asarray(u, dtype=float)
        v = np.asarray(v, dtype=float)
        (u0, u1), (v0, v1) = self.surface.u_range, self.surface.v_range
        box = (u >= u0) & (u <= u1) & (v >= v0) & (v <= v1)
        if not self.trimmed:
            return box
        out = np.zeros(u.shape, dtype=bool)
        if np.any(box):
            out[box] = inside(self.polylines, u[box], v[box])
        return out

    def boundary_distance(self, points, upto=np.inf):
        """Distance (mm, in space) of points (N, 3) from the face's boundary polylines
        (outer wire and holes, evaluated on the surface): exact to the polylines' segments
        where it is below ``upto``; above it, a value that is above ``upto`` too."""
        P = np.asarray(points, dtype=float).reshape(-1, 3)
        if not len(P):
            return np.zeros(0)
        k = min(_NEAREST, len(self._seg_a))
        dmid, idx = self._tree.query(P, k=k)
        dmid = dmid.reshape(len(P), k)
        idx = idx.reshape(len(P), k)
        best = _segment_distance(P[:, None, :], self._seg_a[idx], self._seg_d[idx]).min(axis=1)
        # a segment nearer than ``best`` has its midpoint within best + half a segment; the
        # true distance is at least the nearest midpoint's distance less half a segment
        unsure = np.flatnonzero((dmid[:, -1] < best + self._half)
                                & (dmid[:, 0] - self._half < upto))
        if unsure.size:
            lists = self._tree.query_ball_point(P[unsure], best[unsure] + self._half,
                                                return_sorted=False)
            counts = np.fromiter((len(x) for x in lists), dtype=np.int64, count=len(lists))
            owner = np.repeat(unsure, counts)
            cand = np.concatenate([np.asarray(x, dtype=np.int64) for x in lists])
            d = _segment_distance(P[owner], self._seg_a[cand], self._seg_d[cand])
            np.minimum.at(best, owner, d)
        return best

    # ---------------------------------------------------------------- geometry
    def frame(self, u, v):
        """Points (N, 3) and outward unit normals (N, 3) at ``(u, v)`` (N,)."""
        u = np.asarray(u, dtype=float).ravel()
        v = np.asarray(v, dtype=float).ravel()
        S, Su, Sv = bspline.derivatives(self.surface, u, v, 1)
        n = bspline.unit_normals(self.surface, u, v, Su, Sv) * self.outward
        return S, n

    def curvatures(self, u, v):
        """Principal curvatures ``(k_min, k_max)`` (1/mm) at ``(u, v)``, positive where the
        face is convex seen from its outward side (a ball's outside: +1/R), negative where
        it is concave (a bowl seen from above)."""
        u = np.asarray(u, dtype=float).ravel()
        v = np.asarray(v, dtype=float).ravel()
        return curvatures_from(bspline.derivatives(self.surface, u, v, 2), self.outward)

    def samples(self, count):
        """A parameter grid of about ``count`` samples over the box, spaced about equally in
        mm along u and v: ``(us, vs)`` (Gu,), (Gv,)."""
        (u0, u1), (v0, v1) = self.surface.u_range, self.surface.v_range
        lu, lv = self.lengths()
        gu = int(np.clip(np.sqrt(count * lu / max(lv, 1e-12)), 8, 4000))
        gv = int(np.clip(count / gu, 8, 4000))
        return np.linspace(u0, u1, gu), np.linspace(v0, v1, gv)

    def lengths(self):
        """Mean lengths (mm) of the parameter lines across the box along u and along v."""
        (u0, u1), (v0, v1) = self.surface.u_range, self.surface.v_range
        t = np.linspace(0.0, 1.0, 33)
        S = bspline.evaluate_grid(self.surface, u0 + (u1 - u0) * t, v0 + (v1 - v0) * t)
        lu = np.linalg.norm(np.diff(S, axis=0), axis=-1).sum(axis=0).mean()
        lv = np.linalg.norm(np.diff(S, axis=1), axis=-1).sum(axis=1).mean()
        return float(lu), float(lv)


def curvatures_from(ders, outward):
    """Principal curvatures from ``(S, Su, Sv, Suu, Suv, Svv)`` (each (N, 3)); sign as in
    :meth:`FaceDomain.curvatures` (first and second fundamental forms, do Carmo 3-3)."""
    _, su, sv, suu, suv, svv = ders
    cross = np.cross(su, sv)
    jac = np.linalg.norm(cross, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        n = outward * cross / jac[:, None]
        e, f, g = (np.einsum("ij,ij->i", a, b) for a, b in ((su, su), (su, sv), (sv, sv)))
        ll, m, nn = (np.einsum("ij,ij->i", a, n) for a in (suu, suv, svv))
        det = e * g - f * f
        mean = -(e * nn - 2 * f * m + g * ll) / (2 * det)
        gauss = (ll * nn - m * m) / det
        root = np.sqrt(np.maximum(mean * mean - gauss, 0.0))
    k1, k2 = mean - root, mean + root
    bad = ~(np.isfinite(k1) & np.isfinite(k2))
    return np.where(bad, 0.0, k1), np.where(bad, 0.0, k2)


def _segment_distance(p, a, d):
    """Distance of points ``p`` (..., 3) from segments ``a + t d``, t in [0, 1] (broadcast)."""
    dd = np.einsum("...i,...i->...", d, d)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip(np.einsum("...i,...i->...", p - a, d) / dd, 0.0, 1.0)
    t = np.where(dd > 0, t, 0.0)
    return np.linalg.norm(p - a - t[..., None] * d, axis=-1)


def segment_distance(p, a, b):
    """Distance of points ``p`` from the segments ``a``-``b`` (all (..., 3), broadcast), mm."""
    a = np.asarray(a, dtype=float)
    return _segment_distance(np.asarray(p, dtype=float), a, np.asarray(b, dtype=float) - a)
