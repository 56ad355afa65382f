# SPDX-License-Identifier: LGPL-2.1-or-later
"""Projection of a point set that moves a little between calls (no FreeCAD).

A rigid fit projects the same measured points again after every step, and once it is
near the solution a step moves them by micrometres. :class:`Tracker` keeps, for every
point, the foot and the face's derivatives there (``S, Su, Sv, Suu, Suv, Svv``) from the
last time the point went through the projection engine (the *base*), and answers a new
call from them:

- one Newton step from the base foot on the base derivatives (the second-order Taylor
  model of the face there, :meth:`Newton.step`) gives the new foot; where that step is a
  full Newton step that moves the foot by at most :data:`TAYLOR_TOL`, the model's foot is
  kept without evaluating the face. Its error is of third order in the step (the engine
  itself finishes every projection with a Taylor step of up to
  :data:`~surfcomp.core.surface.projection_newton.STEP_TOL`); the step is always taken from the
  base, so errors do not add up over calls;
- the other points run the engine's Newton iterations from their base foot with exact
  evaluations (:meth:`Newton.quick`), and the result becomes their new base;
- points whose foot may not be the global one, or that did not converge, are projected
  afresh (:meth:`Projector.project`, seeds and checks included): points farther from the
  face than half its smallest radius of curvature (``Projector.safe_distance``; closer
  ones have a unique closest point, so following the local minimum is exact), feet at
  the end of a closed direction (a seam), and points that could not be projected before.

The first call (or a call with another number of points) projects all points afresh.
The results are those of :meth:`Projector.project` (a :class:`Projection`, without
``derivatives``).
"""

import numpy as np

from ..chunks import for_chunks
from .projection import Projection
from .projection_newton import dot

#: largest motion of a foot (mm) that the Taylor model of the face at the base foot
#: answers without evaluating the face (third-order error: ~1e-12 mm in the distance on faces whose
#: curvature radii are millimetres or more)
TAYLOR_TOL = 1e-3
#: points per block of the Taylor answers (the temporaries stay in the processor's cache)
BLOCK = 8192


class Tracker:
    """Projections of one set of points onto one face, call after call (see the module
    docstring).

    Parameters
    ----------
    projector : surfcomp.core.surface.projection.Projector
    tol : float
        :data:`TAYLOR_TOL`; 0 evaluates the face at every call.

    Attributes
    ----------
    counts : dict
        Points answered so far by the Taylor model (``'taylor'``), by Newton from the
        base (``'newton'``) and afresh (``'fresh'``).
    """

    def __init__(self, projector, tol=TAYLOR_TOL):
        self.pj = projector
        self.tol = float(tol)
        self.u = self.v = self.D = None
        self.counts = {"taylor": 0, "newton": 0, "fresh": 0}

    def project(self, points):
        """The projection of ``points`` (N, 3), as :meth:`Projector.project` gives it."""
        P = np.asarray(points, dtype=float)
        N = P.shape[0]
        if self.u is None or self.u.size != N:
            p = self.pj.project(P, derivatives=True)
            self.u, self.v, self.D = p.u.copy(), p.v.copy(), p.derivatives
            self.counts["fresh"] += N
            return Projection(p.u, p.v, p.foot, p.normal, p.distance, p.outside, p.converged)
        res = dict(u=np.full(N, np.nan), v=np.full(N, np.nan), foot=np.full((N, 3), np.nan),
                   normal=np.full((N, 3), np.nan), distance=np.full(N, np.nan),
                   outside=np.zeros(N, dtype=bool), converged=np.zeros(N, dtype=bool))
        redo = np.zeros(N, dtype=bool)
        newton = np.zeros(N, dtype=bool)
        for_chunks(lambda sl: self._block(P, sl, res, redo, newton), N, BLOCK,
                   workers=self.pj.workers)
        again = np.flatnonzero(redo)
        if again.size:
            p = self.pj.project(P[again], derivatives=True)
            self.u[again], self.v[again] = p.u, p.v
            self.D[:, :, again] = p.derivatives
            for key in res:
                res[key][again] = getattr(p, key)
        self.counts["fresh"] += int(again.size)
        self.counts["newton"] += int(newton.sum())
        self.counts["taylor"] += N - int(again.size) - int(newton.sum())
        return Projection(**res)

    def _block(self, P, sl, res, redo, newton):
        pj = self.pj
        Pt = np.ascontiguousarray(P[sl].T)
        u0, v0 = self.u[sl], self.v[sl]
        D0 = [d for d in self.D[:, :, sl]]
        S0, Su0, Sv0, Suu, Suv, Svv = D0
        du, dv, fast = pj.newton.step(u0, v0, S0 - Pt, Su0, Sv0, Suu, Suv, Svv)
        D = _taylor(D0, du, dv)
        du2, dv2, fast2 = pj.newton.step(u0 + du, v0 + dv, D[0] - Pt, *D[1:])
        du, dv = du + du2, dv + dv2
        D = _taylor(D0, du, dv)
        u, v = u0 + du, v0 + dv
        mv = Su0 * du + Sv0 * dv
        conv = (fast & fast2 & (dot(mv, mv) <= self.tol * self.tol)
                & self._unique(Pt, u, v, D[0]))
        slow = np.flatnonzero(~conv & np.isfinite(u0))
        if slow.size:
            u2, v2, D2, c2 = pj.newton.quick(Pt[:, slow], u0[slow], v0[slow],
                                              [d[:, slow] for d in D0], evaluations=1)
            c2 &= self._unique(Pt[:, slow], u2, v2, D2[0])
            k = slow[c2]
            u[k], v[k], conv[k] = u2[c2], v2[c2], True
            for d, d2 in zip(D, D2):
                d[:, k] = d2[:, c2]
            g = np.arange(sl.start, sl.stop)[k]
            self.u[g], self.v[g] = u[k], v[k]
            for j, d in enumerate(D):
                self.D[j][:, g] = d[:, k]
            newton[g] = True
        redo[sl] = ~conv
        if conv.all():
            pj._finish(P[sl], np.arange(sl.start, sl.stop), u, v, D, conv, res, None)
            return
        keep = np.flatnonzero(conv)
        pj._finish(P[sl][keep], np.arange(sl.start, sl.stop)[keep], u[keep], v[keep],
                   [d[:, keep] for d in D], conv[keep], res, None)

    def _unique(self, Pt, u, v, S):
        """Feet known to be the global closest points: within the face's safe distance
        and not at the end of a closed direction."""
        r = S - Pt
        ok = dot(r, r) < self.pj.safe_distance ** 2
        for t, (lo, hi), closed in zip((u, v), (self.pj.surf.u_range, self.pj.surf.v_range),
                                       self.pj._closed):
            if closed:
                ok &= (t > lo) & (t < hi)
        return ok


def _taylor(D, du, dv):
    """``S, Su, Sv, Suu, Suv, Svv`` of the second-order Taylor model of the face at the
    derivatives ``D``, a parameter step ``(du, dv)`` away."""
    S, Su, Sv, Suu, Suv, Svv = D
    # S + Su du + Sv dv + (Suu du du + 2 Suv du dv + Svv dv dv) / 2, Su + Suu du + Suv dv,
    # Sv + Suv du + Svv dv: the same operations in the same order, in place (fewer
    # temporaries of the size of the path)
    q = Suu * du
    q *= du
    w = 2.0 * Suv
    w *= du
    w *= dv
    q += w
    np.multiply(Svv, dv, out=w)
    w *= dv
    q += w
    q *= 0.5
    s = Su * du
    s += S
    np.multiply(Sv, dv, out=w)
    s += w
    s += q
    su = Suu * du
    su += Su
    np.multiply(Suv, dv, out=w)
    su += w
    sv = Suv * du
    sv += Sv
    np.multiply(Svv, dv, out=w)
    sv += w
    return [s, su, sv, Suu, Suv, Svv]
