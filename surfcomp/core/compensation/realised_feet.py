# SPDX-License-Identifier: LGPL-2.1-or-later
"""The correction a corrected face realises at projected feet, for many points (no FreeCAD).

:func:`surfcomp.core.compensation.corrected_check.realised_correction` intersects the line
``S(u, v) - t n(u, v)`` with the corrected face (Newton on ``S_c(a, b) + t n - S = 0``). At
the contact points of a tool path the nominal point ``S`` and its normal ``n`` are already
known (the projection gave them), and the corrected face is evaluated there many times:
:class:`RealisedAt` takes ``S`` and ``n`` from the caller and evaluates the corrected face
with the projection engine's power-basis table
(:class:`surfcomp.core.surface.projection_newton.SpanTable`), several times faster than
:func:`surfcomp.core.surface.bspline.derivatives` per point.

Path points come in order and their neighbours' intersections are close: with
``warm=True`` the points of a path start from the parameter offset ``(a - u, b - v)`` and
``t`` of the last point before them that started cold (one per :data:`SPACING` mm of
path, see :func:`surfcomp.core.surface.projection_chain.path_anchors`), which saves about
one evaluation per point. Both start the same Newton iteration and stop on the same test
(the step from a residual below
:data:`~surfcomp.core.compensation.corrected_check.FINAL_STEP`): the results agree to
~1e-13 mm. A point whose warm Newton has not converged after :data:`WARM_ITERATIONS`
starts again cold.
"""

import numpy as np

from ..surface.projection import MAX_TABLE_VALUES
from ..surface.projection_chain import path_anchors
from ..surface.projection_newton import GenericEval, SpanTable
from .corrected_check import FINAL_STEP, _solve3, realised_correction

#: path length (mm) between the points that start from the nominal point itself
SPACING = 0.5
#: iterations a warm start gets before the point starts again cold
WARM_ITERATIONS = 6


class RealisedAt:
    """``t`` at contact points: how far the corrected face lies inside the nominal along
    the outward normal there.

    Parameters
    ----------
    nominal, corrected : surfcomp.core.surface.bspline.Surface
    outward : {1, -1}
    warm : bool
        Start path points from their anchor's intersection (module docstring).
    """

    def __init__(self, nominal, corrected, outward, warm=True):
        self.nominal, self.corrected, self.outward = nominal, corrected, int(outward)
        self.warm = warm
        self.ev = (SpanTable(corrected) if SpanTable.size(corrected) <= MAX_TABLE_VALUES
                   else GenericEval(corrected))
        self.counts = {"cold": 0, "warm": 0}

    def __call__(self, u, v):
        """The realised correction at ``(u, v)`` (the full evaluation from the nominal)."""
        return realised_correction(self.nominal, self.corrected, u, v, self.outward)

    def at(self, u, v, foot, normal):
        """The realised correction at feet ``(u, v)`` (N,) with nominal points ``foot``
        (N, 3) and unit normals ``normal`` (N, 3) along ``Su x Sv`` (the projection's)."""
        u = np.asarray(u, dtype=float)
        v = np.asarray(v, dtype=float)
        S = np.asarray(foot, dtype=float)
        n = self.outward * np.asarray(normal, dtype=float)
        N = u.size
        t = np.zeros(N)
        if not N:
            return t
        if not self.warm:
            a, b, t, _ = self._newton(S, n, u.copy(), v.copy(), t, 20)
            self.counts["cold"] += N
            return t
        anchor = path_anchors(S, SPACING)
        ia = np.flatnonzero(anchor)
        a, b, t[ia], _ = self._newton(S[ia], n[ia], u[ia].copy(), v[ia].copy(), t[ia], 20)
        rest = np.flatnonzero(~anchor)
        base = (np.cumsum(anchor) - 1)[rest]
        cold = np.zeros(0, dtype=int)
        if rest.size:
            a2, b2, t2, conv = self._newton(S[rest], n[rest], u[rest] + (a - u[ia])[base],
                                            v[rest] + (b - v[ia])[base], t[ia][base].copy(),
                                            WARM_ITERATIONS)
            t[rest] = t2
            cold = rest[~conv]
        if cold.size:
            t[cold] = self._newton(S[cold], n[cold], u[cold].copy(), v[cold].copy(),
                                   np.zeros(cold.size), 20)[2]
        self.counts["cold"] += ia.size + cold.size
        self.counts["warm"] += N - ia.size - cold.size
        return t

    def _newton(self, P, n, a, b, t, iterations):
        """Newton on ``S_c(a, b) + t n - P = 0`` as
        :meth:`surfcomp.core.compensation.corrected_check.NodeFrame.realised` runs it;
        returns ``a, b, t`` and which points converged."""
        (ua, ub), (va, vb) = self.corrected.u_range, self.corrected.v_range
        act = np.arange(a.size)
        conv = np.zeros(a.size, dtype=bool)
        for _ in range(iterations):
            C, Cu, Cv = self.ev.evaluate(a[act], b[act], 1)
            F = C.T + t[act, None] * n[act] - P[act]
            small = np.all(np.abs(F) < 1e-12, axis=1)
            conv[act[small]] = True
            act, F, Cu, Cv = act[~small], F[~small], Cu[:, ~small], Cv[:, ~small]
            if act.size == 0:
                break
            da, db, dt = _solve3(Cu.T, Cv.T, n[act], -F)
            a[act] = np.clip(a[act] + da, ua, ub)
            b[act] = np.clip(b[act] + db, va, vb)
            t[act] += dt
            fin = np.all(np.abs(F) < FINAL_STEP, axis=1)
            conv[act[fin]] = True
            act = act[~fin]
            if act.size == 0:
                break
        return a, b, t, conv
