# SPDX-License-Identifier: LGPL-2.1-or-later
"""The sharp edges of a region and the vector each moves by (issue 30; numpy/scipy only).

Where two corrected faces meet at an angle, the edge is moved once, by one vector ``-delta m``
that both faces take (:mod:`surfcomp.core.compensation.region_build` turns each face's displacement
towards it within a band around the edge). ``m`` is the edge's miter
``(n_A + n_B) / (1 + n_A.n_B)``: both faces' normal components are then the correction, and
the edge moves as the intersection of the two offset faces does. The miter grows as
``1 / cos(half the angle between the normals)``; past
:data:`~surfcomp.core.compensation.region_build.MITER_ANGLE` (a knife edge, the normals nearly
opposite) it is shortened along the bisector and the correction there is not met in full (the offset
of a knife edge recedes without bound: no edge vector closes both faces and realises both
corrections).

**Vertices.** Where several sharp edges end at one vertex (a blade's leading edge, its
side and its root cap), each edge's own miter differs; the vertex gets one vector
(:func:`vertex_miter`, the least-squares miter of every face meeting there) and each edge's
miter turns to it within half a band of the vertex; where no vector realises every face's
correction at the vertex (a knife edge ending on a cap) the correction is shortened there
as at a knife edge, so the faces meet at the vertex whichever edge is nearest.

**Between edges** the displacement takes every edge within the band, weighted by
``(1 - smoothstep(d / band)) / d^2`` (``d`` the distance to the edge): on an edge that
edge's vector alone, and continuous where the nearest edge changes.
"""

import copy
import math

import numpy as np
from scipy.spatial import cKDTree

#: regularisation of a vertex's least-squares miter (share of the normal matrix)
VERTEX_REG = 1e-9


def smoothstep(s):
    """Quintic smooth step: 0 below 0, 1 above 1, C2."""
    s = np.clip(s, 0.0, 1.0)
    return s * s * s * (s * (6 * s - 15) + 10)


def vertex_miter(normals, limit):
    """One vector ``m`` with ``m . n ~ 1`` for every outward normal (K, 3) of the faces at a
    vertex (regularised least squares, no longer than ``limit``)."""
    n = np.asarray(normals, dtype=float)
    a = n.T @ n
    m = np.linalg.solve(a + VERTEX_REG * np.trace(a) * np.eye(3), n.T @ np.ones(len(n)))
    size = np.linalg.norm(m)
    return m * (limit / size) if size > limit else m


def at_vertices(points, miter, exact, edge, normals, zone, limit, tol, singular=None,
                away=False):
    """Turn each edge's miters to its vertex's vector near the vertex (see the module
    docstring). ``normals``: (K, 2, 3), both faces' normals at each sample; ``zone``: the
    arc length (mm) over which an edge's miter turns; ``tol``: ends closer than this meet;
    ``singular``: (S, 3) points where a face collapses (a cap's end: its normal takes every
    direction of a fan there, so no vector but the vertex's own moves it as one point).
    Returns new ``miter`` and ``exact`` arrays (and with ``away`` a third: 0 at a vertex
    where two edges meet, rising to 1 over ``zone``)."""
    miter, exact = miter.copy(), exact.astype(float).copy()
    far = np.ones(len(miter))
    ends = []
    for k in np.unique(edge):
        idx = np.flatnonzero(edge == k)
        ends.extend([(k, idx), (k, idx[::-1])])
    tips = np.array([points[idx[0]] for _, idx in ends])
    groups = cKDTree(tips).query_ball_point(tips, tol)
    done = set()
    for g in groups:
        key = tuple(sorted(g))
        if key in done:
            continue
        done.add(key)
        if len({ends[i][0] for i in g}) < 2:       # one edge's end: nothing to agree on
            continue
        nv = np.concatenate([normals[ends[i][1][0]] for i in g])
        mv = vertex_miter(nv, limit)
        # a vertex whose faces' normals admit one miter (a box corner) keeps the correction
        shorten = np.max(np.abs(nv @ mv - 1.0)) > 1e-6 or _touches(tips[list(g)], singular,
                                                                   tol)
        for i in g:
            idx = ends[i][1]
            arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points[idx], axis=0), axis=1))]
            t = smoothstep(arc / zone)[:, None]
            miter[idx] = t * miter[idx] + (1.0 - t) * mv
            far[idx] *= t[:, 0]
            if shorten:
                exact[idx] *= smoothstep(arc / zone - 1.0)
    return (miter, exact, far) if away else (miter, exact)


def eased(exact, edge, points, length):
    """``exact`` (K,) made to change along each edge over at least ``length`` (mm), never
    above what it was: the least value within ``length`` of a sample, then averaged twice
    over ``length / 2`` either side (each average takes values within ``length`` of the
    sample, all at most its own). An edge whose angle crosses the knife limit within a few
    mm (the BladeX trailing edge goes from 143 to 95 degrees in 3.5 mm near the tip) turns
    the displacement from the edge's vector to the face's normal there, faster than the
    face's fit follows (2 to 5 um beyond the shortened zone, on 3 mm spanwise knot spans)."""
    out = np.asarray(exact, dtype=float).copy()
    for k in np.unique(edge):
        idx = np.flatnonzero(edge == k)
        arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points[idx], axis=0), axis=1))]
        # (the rounding of the arc lengths must not take a sample into one window and
        # not into its neighbour's)
        near = np.abs(arc[:, None] - arc[None, :]) - 1e-9 * length
        e = np.where(near <= length, out[idx][None, :], np.inf).min(axis=1)
        half = (near <= 0.5 * length).astype(float)
        half /= half.sum(axis=1, keepdims=True)
        out[idx] = half @ (half @ e)
    return out


def _catmull_rom(v, ks, t):
    """Catmull-Rom interpolation of the samples ``v`` (K, n) between ``ks[1]`` and
    ``ks[2]`` at ``t`` (M, 1) in [0, 1], ``ks[0]`` and ``ks[3]`` the neighbours (C1 along
    the samples; the samples' own values at t = 0 and 1)."""
    km, k0, k1, kp = ks
    t2, t3 = t * t, t * t * t
    d0, d1 = 0.5 * (v[k1] - v[km]), 0.5 * (v[kp] - v[k0])
    return ((2 * t3 - 3 * t2 + 1) * v[k0] + (t3 - 2 * t2 + t) * d0
            + (3 * t2 - 2 * t3) * v[k1] + (t3 - t2) * d1)


def _touches(tips, singular, tol):
    """True when one of ``tips`` lies within ``tol`` of a ``singular`` point."""
    if singular is None or not len(singular):
        return False
    return bool(np.any(cKDTree(np.asarray(singular, dtype=float)).query(tips, k=1)[0] <= tol))


class SharpEdges:
    """Polylines along the edges where corrected faces meet at an angle.

    Parameters
    ----------
    points : ndarray, shape (K, 3)
    miter : ndarray, shape (K, 3)
    exact : ndarray, shape (K,)
        1 where the miter realises both faces' corrections (the faces turn to it with their
        normal component kept), 0 where the edge moves by ``-delta m`` alone (a knife edge,
        a vertex); booleans ``clamped`` may be given as ``~exact``.
    edge : ndarray of int, shape (K,)
        Which edge each sample belongs to (an edge's samples are consecutive).
    band : float
        Width (mm) of the band in which the displacement turns to the edge's vector.
    normals : ndarray, shape (K, 2, 3), optional
    faces : ndarray of int, shape (K, 2), optional
        The two faces' outward normals at each sample and the faces' indices: with them,
        :meth:`for_face` gives the edges as one face sees them (the turn taken relative to
        that face's own normal at the edge).
    inward : ndarray, shape (K, 2, 3), optional
        The two faces' unit directions into the face, normal to the edge, at each sample:
        :meth:`for_face` gives the face's own as ``own_inward`` (nan along the edges of
        other faces).
    """

    def __init__(self, points, miter, exact, edge, band, normals=None, faces=None,
                 inward=None):
        self.points = np.asarray(points, dtype=float)
        self.miter = np.asarray(miter, dtype=float)
        exact = np.asarray(exact)
        self.exact = (~exact).astype(float) if exact.dtype == bool else exact.astype(float)
        self.edge = np.asarray(edge)
        self.band = float(band)
        self.normals = None if normals is None else np.asarray(normals, dtype=float)
        self.faces = None if faces is None else np.asarray(faces)
        self.inward = None if inward is None else np.asarray(inward, dtype=float)
        self.own_inward = None
        # what the displacement turns by along the face, per sample: the miter itself
        # (seen from no face in particular), or the miter less the face's own normal
        self.excess = self.miter
        # the second-order edge vector (mm, region_second.edge_vector; zero unless set)
        self.second = np.zeros_like(self.miter)
        self._edges = [np.flatnonzero(self.edge == k) for k in np.unique(self.edge)]
        self._trees = [cKDTree(self.points[idx]) for idx in self._edges]
        # a point within the band of a segment is within this much more of a sample
        self._reach = float(np.max(np.linalg.norm(np.diff(self.points, axis=0), axis=1)[
            np.diff(self.edge) == 0], initial=0.0))

    def for_face(self, i):
        """The edges as face ``i`` sees them: along its own edges the turn is the miter
        less the face's normal at the edge (on a strongly curved face the normal a little
        way off the edge differs from the edge's, and turning to the miter itself would
        slide the face along itself by that difference: a blend of 0.17 mm radius slid by
        8 um misses its correction by 0.18 um, curvature x slide^2 / 2); along the others
        the miter itself."""
        if self.faces is None:
            return self
        out = copy.copy(self)
        out.excess = self.miter.copy()
        if self.inward is not None:
            out.own_inward = np.full_like(self.miter, np.nan)
        for side in (0, 1):
            mine = self.faces[:, side] == i
            out.excess[mine] = self.miter[mine] - self.normals[mine, side]
            if self.inward is not None:
                out.own_inward[mine] = self.inward[mine, side]
        return out

    def _one(self, x, idx, tree):
        """The points of ``x`` within ``band`` plus the samples' spacing of a sample of one
        edge polyline (the others are beyond its band: nothing turns towards it there),
        their distance to the polyline, and the miter, exactness and excess there."""
        pts = self.points[idx]
        mit = np.concatenate([self.miter[idx], self.excess[idx], self.second[idx],
                              self.exact[idx, None]], axis=1)
        last = len(idx) - 1
        _, j = tree.query(x, k=1, distance_upper_bound=self.band + self._reach)
        k = np.flatnonzero(j <= last)
        x, j = x[k], j[k]
        # the two segments at the nearest sample; the second where strictly nearer
        ends, feet = [], []
        for k0, k1 in ((np.maximum(j - 1, 0), j), (j, np.minimum(j + 1, last))):
            a, b = pts[k0], pts[k1]
            ab = b - a
            t = np.einsum("ij,ij->i", x - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab),
                                                              1e-300)
            t = np.clip(t, 0.0, 1.0)
            ends.append((k0, k1))
            feet.append((t, np.linalg.norm(x - (a + t[:, None] * ab), axis=1)))
        second = feet[1][1] < feet[0][1]
        k0 = np.where(second, ends[1][0], ends[0][0])
        k1 = np.where(second, ends[1][1], ends[0][1])
        tt = np.where(second, feet[1][0], feet[0][0])[:, None]
        d = np.where(second, feet[1][1], feet[0][1])
        # Catmull-Rom between the samples: the displacement's slope does not jump where
        # the foot passes a sample (a linear blend kinks it there, and the fit of a face
        # along the edge follows no kink)
        ks = (np.maximum(k0 - 1, 0), k0, k1, np.minimum(k1 + 1, last))
        mk = _catmull_rom(mit, ks, tt)
        return k, d, mk[:, :9], mk[:, 9]

    def feet(self, x, reach):
        """The nearest point of the edge polylines to each of ``x`` (M, 3), its distance
        and the sample nearer to it of its segment's two (an index into ``points``), for
        the points within ``reach`` (mm) of an edge sample's neighbourhood (beyond: nan,
        inf and -1)."""
        x = np.asarray(x, dtype=float)
        dist = np.full(len(x), np.inf)
        foot = np.full((len(x), 3), np.nan)
        near = np.full(len(x), -1)
        for idx, tree in zip(self._edges, self._trees):
            pts, last = self.points[idx], len(idx) - 1
            _, j = tree.query(x, k=1, distance_upper_bound=reach + self._reach)
            k = np.flatnonzero(j <= last)
            j = j[k]
            for k0, k1 in ((np.maximum(j - 1, 0), j), (j, np.minimum(j + 1, last))):
                a, ab = pts[k0], pts[k1] - pts[k0]
                t = np.clip(np.einsum("ij,ij->i", x[k] - a, ab)
                            / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0.0, 1.0)
                p = a + t[:, None] * ab
                d = np.linalg.norm(x[k] - p, axis=1)
                better = d < dist[k]
                dist[k[better]] = d[better]
                foot[k[better]] = p[better]
                near[k[better]] = idx[np.where(t < 0.5, k0, k1)[better]]
        return foot, dist, near

    def nearest(self, x):
        """Distance to the nearest edge, and the blended miter, exactness and excess (the
        turn along the face: :meth:`for_face`) at ``x``. The distance is exact within the
        band; beyond it, where nothing turns, it is at least the band (or inf)."""
        return self.blend(x)[:4]

    def blend(self, x):
        """:meth:`nearest` and the blended second-order edge vector at ``x``."""
        x = np.asarray(x, dtype=float)
        dmin = np.full(len(x), np.inf)
        wsum = np.zeros(len(x))
        m = np.zeros((len(x), 9))
        e = np.zeros(len(x))
        eps2 = (1e-9 * self.band) ** 2
        for idx, tree in zip(self._edges, self._trees):
            # only the points in the edge's box widened by the band weigh it
            lo, hi = self.points[idx].min(axis=0), self.points[idx].max(axis=0)
            k = np.flatnonzero(np.all((x >= lo - self.band) & (x <= hi + self.band), axis=1))
            sub, d, mk, ek = self._one(x[k], idx, tree)
            k = k[sub]
            w = (1.0 - smoothstep(d / self.band)) / (d * d + eps2)
            dmin[k] = np.minimum(dmin[k], d)
            wsum[k] += w
            m[k] += w[:, None] * mk
            e[k] += w * ek
        far = wsum <= 0
        wsum[far] = 1.0
        e[far] = 1.0
        m /= wsum[:, None]
        return dmin, m[:, :3], e / wsum, m[:, 3:6], m[:, 6:]


def knife_limit(angle):
    """The longest miter (share of the correction) of the edges sharper than ``angle``
    (degrees between the normals)."""
    return 1.0 / math.cos(math.radians(0.5 * angle))
