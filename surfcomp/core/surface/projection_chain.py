# SPDX-License-Identifier: LGPL-2.1-or-later
"""Projection of points that follow a path: each from a nearby point's foot (no FreeCAD).

Consecutive cutter-location points of a tool path lie fractions of a millimetre apart, and
so do their feet on the face. :func:`project_chain` projects *anchors* with the full engine
(:meth:`surfcomp.core.surface.projection.Projector.project`: seeds, Newton, the global
checks) and every other point from its anchor's foot:

- the points of the first of :data:`LEVELS` (the first point, a point after a non-finite
  one, a point more than the level's spacing from the one before: a rapid, a retract, the
  next pass; and the first point past each further spacing of path length,
  :func:`path_anchors`) go through the engine; the points of each further level start
  from the last point of a coarser level before them (within that level's spacing along
  the path, so in space too), the remaining points from the last point of any level;
- from that foot and the face's derivatives there (``S, Su, Sv, Suu, Suv, Svv``) two
  Newton steps on its second-order Taylor model of the face (as
  :class:`surfcomp.core.surface.projection_warm.Tracker` takes them) bring the foot within
  the model's third-order error; one exact evaluation and a full Newton step finish it (a
  second evaluation where that step is longer than :data:`FINAL_STEP`). A point is
  answered so when its last step is a fast (positive definite) Newton step of at most
  :data:`FINAL_STEP` (what is left after it is of the order ``step^2 x curvature``:
  ~1e-10 mm), its foot lies inside the work area (not on its border, so not at the end of
  a closed direction either), and the foot is certified global as the engine certifies
  it: closer to the face than the projector's ``safe_distance``, or covered by the region
  certificate;
- everything else (points whose start did not converge, whose step was too long, whose
  foot is on the border or not certified) goes through the full engine, in one call.

The results are those of the full engine to ~1e-10 mm (tested to 1e-9 mm against it).
"""

import numpy as np

from .projection import Projection
from .projection_newton import dot
from .projection_warm import _taylor

#: a warm-started foot is kept when its last Newton step (after one or two exact
#: evaluations) is at most this (mm): the error left is of the order step^2 x curvature,
#: ~1e-10 mm
FINAL_STEP = 3e-5
#: a step this long or longer (mm) after the first evaluation goes to the full engine
SECOND_STEP = 1e-2
#: path lengths (mm) between the points of each level: the first level's go through the
#: full engine, the next level's start from them, the remaining points from the level
#: before theirs (within an eighth of a millimetre: one exact evaluation finishes most)
LEVELS = (0.5, 0.125)


def path_anchors(points, spacing):
    """Which points of the path ``points`` (N, 3) start a piece of at most ``spacing`` (mm)
    of path length (bool (N,)): the first point, points after or at a non-finite one,
    points more than ``spacing`` from the one before, and the first point past each
    further ``spacing`` of path length."""
    P = np.asarray(points, dtype=float)
    n = P.shape[0]
    finite = np.all(np.isfinite(P), axis=1)
    step = np.full(n, np.inf)
    if n > 1:
        step[1:] = np.linalg.norm(np.diff(P, axis=0), axis=1)
    step = np.where(np.isfinite(step), step, np.inf)
    jump = step > spacing
    bucket = np.floor(np.cumsum(np.where(jump, 0.0, step)) / spacing)
    anchor = jump | ~finite
    if n:
        anchor[1:] |= bucket[1:] != bucket[:-1]
        anchor[0] = True
    return anchor


def project_chain(projector, points, max_distance=None, levels=LEVELS, counts=None):
    """The projection of the path ``points`` (N, 3), as
    :meth:`~surfcomp.core.surface.projection.Projector.project` gives it (without
    ``derivatives``); see the module docstring. ``counts``, a dict, gets the numbers of
    points answered from a nearby foot (``'warm'``) and by the full engine (``'full'``)."""
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    n = P.shape[0]
    level = np.full(n, len(levels))
    for k in range(len(levels) - 1, -1, -1):
        level[path_anchors(P, levels[k])] = k
    res = dict(u=np.full(n, np.nan), v=np.full(n, np.nan), foot=np.full((n, 3), np.nan),
               normal=np.full((n, 3), np.nan), distance=np.full(n, np.nan),
               outside=np.zeros(n, dtype=bool), converged=np.zeros(n, dtype=bool),
               derivatives=np.full((6, 3, n), np.nan))
    order = np.arange(n)
    solved = np.zeros(n, dtype=bool)
    for k in range(len(levels) + 1):
        idx = np.flatnonzero(level == k)
        if k == 0:
            _engine(projector, P, idx, res, max_distance)
            solved[idx] = True
            continue
        base = np.maximum.accumulate(np.where(level < k, order, 0))[idx]
        # from solved feet only (the others go through the engine at the end, together)
        go = res["converged"][base] & solved[base]
        if go.any():
            solved[idx[go]] = _warm(projector, P, idx[go], base[go], res, max_distance)
    rest = np.flatnonzero(~solved)
    _engine(projector, P, rest, res, max_distance)
    full = int(np.count_nonzero(level == 0) + rest.size)
    warm = n - full
    if counts is not None:
        counts["full"] = counts.get("full", 0) + full
        counts["warm"] = counts.get("warm", 0) + warm
    del res["derivatives"]
    return Projection(**res)


def _engine(projector, P, idx, res, max_distance):
    """The full engine's projection of ``P[idx]`` into ``res`` (with derivatives)."""
    if idx.size:
        p = projector.project(P[idx], max_distance, derivatives=True)
        for key in res:
            if key == "derivatives":
                res[key][:, :, idx] = p.derivatives
            else:
                res[key][idx] = getattr(p, key)


def _step(r, Su, Sv, Suu, Suv, Svv):
    """The plain Newton step ``(du, dv)`` on ``(S - P) . Su = 0``, ``(S - P) . Sv = 0``
    (``r = S - P``) and where it is a fast one (the distance's Hessian clearly positive
    definite, as :meth:`surfcomp.core.surface.projection_newton.Newton.step` tells it);
    no bounds (a foot that leaves the work area goes to the full engine)."""
    gu, gv = dot(r, Su), dot(r, Sv)
    a, b, c = dot(Su, Su), dot(Su, Sv), dot(Sv, Sv)
    Huu, Huv, Hvv = a + dot(r, Suu), b + dot(r, Suv), c + dot(r, Svv)
    det = Huu * Hvv - Huv * Huv
    fast = (Huu > 0) & (det > 0.5 * (a * c - b * b))
    det = np.where(fast, det, 1.0)
    return (Huv * gv - Hvv * gu) / det, (Huv * gu - Huu * gv) / det, fast


def _warm(pj, P, idx, base, res, max_distance):
    """Project ``P[idx]`` from the feet of the points ``base`` (in ``res``); fills ``res``
    where the answer is certified and returns that mask."""
    Pt = np.ascontiguousarray(P[idx].T)
    u0, v0 = res["u"][base], res["v"][base]
    D0 = list(res["derivatives"][:, :, base])
    du, dv, ok = _step(D0[0] - Pt, *D0[1:])
    D = _taylor(D0, du, dv)
    du2, dv2, fast = _step(D[0] - Pt, *D[1:])
    u, v = u0 + du + du2, v0 + dv + dv2
    (ulo, uhi), (vlo, vhi) = pj.surf.u_range, pj.surf.v_range
    ok &= fast & (u > ulo) & (u < uhi) & (v > vlo) & (v < vhi)
    u, v = np.where(ok, u, u0), np.where(ok, v, v0)
    D = pj.ev.evaluate(u, v, 2)
    du, dv, fast = _step(D[0] - Pt, *D[1:])
    mv = D[1] * du + D[2] * dv
    s2 = dot(mv, mv)
    # a second evaluation where the first left a step longer than FINAL_STEP
    two = np.flatnonzero(ok & fast & (s2 > FINAL_STEP ** 2) & (s2 < SECOND_STEP ** 2))
    if two.size:
        u[two] += du[two]
        v[two] += dv[two]
        D2 = pj.ev.evaluate(u[two], v[two], 2)
        du[two], dv[two], fast[two] = _step(D2[0] - Pt[:, two], *D2[1:])
        for d, d2 in zip(D, D2):
            d[:, two] = d2
        mv = D[1] * du + D[2] * dv
        s2 = dot(mv, mv)
    u, v = u + du, v + dv
    ok &= fast & (s2 <= FINAL_STEP ** 2) & (u > ulo) & (u < uhi) & (v > vlo) & (v < vhi)
    D = _taylor(D, du, dv)
    r = D[0] - Pt
    d2 = dot(r, r)
    check = np.flatnonzero(ok & ~(d2 < pj.safe_distance ** 2))
    if check.size:
        ok[check] = pj._certified(u[check], v[check], r[:, check],
                                  [d[:, check] for d in D[1:3]], ok[check])
    if ok.all():                 # (all answered: no copies)
        pj._finish(P[idx], idx, u, v, D, ok, res, max_distance)
        return ok
    keep = np.flatnonzero(ok)
    pj._finish(P[idx[keep]], idx[keep], u[keep], v[keep], [d[:, keep] for d in D],
               np.ones(keep.size, dtype=bool), res, max_distance)
    return ok
