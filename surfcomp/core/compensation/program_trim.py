# SPDX-License-Identifier: LGPL-2.1-or-later
"""The trimmed face's boundary for the direct program route (no FreeCAD).

:class:`surfcomp.core.compensation.program_offset.BallOffset` projects the ball centres onto
the face's B-spline surface. Where the face is trimmed (an outer boundary inside the
surface, holes), a centre whose foot lies outside the trimmed face touches the face, if at
all, on its boundary: :class:`Trim` gives, for such centres, the closest point of the
boundary (a polyline of the boundary curves mapped onto the surface, closest segment
point in space) with its parameters, so that the clearance ``|C - B| - R`` and the
correction at ``B`` fade the move out over the blend as beyond the surface's own edge. A
centre whose foot crosses the boundary from inside moves continuously: at the boundary
the foot and the boundary point coincide (up to the polyline's chord error, a fraction of a
micrometre at :data:`STEP` mm between boundary points on faces curved like the example's).
"""

import numpy as np
from scipy.spatial import cKDTree

from ..surface import bspline
from ..surface.trimmed import inside, whole_domain

#: longest piece (mm) of the boundary polyline in space
STEP = 0.02
#: nearest boundary points looked at per centre (their segments on both sides)
NEIGHBOURS = 4


class Trim:
    """The boundary of a trimmed face.

    Parameters
    ----------
    surface : surfcomp.core.surface.bspline.Surface
    pieces : list of (n, 2) arrays
        The boundary in (u, v) (:func:`surfcomp.app.nominal.boundary_polylines`).
    """

    def __init__(self, surface, pieces):
        self.surface = surface
        self.pieces = [np.asarray(p, dtype=float) for p in pieces]
        uv, xyz, nxt = [], [], []
        start = 0
        for p in self.pieces:
            X = bspline.evaluate(surface, p[:, 0], p[:, 1])
            seg = np.linalg.norm(np.diff(X, axis=0), axis=1)
            k = np.maximum(1, np.ceil(seg / STEP).astype(int))
            f = np.concatenate([np.arange(n) / n for n in k])
            i = np.repeat(np.arange(seg.size), k)
            q = np.concatenate([p[i] + (p[i + 1] - p[i]) * f[:, None], p[-1:]])
            uv.append(q)
            xyz.append(bspline.evaluate(surface, q[:, 0], q[:, 1]))
            n = q.shape[0]
            # the next point of the same piece (-1 at its end)
            nxt.append(np.r_[np.arange(start + 1, start + n), -1])
            start += n
        self.uv = np.concatenate(uv)
        self.xyz = np.concatenate(xyz)
        self.next = np.concatenate(nxt)
        self.prev = np.full(self.next.size, -1)
        has = self.next >= 0
        self.prev[self.next[has]] = np.flatnonzero(has)
        self.tree = cKDTree(self.xyz)

    @classmethod
    def of(cls, surface, pieces):
        """A :class:`Trim`, or None where ``pieces`` bound the whole surface."""
        if not pieces or whole_domain(pieces, surface.u_range, surface.v_range):
            return None
        return cls(surface, pieces)

    def outside(self, u, v):
        """Which feet ``(u, v)`` lie outside the trimmed face (bool)."""
        return ~inside(self.pieces, u, v)

    def closest(self, points):
        """Closest boundary points of ``points`` (k, 3): ``(xyz (k, 3), u (k,), v (k,),
        distance (k,))``."""
        P = np.asarray(points, dtype=float).reshape(-1, 3)
        k = min(NEIGHBOURS, self.xyz.shape[0])
        _d, nb = self.tree.query(P, k=k)
        nb = nb.reshape(P.shape[0], -1)
        best = np.full(P.shape[0], np.inf)
        bx, bu = np.zeros((P.shape[0], 3)), np.zeros((P.shape[0], 2))
        for a_of in (self.prev, self.next):
            for j in range(nb.shape[1]):
                a, b = nb[:, j], a_of[nb[:, j]]
                b = np.where(b >= 0, b, a)
                A, B = self.xyz[a], self.xyz[b]
                AB = B - A
                den = np.einsum("ij,ij->i", AB, AB)
                s = np.clip(np.einsum("ij,ij->i", P - A, AB) / np.where(den > 0, den, 1.0),
                            0.0, 1.0)
                X = A + s[:, None] * AB
                d = np.linalg.norm(P - X, axis=1)
                better = d < best
                best[better] = d[better]
                bx[better] = X[better]
                uvs = self.uv[a] + s[:, None] * (self.uv[b] - self.uv[a])
                bu[better] = uvs[better]
        return bx, bu[:, 0], bu[:, 1], best
